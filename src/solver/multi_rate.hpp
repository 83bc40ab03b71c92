// Multi-rate stepping (time.multi_rate; docs/theory.md, "Multi-rate stepping"): each part
// advances at its own stable step, a power-of-two multiple m_p of a base step h, in cycles of
// M = max m_p base steps at whose end every part has finished a step (subcycling in the sense
// of Belytschko, Yen & Mullen 1979 and Daniel 1997; here between parts joined by contacts).
//
// Within a cycle, at base step j (time t_j = T + j h):
//   - parts whose step starts there advance (half kick, drift) over m_p h;
//   - parts whose step ends at t_{j+1} compute their forces there;
//   - a contact c between parts a and b is evaluated when the finer of them ends a step
//     (every m_c = min(m_a, m_b) base steps), with its step h_c = m_c h. A part in the middle
//     of its step shows the contact the positions of t_{j+1} on its straight path
//     (Part::set_contact_lag): x^{n+1} - (t_end - t_{j+1}) v^{n+1/2};
//   - a coarser part (r = m_c / m_p < 1 for one of its contacts) takes over its step of
//     length H exactly the impulse its partner got, the trapezoidal sum
//     J = sum_c h_c (F_c,0 / 2 + sum F_c,inner + F_c,end / 2), and takes it as velocity Verlet
//     would: its first half kick with the contacts' full forces at its step's start, S =
//     sum_c F_c,0, and its last half kick with G = 2 J / H - S (Part::add_contact_forces), the
//     next step again starting with the full forces S' = sum_c F_c,end
//     (Part::set_next_contact_forces). Momentum is then exchanged exactly at every step's end,
//     the part books the work H/2 v^{n+1/2} . (S + G) = v^{n+1/2} . J as in one-rate stepping,
//     and G = F_end + O(H^2) for a smooth force, so that the kinetic energy's error stays of
//     second order (a split that gave all of J - S H/2 to the last half kick without the
//     full start force made it first order: 13 % energy error at ratio 8 in the grain test).
// A part's sums follow its particles by their ids (parts::ContactPoints::id) through what
// changes their order within its step: the re-sort at a rebuild of its lists (in its force
// stage at the step's end) and the removals (outflow) at the end of the step before. On MPI
// ranks the sums are over the whole part in one rank's order (Coupling::seen, hand_to), the
// same numbers on every rank, and each rank's part takes those of its own entities.
// The ratios for the next cycle are decided at the end of this one, from the state whose
// forces are known (after the force stage, the contacts and the checks, before the last half
// kicks, so that the parts' limits are those one-rate stepping would see next): each
// part's own allowed step, the side limits of its contacts (its lightest body on the stiffest
// spring, its bodies held by several springs; absolute), and each contact's pair limit on the
// finer of its parts. m_p = the largest power of two <= max_ratio with m_p h_0 <= allowed_p,
// h_0 the smallest allowed step; the base step of the next cycle is min_p allowed_p / m_p.
// Parts are visited in scenario order at every stage and contacts in scenario order, so the
// result does not depend on the thread count.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "contact/coupling.hpp"
#include "core/axial_vec.hpp"
#include "core/error.hpp"
#include "solver/part_names.hpp"
#include "solver/step.hpp"

namespace crater::solver {

/// One multi-rate cycle: from t0, `length` base steps of h (the last ending exactly at t_end),
/// part p stepping ratio[p] base steps at a time.
struct RateCycle {
  Real t0 = 0, t_end = 0, h = 0;
  std::int64_t length = 1;
  std::vector<std::int64_t> ratio;
  bool at_frame = false;
};

/// The ratios of the next cycle and its base step.
struct RatePlan {
  std::vector<std::int64_t> ratio;
  Real h = std::numeric_limits<Real>::infinity();
};

/// The cycle a plan gives from t0: max ratio base steps, or, when that would pass the output
/// time frame_t, the fewest power-of-two base steps that reach it, shortened to land on it
/// exactly (no part's step longer than in the plan). A plan without a limit (no part has live
/// entities) goes straight to frame_t.
inline RateCycle make_cycle(const RatePlan& plan, Real t0, Real frame_t, Real t_eps) {
  RateCycle cy;
  cy.t0 = t0;
  cy.ratio = plan.ratio;
  cy.h = plan.h;
  cy.length = 1;
  for (std::int64_t m : cy.ratio)
    cy.length = std::max(cy.length, m);
  if (!(cy.h < std::numeric_limits<Real>::infinity())) {
    cy.h = frame_t - t0;
    cy.length = 1;
    cy.ratio.assign(cy.ratio.size(), 1);
  }
  cy.t_end = t0 + cy.h * static_cast<Real>(cy.length);
  if (cy.t_end >= frame_t - t_eps) {
    std::int64_t m = 1;
    while (m < cy.length && cy.h * static_cast<Real>(m) < frame_t - t0)
      m *= 2;
    cy.length = m;
    cy.h = (frame_t - t0) / static_cast<Real>(m);
    for (std::int64_t& r : cy.ratio)
      r = std::min(r, m);
    cy.t_end = frame_t;
    cy.at_frame = true;
  }
  return cy;
}

template <int D>
class MultiRate {
 public:
  using PartList = std::vector<std::unique_ptr<Part<D>>>;

