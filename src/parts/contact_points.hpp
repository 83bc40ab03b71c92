// What a particle part keeps for the contacts with other parts (src/contact/), besides the
// ContactPoints view of its fields (part.hpp): the work those forces do on it.
#pragma once

#include <span>
#include <vector>

#include "core/axial_vec.hpp"
#include "core/index.hpp"
#include "core/types.hpp"
#include "parallel/comm.hpp"
#include "parallel/parallel.hpp"

namespace crater::parts {

/// Work of the contact forces on a part [J] (Energies::contact_j is its negative, plus what
/// the part stores in contacts of its own), booked per half kick: the forces F set at the last
/// force stage and the new forces F' act over the step just taken, so that step adds
/// dt/2 sum_i v_i . (F_i + F'_i) (trapezoidal rule, with the velocity the part kicks with).
/// The part calls moved(dt) when it advances and settle() when the new forces arrive.
struct ContactWork {
  Real work_j = 0;
  Real last_dt_s = 0;    // the step of the last advance
  bool pending = false;  // moved since the contact forces were set

  void moved(Real dt_s) {
    last_dt_s = dt_s;
    pending = true;
  }

  /// Books the step's work, power(i) being v_i . (F_i + F'_i) (plus the torques' share for
  /// rotating particles), once per advance: dt/2 times the sum over the entities i of [0, n)
  /// with own(i) (a rank's own, not its ghosts), by the reproducible sum over the ranks of
  /// `comm`, so that it has the same bits for any thread and rank count. Only the particles in
  /// contact have power: the sum takes the nonzero terms alone. Collective on ranks.
  template <class Power, class Own>
  void settle(const parallel::Comm& comm, Index n, Power&& power, Own&& own) {
    if (begin(n)) {
      const Real h = half_dt();
      parallel::for_each(n, [&](Index i) { power_[at(i)] = own(i) ? h * power(i) : Real(0); });
    }
    book(comm, n);
  }

  /// settle() for a part that computes the powers in a pass of its own (the one that takes the
  /// new forces): begin() says whether this advance's work is still to be booked, and sizes
  /// powers() for n entities; the pass then sets powers()[i] = half_dt() * power(i) for the own
  /// entities and 0 for the others, and book() books their sum as settle() does (collective
  /// on ranks).
  bool begin(Index n) {
    booking_ = pending && last_dt_s > 0;
    if (booking_) power_.resize(static_cast<std::size_t>(n));
    return booking_;
  }
  Real half_dt() const { return Real(0.5) * last_dt_s; }
  std::vector<Real>& powers() { return power_; }
  void book(const parallel::Comm& comm, Index n) {
    if (booking_) {
      const std::vector<Index> nonzero =
          parallel::select(n, [&](Index i) { return power_[at(i)] != 0; });
      add_terms(comm, nonzero);
    }
    booking_ = false;
    pending = false;
  }
  /// book() when the pass set powers()[i] for the entities `set` (ascending) alone, every other
  /// entity's power being zero: the same nonzero terms, so the same bits.
  void book_set(const parallel::Comm& comm, std::span<const Index> set) {
    if (booking_) {
      std::vector<Index> nonzero;
      for (const Index i : set)
        if (power_[at(i)] != 0) nonzero.push_back(i);
      add_terms(comm, nonzero);
    }
    booking_ = false;
    pending = false;
  }

 private:
  std::vector<Real> power_;  // settle()'s scratch
  bool booking_ = false;     // between begin() and book()

  void add_terms(const parallel::Comm& comm, std::span<const Index> nonzero) {
    std::vector<Real> terms(nonzero.size());
    for (std::size_t q = 0; q < terms.size(); ++q)
      terms[q] = power_[at(nonzero[q])];
    work_j += parallel::reproducible_sum(comm, std::span<const Real>(terms));
  }
};

/// A particle or solid part's positions as the contacts see them under multi-rate stepping
/// (Part::set_contact_lag): its own, or moved back by lag_s along the drift velocity.
template <int D>
struct LaggedPositions {
  std::vector<Vec<D>> x;
  bool active = false;

  /// lag_s > 0: x_i = own_i - lag_s drift(i) for i in [0, n); 0: the part's own again.
  template <class Drift>
  void set(const std::vector<Vec<D>>& own, Real lag_s, Drift&& drift) {
    active = lag_s != 0;
    if (!active) return;
    x.resize(own.size());
    parallel::for_each(static_cast<Index>(own.size()),
                       [&](Index i) { x[at(i)] = own[at(i)] - lag_s * drift(i); });
  }
  const std::vector<Vec<D>>* view(const std::vector<Vec<D>>& own) const {
    return active ? &x : &own;
  }
};

/// Contact forces (and torques) a part keeps for its next step's first half kick under
/// multi-rate stepping (Part::set_next_contact_forces), until its step is finished. The part
/// calls started() in advance() and, once its step is finished (or at once when it is not in
/// a step), take(f) with f(force, torque) replacing its contact forces.
template <int D>
struct NextContactForces {
  std::vector<Vec<D>> force;
  std::vector<AxialVec<D>> torque;
  bool pending = false;
  bool in_step = false;

  void started() { in_step = true; }
  /// Keeps the forces; takes them at once (take(f)) when the part is between steps.
  template <class Take>
  void set(const std::vector<Vec<D>>& f, const std::vector<AxialVec<D>>& t, Take&& take) {
    force = f;
    torque = t;
    pending = true;
    if (!in_step) finished(take);
  }
  /// The step is finished: the kept forces, if any, replace the part's.
  template <class Take>
  void finished(Take&& take) {
    in_step = false;
    if (!pending) return;
    take(force, torque);
    pending = false;
  }
};

}  // namespace crater::parts
