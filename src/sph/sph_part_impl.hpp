// SPH equations as implemented (docs/theory.md has them with the paper's numbers). With the
// particle volume V_j = m_j / rho_j (the multiphase form of Colagrossi & Landrini 2003, J.
// Comput. Phys. 191, 448, which stays well behaved across density jumps such as a shock
// tube's contact or a charge's edge; for uniform mass it is the paper's eqs. 32 and 34):
//   continuity (32):  d rho_i/dt = rho_i sum_j V_j v_ij . grad_i W_ij
//   momentum (34):    d v_i/dt   = -1/rho_i sum_j V_j (p_i + p_j) grad_i W_ij
//                                  - sum_j m_j (Pi_ij + R_ij f_ij^4) grad_i W_ij
//                                  + (viscous term, eq. 36) + g
//   energy:           d e_i/dt   = p_i/rho_i sum_j V_j v_ij . grad_i W_ij
//                                  + 1/2 sum_j m_j Pi_ij v_ij . grad_i W_ij + viscous heating
//                                  + sum_j m_j alpha_u v_sig^u (e_i - e_j)/rhobar r_hat . grad_i W
//                                    (artificial conductivity, Price 2008; off by default)
//   Monaghan viscosity: Pi_ij = (-alpha cbar mu + beta mu^2) / rhobar for v_ij . r_ij < 0,
//                       mu = hbar v_ij . r_ij / (r_ij^2 + 0.01 hbar^2)
// Pairs use hbar = (h_i + h_j)/2, so grad_i W_ij = -grad_j W_ji and pair forces are equal and
// opposite: momentum is conserved to round-off; kinetic + internal energy is conserved by the
// semi-discrete equations (the energy equation is the one that balances the momentum
// equation's pressure work pair by pair), and by the wall terms (energy_rate, pair_terms.hpp).
// Each particle gathers over its own neighbour list (ascending j), so the sums are evaluated in
// the same order for any number of threads (bit-identical results). With density = "summation"
// the density is summed and h solved with it (summation.hpp), and the pressure terms take their
// grad-h form (pair_terms.hpp, gather_pair_grad_h).
//
// The SPH part's class, internal to src/sph (sph_part.hpp is the public face). Its members are
// defined by concern, each file instantiating its own for D = 2 and 3:
//   sph_part.cpp   construction, the step's stages (stable step, forces, advance, finish),
//                  contacts with other parts, energies, outflow removal, the neighbour lists,
//                  checkpoints, make_sph_part
//   sph_rates.cpp  the force stage's kernels: summation density, EOS, the wall particles' and
//                  mirror images' states, the pair sums (rates), the smoothing lengths
//   sph_ranks.cpp  the part spread over MPI ranks (docs/distributed.md, "The SPH part on ranks")
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/axial_vec.hpp"
#include "core/index.hpp"
#include "core/types.hpp"
#include "fields/field_set.hpp"
#include "fields/spread.hpp"
#include "materials/eos/eos.hpp"
#include "neighbors/neighbor_list.hpp"
#include "neighbors/verlet_skin.hpp"
#include "parallel/parallel.hpp"
#include "parts/contact_points.hpp"
#include "parts/outflow.hpp"
#include "parts/part.hpp"
#include "parts/region.hpp"
#include "parts/whole_layout.hpp"
#include "sph/burn.hpp"
#include "sph/pair_terms.hpp"
#include "sph/settings.hpp"
#include "sph/sph_walls.hpp"
#include "sph/summation.hpp"

namespace crater::sph::detail {

constexpr Real kSkin = 0.25;  // neighbour-list margin, as a fraction of a particle's support
constexpr Real kInf = std::numeric_limits<Real>::infinity();
// Summation density: h is at most this many times h_factor (m / rho0)^(1/D), the particle's h at
// the material's reference density (the wall and image lists are built for the largest h).
constexpr Real kMaxHGrowth = 3;

template <int D>
class SphPart final : public parts::Part<D> {
 public:
  explicit SphPart(const PartSettings& settings);

  const std::string& name() const override { return name_; }
  const char* method() const override { return "sph"; }
  Index count() const override;
  Real mass_kg() const override {
    return total([&](Index i) { return m_[i]; });
  }