  MultiRate(Real safety_factor, std::int64_t max_ratio)
      : safety_(safety_factor), max_ratio_(max_ratio) {}

  /// Each part's step for the next cycle from the current state's limits (after the force
  /// stage and the contacts).
  RatePlan plan(const PartList& parts, const contact::Coupling<D>& coupling) const {
    const std::size_t n = parts.size();
    std::vector<Real> allowed(n);
    for (std::size_t p = 0; p < n; ++p)
      allowed[p] = parts[p]->stable_step().allowed_s(safety_);
    const std::vector<contact::PairLimits> lim = coupling.limits(parts);
    for (std::size_t c = 0; c < lim.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      allowed[a] = std::min(allowed[a], lim[c].points.best.dt_s);
      allowed[b] = std::min(allowed[b], lim[c].other.best.dt_s);
    }
    for (std::size_t c = 0; c < lim.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      const std::size_t finer = allowed[a] <= allowed[b] ? a : b;
      allowed[finer] = std::min(allowed[finer], lim[c].pair.best.dt_s);
    }
    const Real h0 = *std::min_element(allowed.begin(), allowed.end());
    RatePlan plan;
    plan.ratio.assign(n, 1);
    if (!(h0 < std::numeric_limits<Real>::infinity())) return plan;
    for (std::size_t p = 0; p < n; ++p)
      while (plan.ratio[p] < max_ratio_ && Real(2 * plan.ratio[p]) * h0 <= allowed[p])
        plan.ratio[p] *= 2;
    for (std::size_t p = 0; p < n; ++p)
      plan.h = std::min(plan.h, allowed[p] / Real(plan.ratio[p]));
    return plan;
  }

  /// At t = 0, after Coupling::apply: every contact evaluated on its own, each part given
  /// their sum, and the first steps' sums begun (ratio: the first cycle's).
  void start(const PartList& parts, contact::Coupling<D>& coupling,
             const std::vector<std::int64_t>& ratio) {
    std::vector<std::size_t> all(coupling.size());
    for (std::size_t c = 0; c < all.size(); ++c)
      all[c] = c;
    coupling.evaluate(parts, all, std::vector<Real>(all.size(), Real(0)), forces_);
    acc_.assign(parts.size(), {});
    ids_at_end_.assign(parts.size(), {});
    for (std::size_t p = 0; p < parts.size(); ++p) {
      if (!involved(coupling, p)) continue;
      keep_ids(coupling.seen(parts), p);
      Sums full = end_forces(coupling, p);
      coupling.hand_to(parts, p, full.force, full.torque, /*next=*/true);
      begin_step(coupling, p, ratio, std::move(full));
    }
  }

  /// Runs one cycle (a fault of a part throws NumericalError). `decide` is asked at the
  /// cycle's end, before the last half kicks, for the ratios of the next cycle (make_cycle's);
  /// `steps[p]` counts part p's steps.
  void cycle(const RateCycle& cy, const PartList& parts, contact::Coupling<D>& coupling,
             StageClock& clock, const std::function<std::vector<std::int64_t>()>& decide,
             std::vector<std::int64_t>& steps) {
    const std::size_t np = parts.size();
    const std::int64_t M = cy.length;
    if (acc_.size() != np) acc_.assign(np, {});
    for (std::int64_t i = 0; i < M; ++i) {
      const Real t = cy.t0 + cy.h * static_cast<Real>(i);
      for (std::size_t p = 0; p < np; ++p)
        if (i % cy.ratio[p] == 0) {
          if (cy.at_frame && i + cy.ratio[p] == M) parts[p]->expect_frame();
          StageClock::time(clock.part(p),
                           [&] { parts[p]->advance(t, cy.h * static_cast<Real>(cy.ratio[p])); });
          ++steps[p];
        }
      const std::int64_t j = i + 1;
      const Real t_next = j == M ? cy.t_end : cy.t0 + cy.h * static_cast<Real>(j);
      auto ends = [&](std::size_t p) { return j % cy.ratio[p] == 0; };
      for (std::size_t p = 0; p < np; ++p)
        if (ends(p)) StageClock::time(clock.part(p), [&] { parts[p]->compute_forces(t_next); });
      StageClock::time(clock.contacts, [&] { contacts(cy, j, parts, coupling); });
      // As one-rate stepping: the contact forces to the parts, every part checked, then the
      // last half kicks; the next cycle's ratios from the state in between.
      std::vector<Sums> full(np);
      for (std::size_t p = 0; p < np; ++p)
        if (ends(p))
          StageClock::time(clock.contacts, [&] { full[p] = hand_over(parts, coupling, p); });
      for (std::size_t p = 0; p < np; ++p)
        if (ends(p))
          StageClock::time(clock.part(p), [&] {
            if (auto fault = parts[p]->check())
              throw NumericalError(parts[p]->name(), fault->entity_id, t_next, fault->what);
          });
      std::vector<std::int64_t> next;
      if (j == M) next = decide();
      const std::vector<std::int64_t>& after = j == M ? next : cy.ratio;
      for (std::size_t p = 0; p < np; ++p) {
        if (!ends(p)) continue;
        StageClock::time(clock.part(p),
                         [&] { parts[p]->finish_step(cy.h * static_cast<Real>(cy.ratio[p])); });
        StageClock::time(clock.contacts, [&] {
          if (involved(coupling, p)) begin_step(coupling, p, after, std::move(full[p]));
        });
      }
    }
  }

  /// The sums carried from one cycle to the next (checkpoints), flattened.
  std::vector<Real> carried() const {
    std::vector<Real> out;
    auto put = [&](const auto& v) {
      out.push_back(static_cast<Real>(v.size()));
      for (const auto& x : v)
        for (int k = 0; k < components(x); ++k)
          out.push_back(component(x, k));
    };
    out.push_back(static_cast<Real>(acc_.size()));
    for (const Accumulated& a : acc_) {
      out.push_back(a.unit ? 1 : 0);
      put(a.weighted.force);
      put(a.weighted.torque);
      put(a.start.force);
      put(a.start.torque);
      put(a.ids);
    }
    return out;
  }
  /// Restores carried() (on resume); throws std::runtime_error on a malformed list.
  void restore(const std::vector<Real>& in) {
    std::size_t k = 0;
    auto next = [&]() {
      if (k >= in.size()) throw std::runtime_error("multi-rate sums: too short");
      return in[k++];
    };
    auto get = [&](auto& v) {
      const auto n = static_cast<std::size_t>(next());
      if (n > in.size()) throw std::runtime_error("multi-rate sums: bad count");
      v.resize(n);
      for (auto& x : v)
        for (int c = 0; c < components(x); ++c)
          set_component(x, c, next());
    };
    acc_.assign(in.empty() ? 0 : static_cast<std::size_t>(next()), {});
    for (Accumulated& a : acc_) {
      a.unit = next() != 0;
      get(a.weighted.force);
      get(a.weighted.torque);
      get(a.start.force);
      get(a.start.torque);
      get(a.ids);
    }
    if (k != in.size()) throw std::runtime_error("multi-rate sums: too long");
  }

 private:
  struct Sums {
    std::vector<Vec<D>> force;
    std::vector<AxialVec<D>> torque;
  };
  // A part's contact sums over its current step: the weighted forces (2 J / H: r at the
  // step's ends, 2 r inside) and the full forces its first half kick took (S); the ids of its
  // particles when they were begun. `unit`: every contact at the part's own step (r = 1),
  // where the end forces stand as they are and no sums are kept.
  struct Accumulated {
    Sums weighted, start;
    std::vector<std::int64_t> ids;
    bool unit = true;
  };