  parts::StableStep stable_step() const override;
  void compute_forces(Real t) override;
  std::optional<parts::Fault> check() const override;
  void advance(Real t, Real dt) override;
  void finish_step(Real dt) override;

  /// Particles as contacts see them: spheres (disks) of half their volume-equivalent size,
  /// (m / rho)^(1/D) / 2, moving at the predicted velocity.
  std::optional<parts::ContactPoints<D>> contact_points() const override;
  void set_contact_lag(Real lag_s) override {
    // The drift of advance(): the half-step velocity and the XSPH correction.
    lagged_.set(x_, lag_s, [&](Index i) { return Vec<D>(vh_[i] + dx_xsph_[i]); });
  }
  void set_next_contact_forces(const std::vector<Vec<D>>& force,
                               const std::vector<AxialVec<D>>& torque) override;
  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& torque) override;

  parts::Energies energies() const override;

  parts::Geometry<D> geometry() const override {
    parts::Geometry<D> g;
    g.points = &x_;
    return g;
  }
  std::vector<fields::FieldView> point_fields() const override { return f_.views(fields::kOutput); }

  std::vector<parts::Diagnostic> diagnostics() const override {
    std::vector<parts::Diagnostic> d;
    if (has_walls_) {
      d.push_back({"wall_reflections", static_cast<Real>(all_reflections())});
      d.push_back({"wall_max_penetration_m", global_max(max_penetration_)});
    }
    if (outflow_remove_) outflow_.add_diagnostics(d);
    return d;
  }

  void save_state(parts::StateWriter& w) const override;
  void load_state(parts::StateReader& r) override;

  // sph_ranks.cpp: the part on several ranks.
  void distribute(const parallel::Comm& comm) override;
  std::optional<parts::GatheredPoints<D>> gathered_points() const override;
  std::optional<parts::GatheredPoints<D>> own_piece() const override;
  std::optional<parts::OwnNumbers> own_numbers() const override;
  Real load_ratio() const override { return spread_.load_ratio(); }
  fields::BusyClock* busy_clock() override { return spread_.active() ? &spread_.busy() : nullptr; }
  std::vector<parts::Diagnostic> rank_figures() const override;
  const parts::WholeLayout* contact_layout() const override;

 private:
  Real initial_energy(Real rho, std::optional<Real> pressure) const {
    if (const auto* jwl = std::get_if<materials::JwlParams>(&eos_))
      return jwl->e0_j_m3 / jwl->rho0_kg_m3;  // chemical energy, released by the burn
    if (const auto* gas = std::get_if<materials::IdealGasParams>(&eos_))
      return pressure.value_or(0.0) / ((gas->gamma - 1) * rho);
    return 0;  // Tait: pressure follows from density alone
  }

  // A particle that crossed a walled face is put back (sph_walls.hpp, reflect_at_walls),
  // counted in summary.json: `wall_reflections` and `wall_max_penetration_m`.
  void reflect_at_walls(Index i) {
    const Reflection r =
        sph::reflect_at_walls<D>(cfg_.walls, domain_lo_, domain_hi_, x_[i], vh_[i], a_[i]);
    if (r.faces > 0) {
#pragma omp critical(crater_sph_reflections)
      {
        reflections_ += r.faces;
        max_penetration_ = std::max(max_penetration_, r.deepest);
      }
    }
  }

  // On ranks: whether particle i is a copy of another rank's (a ghost: never integrated, its
  // fields refreshed from its owner); the largest value over the ranks.
  bool ghost(Index i) const {
    return spread_.ghost(i);
  }
  Real global_max(Real x) const {
    return spread_.active() ? spread_.comm().max(x) : x;
  }
  Index all_reflections() const {
    return spread_.active() ? static_cast<Index>(spread_.comm().sum(reflections_)) : reflections_;
  }
  // The sum over the part's particles (this rank's own) and `extra`, by the reproducible sum: the
  // same bits for any thread and rank count (collective on ranks).
  template <class Term>
  Real total(Term&& term, Real extra = 0) const {
    std::vector<Real> terms;
    terms.reserve(static_cast<std::size_t>(f_.size()) + 1);
    for (Index i = 0; i < f_.size(); ++i)
      if (!ghost(i)) terms.push_back(term(i));
    terms.push_back(extra);
    return parallel::reproducible_sum(spread_.active() ? spread_.comm() : parallel::Comm{}, terms);
  }