  static std::int64_t contact_ratio(const std::vector<std::int64_t>& ratio, std::size_t a,
                                    std::size_t b) {
    return std::min(ratio[a], ratio[b]);
  }
  static bool involved(const contact::Coupling<D>& coupling, std::size_t p) {
    for (std::size_t c = 0; c < coupling.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      if (a == p || b == p) return true;
    }
    return false;
  }

  template <class V>
  static int components(const V& x) {
    if constexpr (std::is_arithmetic_v<V>)
      return 1;
    else
      return static_cast<int>(x.size());
  }
  template <class V>
  static Real component(const V& x, int k) {
    if constexpr (std::is_arithmetic_v<V>)
      return static_cast<Real>(x);
    else
      return x[k];
  }
  template <class V>
  static void set_component(V& x, int k, Real value) {
    if constexpr (std::is_arithmetic_v<V>)
      x = static_cast<V>(value);
    else
      x[k] = value;
  }
  template <class V>
  static void add_scaled(std::vector<V>& into, const std::vector<V>& f, Real s) {
    if (f.empty()) return;
    if (into.empty()) {
      if constexpr (std::is_arithmetic_v<V>)
        into.assign(f.size(), V(0));  // a 2D torque
      else
        into.assign(f.size(), V::Zero());
    }
    for (std::size_t i = 0; i < f.size(); ++i)
      into[i] += s * f[i];
  }

  // The contacts' full forces on part p at their last evaluation (all of p's contacts were
  // evaluated at its step's end).
  Sums end_forces(const contact::Coupling<D>& coupling, std::size_t p) const {
    Sums s;
    for (std::size_t c = 0; c < coupling.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      if (a != p && b != p) continue;
      add_scaled(s.force, forces_[c].force[p], 1);
      add_scaled(s.torque, forces_[c].torque[p], 1);
    }
    return s;
  }

  // Part p begins a step under `ratio` whose first half kick takes `full`: the sums of a
  // coarser part start with its contacts' forces at weight r.
  void begin_step(const contact::Coupling<D>& coupling, std::size_t p,
                  const std::vector<std::int64_t>& ratio, Sums full) {
    Accumulated& acc = acc_[p];
    acc = {};
    for (std::size_t c = 0; c < coupling.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      if ((a == p || b == p) && contact_ratio(ratio, a, b) != ratio[p]) acc.unit = false;
    }
    if (acc.unit) return;
    for (std::size_t c = 0; c < coupling.size(); ++c) {
      const auto [a, b] = coupling.sides(c);
      if (a != p && b != p) continue;
      const Real r = static_cast<Real>(contact_ratio(ratio, a, b)) / static_cast<Real>(ratio[p]);
      add_scaled(acc.weighted.force, forces_[c].force[p], r);
      add_scaled(acc.weighted.torque, forces_[c].torque[p], r);
    }
    acc.start = std::move(full);
    acc.ids = std::move(ids_at_end_[p]);
  }

  // The ids of part p's particles as its contacts' forces were last found (before any removal
  // at the end of its step).
  void keep_ids(const PartList& parts, std::size_t p) {
    if (ids_at_end_.size() != parts.size()) ids_at_end_.resize(parts.size());
    const auto pts = parts[p]->contact_points();
    ids_at_end_[p] = pts && pts->id ? *pts->id : std::vector<std::int64_t>{};
  }