  bool in_domain(Index i) const {
    return parts::in_box<D>(x_[i], domain_lo_, domain_hi_);
  }
  bool healthy(Index i) const {
    return std::isfinite(drho_[i]) && std::isfinite(de_[i]) && a_[i].allFinite() && rho_[i] > 0 &&
           std::isfinite(p_[i]) && (outflow_remove_ ? x_[i].allFinite() : in_domain(i));
  }
  bool summation() const {
    return cfg_.density == DensityKind::Summation;
  }

  // sph_part.cpp: outflow removal, the neighbour lists, the checkpoint layout.
  void remove_outflow();
  void update_neighbors();
  bool lists_stale() const;
  void relist(bool sort);
  void set_list_h();
  void build_lists();
  void resort(Real cell_m);  // the canonical order: cells of cell_m, ids breaking ties
  // The checkpoint layout; `whole`, `skin` and the wall counts are the part's own on one rank, the
  // gathered part's on ranks (save_gathered).
  // `wall_rho`: the wall particles' densities (wall_.rho; on ranks, shared_wall_density()'s).
  template <class Archive, class Self, class Fields, class Skin, class Count, class Depth,
            class WallRho>
  static void archive(Archive& a, Self& s, Fields& whole, Skin& skin, Count& reflections,
                      Depth& penetration, WallRho& wall_rho) {
    a.tag("sph");
    a.block(whole);
    a.value(s.h_max_);
    a.value(s.external_work_);
    a.value(s.contact_.work_j);
    a.value(s.contact_.last_dt_s);
    a.value(s.contact_.pending);
    a.value(reflections);
    a.value(penetration);
    a.block(skin);
    a.block(s.outflow_);
    // A wall particle without fluid in reach keeps the density of its last average, which the
    // summation density reads (kernel_sum) before the next average.
    if (!s.wall_x_.empty()) a.vector(wall_rho);
  }

  // sph_ranks.cpp.
  Real halo_reach(Real radius) const {  // a wall particle's fluid neighbours: twice the reach
    return wall_x_.empty() ? radius : 2 * radius;
  }
  void save_gathered(parts::StateWriter& w) const;
  // The wall particles' densities, each from a rank that holds every fluid particle its list can
  // hold (wall_complete_), on every rank. Collective.
  std::vector<Real> shared_wall_density() const;
  // Sets wall_complete_ for the lists just built from `xb` with reach `radius` (on ranks).
  void mark_complete_walls(std::span<const Vec<D>> xb, Real radius);

  // sph_rates.cpp: the force stage. Its member templates and always_inline helpers are defined
  // and used there alone.
  void ghost_state();
  void pair_rates();
  void update_smoothing_lengths();
  void summation_density();  // with the part's kernel
  template <class Kernel>
  void summation_density();
  template <class Kernel>  // inlined as when the class had internal linkage (one .cpp)
  [[gnu::always_inline]] inline KernelSum<Kernel> kernel_sum(Index i, Real h) const;
  void update_eos(Real t);
  template <class Kernel>
  void wall_state();
  template <class Kernel>
  void rates();
  [[gnu::always_inline]] inline Centre<D> centre(const RateParams& c, Index i) const;
  [[gnu::always_inline]] inline Neighbour<D> fluid_neighbour(const Vec<D>& rij, Index j) const;
  [[gnu::always_inline]] inline Neighbour<D> wall_neighbour(const Vec<D>& rij, Index w) const;
  [[gnu::always_inline]] inline Neighbour<D> ghost_neighbour(const Vec<D>& rij, Index g) const;
  [[gnu::always_inline]] static inline Neighbour<D> with_grad_h(Neighbour<D> n, Real h, Real omega);

  std::string name_;
  SourceLocation where_;  // of the part in the scenario (errors)
  materials::EosParams eos_;
  Settings cfg_;
  Real spacing_;
  Real rho_material_;  // the material's reference density (the summation density's h cap)
  Vec<D> gravity_, domain_lo_, domain_hi_;
  bool outflow_remove_ = false;  // domain.outflow = "remove" (remove_outflow)
  ProgrammedBurn burn_model_;
  Real cell_volume_ = 0;
  Real h0_ = 0;