  // Part p's sums follow its particles by id (`seen`: as the contacts saw them last) when
  // they were removed or re-sorted since its step began.
  void follow_ids(const PartList& seen, std::size_t p) {
    Accumulated& acc = acc_[p];
    const auto pts = seen[p]->contact_points();
    if (acc.unit || !pts || !pts->id || *pts->id == acc.ids) return;
    const std::vector<std::int64_t>& now = *pts->id;
    // By id: a part re-sorts its particles at a rebuild of its lists (in its force stage, at its
    // step's end), and a removal drops some and may re-sort those that stay.
    std::vector<std::pair<std::int64_t, std::size_t>> was(acc.ids.size());
    for (std::size_t k = 0; k < was.size(); ++k)
      was[k] = {acc.ids[k], k};
    std::sort(was.begin(), was.end());
    std::vector<std::size_t> from(now.size());
    for (std::size_t i = 0; i < now.size(); ++i) {
      const auto it =
          std::lower_bound(was.begin(), was.end(), std::make_pair(now[i], std::size_t{0}));
      if (it == was.end() || it->first != now[i])
        throw std::logic_error("multi-rate: a particle's id was lost");
      from[i] = it->second;
    }
    auto pick = [&](auto& v) {
      if (v.empty()) return;
      auto w = v;
      w.resize(from.size());
      for (std::size_t i = 0; i < from.size(); ++i)
        w[i] = v[from[i]];
      v = std::move(w);
    };
    pick(acc.weighted.force);
    pick(acc.weighted.torque);
    pick(acc.start.force);
    pick(acc.start.torque);
    acc.ids = now;
  }

  // The contacts due at base step j (their finer part ends a step there), parts in the middle
  // of their step shown at t_j, the forces added to the coarser sides' sums.
  void contacts(const RateCycle& cy, std::int64_t j, const PartList& parts,
                contact::Coupling<D>& coupling) {
    const std::size_t nc = coupling.size();
    std::vector<std::size_t> due;
    std::vector<Real> dt(nc, 0);
    std::vector<char> lagged(parts.size(), 0);
    for (std::size_t c = 0; c < nc; ++c) {
      const auto [a, b] = coupling.sides(c);
      const std::int64_t mc = contact_ratio(cy.ratio, a, b);
      if (j % mc != 0) continue;
      due.push_back(c);
      dt[c] = cy.h * static_cast<Real>(mc);
      for (std::size_t q : {a, b})
        if (j % cy.ratio[q] != 0 && !lagged[q]) {
          const std::int64_t left = cy.ratio[q] - j % cy.ratio[q];  // base steps to its end
          parts[q]->set_contact_lag(cy.h * static_cast<Real>(left));
          lagged[q] = 1;
        }
    }
    if (due.empty()) return;
    coupling.evaluate(parts, due, dt, forces_);
    for (std::size_t q = 0; q < parts.size(); ++q)
      if (lagged[q]) parts[q]->set_contact_lag(0);
    for (std::size_t q = 0; q < parts.size(); ++q)
      follow_ids(coupling.seen(parts), q);
    for (std::size_t c : due) {
      const auto [a, b] = coupling.sides(c);
      const std::int64_t mc = contact_ratio(cy.ratio, a, b);
      for (std::size_t q : {a, b}) {
        if (acc_[q].unit) continue;
        const Real r = static_cast<Real>(mc) / static_cast<Real>(cy.ratio[q]);
        const Real w = j % cy.ratio[q] == 0 ? r : 2 * r;
        add_scaled(acc_[q].weighted.force, forces_[c].force[q], w);
        add_scaled(acc_[q].weighted.torque, forces_[c].torque[q], w);
      }
    }
  }

  // Part p ends its step: its last half kick's contact forces (G = 2 J / H - S for a coarser
  // part, else the end forces), and the full end forces for its next step's first half kick.
  // Returns the full end forces.
  Sums hand_over(const PartList& parts, const contact::Coupling<D>& coupling, std::size_t p) {
    if (!involved(coupling, p)) return {};
    keep_ids(coupling.seen(parts), p);
    Sums full = end_forces(coupling, p);
    Accumulated& acc = acc_[p];
    if (acc.unit) {
      coupling.hand_to(parts, p, full.force, full.torque, /*next=*/false);
      return full;
    }
    Sums g = std::move(acc.weighted);
    add_scaled(g.force, acc.start.force, -1);
    add_scaled(g.torque, acc.start.torque, -1);
    coupling.hand_to(parts, p, g.force, g.torque, /*next=*/false);
    coupling.hand_to(parts, p, full.force, full.torque, /*next=*/true);
    return full;
  }

  Real safety_;
  std::int64_t max_ratio_;
  std::vector<contact::ContactForces<D>> forces_;      // per contact, of its last evaluation
  std::vector<Accumulated> acc_;                       // per part, over its current step
  std::vector<std::vector<std::int64_t>> ids_at_end_;  // per part, at its last step's end
};

}  // namespace crater::solver