  fields::FieldSet<D> f_;
  std::vector<std::int64_t>& id_;
  std::vector<Vec<D>>& x_;
  std::vector<Vec<D>>& v_;
  std::vector<Real>& m_;
  std::vector<Real>& rho_;
  std::vector<Real>& e_;
  std::vector<Real>& h_;
  std::vector<Real>& p_;
  std::vector<Real>& c_;
  std::vector<Real>& burn_;
  std::vector<Real>& light_;
  std::vector<Vec<D>>& a_;
  std::vector<Real>& drho_;
  std::vector<Real>& de_;
  std::vector<Vec<D>>& dx_xsph_;
  std::vector<Vec<D>>& vh_;
  std::vector<Real>& rhoh_;
  std::vector<Real>& eh_;
  std::vector<Real>& dt_cv_;
  std::vector<Real>& omega_;       // summation density: Omega_i of the grad-h terms (1 otherwise)
  std::vector<Real>& h_list_;      // the h its lists serve (rebuild_lists); saved: same lists
  std::vector<Real>& h_wanted_;    // summation density: a larger h than the lists serve, or 0
  std::vector<Real>& list_reach_;  // build_lists: (1 + kSkin) x the support of h_list
  std::vector<Vec<D>>& fc_;        // force of the contacts with other parts (in a_ too)
  parts::LaggedPositions<D> lagged_;          // positions the contacts see (multi-rate stepping)
  parts::NextContactForces<D> next_contact_;  // for the next step's first half kick
  /// Multi-rate: the next step starts with other contact forces than the last one ended with.
  void take_contact(const std::vector<Vec<D>>& force) {
    parallel::for_each(f_.size(), [&](Index i) {
      a_[i] += (force[at(i)] - fc_[i]) / m_[i];
      fc_[i] = force[at(i)];
    });
  }
  std::vector<Real>& surface_offset_;   // parts::ContactPoints::surface_offset
  std::vector<Real>& surface_overlap_;  // parts::ContactPoints::surface_overlap
  std::vector<Real>& work_external_;    // done on it by gravity [J], since t = 0
  mutable std::vector<Real> contact_radius_;
  // What changes the particles' masses or densities (advance, compute_forces, finish_step,
  // load_state, distribute) moves state_epoch_ on; contact_points() measures the radii again
  // only then (the contacts ask for them several times a step).
  std::uint64_t state_epoch_ = 0;
  mutable std::uint64_t radius_epoch_ = ~std::uint64_t{0};
  parts::ContactWork contact_;  // work of the contact forces on the part

  // Fixed wall particles (not part of the FieldSet: they are not entities of the part).
  std::vector<Vec<D>> wall_x_, wall_mirror_;
  WallState<D> wall_;  // their pressure, density, sound speed and velocity (average_wall_state)
  // On ranks, per wall particle: whether it lies within the lists' reach of the box of this
  // rank's own particles at the last build, so that this rank holds (as its own or as ghosts)
  // every fluid particle of its list as one rank has it, and averages it as one rank does
  // (wall_state averages only these; the others keep their values). Empty on one rank.
  std::vector<std::uint8_t> wall_complete_;

  Ghosts<D> ghosts_;               // mirror images behind free-slip walls
  std::vector<Real> ghost_reach_;  // build_lists: per image its parent's list reach

  neighbors::NeighborList list_, wall_to_fluid_, fluid_to_wall_, fluid_to_ghost_;
  std::vector<neighbors::NeighborList> levels_;  // build_pair_radius_list's scratch
  Real h_max_ = 0;
  Real external_work_ = 0;  // of the particles removed (outflow) [J]
  bool has_walls_ = false;
  Index reflections_ = 0;
  Real max_penetration_ = 0;  // deepest crossing of a walled face that was reflected [m]
  neighbors::VerletSkin<D> skin_{kSkin};

  // Particles removed beyond the domain box (outflow = "remove"): how many, their mass [kg] and
  // their kinetic + internal energy when removed [J] (eroded_j).
  parts::OutflowRemoval outflow_;
  Real time_s_ = 0;                            // of the last force stage, for the log
  fields::Spread<D> spread_;                   // on ranks: the cuts, the ghosts and their exchanges
  mutable parts::WholeLayout contact_layout_;  // contact_layout()'s, on ranks
  mutable Index contact_layout_builds_ = -1;   // skin_.builds() it was made at (-1: none)
};

}  // namespace crater::sph::detail
