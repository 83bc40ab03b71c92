// The interface through which a method (SPH, DEM, FEM) joins the time loop (Algorithm 1).
// A part owns its entities as a FieldSet; the solver only calls the stages below, in order,
// once per step. Stages are coarse (one call per part per step), so the virtual call costs
// nothing; inner loops live inside each part and never dispatch per entity.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/index.hpp"
#include "core/types.hpp"
#include "fields/balance.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"
#include "parts/gathered_points.hpp"
#include "parts/state_archive.hpp"

namespace crater::parts {

struct WholeLayout;  // parts/whole_layout.hpp

/// Energies of one part [J] (per metre of depth in 2D). Work terms are accumulated since t = 0.
struct Energies {
  Real kinetic_j = 0;
  Real internal_j = 0;       // thermal + elastic + plastic work stored in the material
  Real external_work_j = 0;  // work done ON the part by gravity, walls and prescribed loads
  Real damping_j = 0;        // dissipated by damping (local, viscous walls)
  Real hourglass_j = 0;      // FEM hourglass control
  Real contact_j = 0;        // stored/dissipated in contacts
  Real eroded_j = 0;         // kinetic + internal energy of eroded entities, and of particles
                             // removed beyond the domain (outflow = "remove")
  Energies& operator+=(const Energies& o) {
    kinetic_j += o.kinetic_j;
    internal_j += o.internal_j;
    external_work_j += o.external_work_j;
    damping_j += o.damping_j;
    hourglass_j += o.hourglass_j;
    contact_j += o.contact_j;
    eroded_j += o.eroded_j;
    return *this;
  }
};

/// The limiting stable step of a part and the entity that limits it.
struct StableStep {
  Real dt_s = 0;
  Index entity_id = -1;
  std::string reason;  // e.g. "CFL, signal speed 7012 m/s"
  // An accuracy bound already well inside the stability limit (the contacts' omega dt <= 1/2):
  // the global step obeys it as it is, where stability limits are scaled by the safety factor.
  bool absolute = false;

  /// The step this limit allows under the scenario's safety factor.
  Real allowed_s(Real safety_factor) const { return absolute ? dt_s : safety_factor * dt_s; }
};

/// A problem found in a part's state: a non-finite value, a negative density, ...
struct Fault {
  Index entity_id = -1;
  std::string what;
};

/// A named count or value a part reports about its run (summary.json, `parts[].diagnostics`).
struct Diagnostic {
  std::string name;
  Real value = 0;
};

/// Entities of a part as the output writers see them: points (particles) or an unstructured
/// mesh (nodes + cells). Cells use VTK cell type ids and connectivity.
template <int D>
struct Geometry {
  const std::vector<Vec<D>>* points = nullptr;
  // Empty for particle parts (written as VTK_VERTEX cells).
  std::vector<std::int64_t> connectivity;
  std::vector<std::int64_t> offsets;  // end offsets, as VTK
  std::vector<std::uint8_t> cell_types;
};

/// What contacts between parts (src/contact/) see of a particle part: one sphere (disk) per
/// particle. Pointers stay valid until the part's next stage.
template <int D>
struct ContactPoints {
  const std::vector<Vec<D>>* position = nullptr;
  const std::vector<Vec<D>>* velocity = nullptr;
  const std::vector<Real>* mass = nullptr;                     // [kg] (per metre of depth in 2D)
  const std::vector<Real>* radius = nullptr;                   // contact radius [m]
  const std::vector<AxialVec<D>>* angular_velocity = nullptr;  // rotating particles (DEM) only
  // Per particle, kept by the part for the contacts (src/contact/coupling.hpp): the overlap
  // with a surface that is ignored (found at first touch or where a face appeared under the
  // particle), or -1 when not touching one; and the overlap at the last step [m].
  std::vector<Real>* surface_offset = nullptr;
  std::vector<Real>* surface_overlap = nullptr;
  // Each particle's id, which stays with it when others are removed (multi-rate stepping
  // follows its particles across a removal with it).
  const std::vector<std::int64_t>* id = nullptr;
  // A view of some of the part's particles (contacts on ranks: the contact zone,
  // contact/spread_coupling.hpp): the whole part's count (-1: the view is the whole part), its
  // lightest mass and largest contact radius, which the contacts' step limits and searches take.
  Index whole_count = -1;
  Real whole_lightest_kg = 0, whole_largest_radius_m = 0;
  // The lightest mass and largest contact radius of the view's particles, when the part keeps
  // them (a bed of grains: they change only when grains leave); NaN: the contacts find them
  // from `mass` and `radius`. Exactly those values when given.
  Real lightest_kg = std::numeric_limits<Real>::quiet_NaN();
  Real largest_radius_m = std::numeric_limits<Real>::quiet_NaN();
  // Contacts on ranks, a view that differs from rank to rank (owner-computed: each rank's own
  // particles and the others' that touch its own): per particle of the view, whether it is this
  // rank's own; a pair counts in the contact's sums on the rank that owns its particle of such a
  // view. Null: every particle counts (one rank, or a view alike on every rank).
  const std::vector<char>* own = nullptr;
};

/// Whether particle i of a view counts as this rank's (ContactPoints::own).
template <int D>
bool counts_here(const ContactPoints<D>& p, Index i) {
  return !p.own || (*p.own)[static_cast<std::size_t>(i)] != 0;
}

/// The particles of the part a view shows (all of them but for a contact zone's view).
template <int D>
Index whole_point_count(const ContactPoints<D>& p) {
  return p.whole_count >= 0 ? p.whole_count : static_cast<Index>(p.position->size());
}

/// Nodes of a surface face: 2 (a segment, 2D) or 4 (a quadrilateral, 3D).
template <int D>
inline constexpr int kFaceNodes = D == 2 ? 2 : 4;

/// What contacts see of a solid part: its surface faces (live elements' faces on the boundary),
/// numbered so that the outward normal is (t_y, -t_x) for the segment tangent t = x_1 - x_0
/// in 2D and (x_2 - x_0) x (x_3 - x_1) in 3D, with the element each face belongs to.
template <int D>
struct ContactSurface {
  const std::vector<Vec<D>>* node_position = nullptr;
  const std::vector<Vec<D>>* node_velocity = nullptr;
  const std::vector<Real>* node_mass = nullptr;
  const std::vector<std::array<Index, kFaceNodes<D>>>* faces = nullptr;
  const std::vector<Index>* face_element = nullptr;
  const std::vector<Real>* face_stiffness = nullptr;  // K A^2 / V of the face's element [N/m]
  std::uint64_t revision = 0;                         // changes whenever `faces` changes (erosion)
};

template <int D>
class Part {
 public:
  virtual ~Part() = default;

  virtual const std::string& name() const = 0;
  /// "sph", "dem" or "fem".
  virtual const char* method() const = 0;
  /// Number of live entities (particles, or elements for FEM).
  virtual Index count() const = 0;
  /// Total mass [kg] (per metre of depth in 2D).
  virtual Real mass_kg() const = 0;

  /// Largest step this part tolerates in its current state.
  virtual StableStep stable_step() const = 0;
  /// Stage "force": internal forces and rates for the current state at time t.
  virtual void compute_forces(Real t_s) = 0;
  /// compute_forces() in three calls, so that a part's heaviest loop can share the threads with
  /// the contact stage (solver/step.hpp): begin_forces() does what the contacts read (lists,
  /// re-sorts, ghosts) and returns how many blocks of work remain; force_block(b) for every b
  /// in [0, blocks), on any thread, in any order, concurrently with each other and with the
  /// contacts, writes only the part's own force fields, which no contact reads; end_forces()
  /// finishes the stage. The three give compute_forces()'s bits. By default the whole stage is
  /// begin_forces() and no block remains.
  virtual Index begin_forces(Real t_s) {
    compute_forces(t_s);
    return 0;
  }
  virtual void force_block(Index /*block*/) {}
  virtual void end_forces() {}
  /// The state of the next compute_forces() is one a frame writes: a part with output fields
  /// that only the force stage can derive, and that no step needs (the DEM grains' stress),
  /// computes them in that stage alone.
  virtual void expect_frame() {}
  /// Looks for non-finite or non-physical values after the force stage; the state itself
  /// is still the last good one then.
  virtual std::optional<Fault> check() const = 0;
  /// Stage "advance" (first half of velocity Verlet / kick-drift-kick): v += a dt/2,
  /// x += v dt, and the other state variables (density, energy, stress) by their rates.
  virtual void advance(Real t_s, Real dt_s) = 0;
  /// Stage "finish" (second half kick), after the forces of the new state are known:
  /// v += a dt/2. Velocities and energies are then those of time t + dt.
  virtual void finish_step(Real dt_s) = 0;

  virtual Energies energies() const = 0;

  /// For writers: point/cell geometry and the fields carrying the output role.
  virtual Geometry<D> geometry() const = 0;
  /// The points' current positions (particles, or nodes) without building the cells: for a
  /// probe that reads a few entities per step. Valid until the part's next stage.
  virtual const std::vector<Vec<D>>& points() const { return *geometry().points; }
  /// The current positions of the points numbered `numbers` as one rank numbers them (a mesh
  /// part's nodes by number), in that order, on every rank: for a probe that follows a few
  /// nodes every step. Collective on ranks (every rank passes the same numbers); the default
  /// reads points() and serves a part that is not spread (a spread mesh part overrides it).
  virtual std::vector<Vec<D>> points_numbered(const std::vector<Index>& numbers) const {
    const std::vector<Vec<D>>& x = points();
    std::vector<Vec<D>> out;
    out.reserve(numbers.size());
    for (const Index k : numbers)
      out.push_back(x.at(at(k)));
    return out;
  }
  virtual std::vector<fields::FieldView> point_fields() const = 0;
  virtual std::vector<fields::FieldView> cell_fields() const { return {}; }

  /// Spreads the part over the ranks of `comm` (issue 29, docs/distributed.md), once, before
  /// the first step, when every rank has built it whole. From then on the part's count(),
  /// mass_kg(), stable_step(), check(), energies(), diagnostics() and gathered_points() are
  /// collective: every rank calls them at the same point of the run, and they give every rank
  /// the whole part's values. A method that does not run on ranks yet throws InputError.
  virtual void distribute(const parallel::Comm& /*comm*/) {
    throw InputError({}, "parts[" + name() + "]",
                     std::string("a part of method '") + method() +
                         "' does not run on several MPI ranks yet (issue 29, "
                         "docs/distributed.md): run the scenario on one rank");
  }
  /// A spread part's frame: its points and point fields from every rank in id order, on the
  /// root rank (collective; empty elsewhere). nullopt: the part is whole here, as geometry()
  /// and point_fields() give it.
  virtual std::optional<GatheredPoints<D>> gathered_points() const { return std::nullopt; }
  /// A spread part's piece of a frame (output.pieces = "ranks"): the entities this rank owns,
  /// in its order, with their point fields (and a mesh part's own elements with their cell
  /// fields and the nodes they use, each piece carrying the global numbers `node_id` and
  /// `element_id`). A particle part's needs no communication, a mesh part's is collective (the
  /// values of its elements' nodes that other ranks own). nullopt: the part is whole here.
  virtual std::optional<GatheredPoints<D>> own_piece() const { return std::nullopt; }
  /// A spread part's local entities by their numbers in the whole part, as its frames name
  /// them: each local point's (a particle's id, a mesh node's number) and each local cell's (a
  /// mesh element's number), -1 for a ghost (another rank's entity); the same length as the
  /// point and cell fields. What the gauges read of their entities alone on ranks (no
  /// communication). nullopt: the part is whole here.
  virtual std::optional<OwnNumbers> own_numbers() const { return std::nullopt; }
  /// A spread part's share among the ranks (collective): e.g. the fewest and most entities a
  /// rank owns, the ghosts a rank holds. Empty on one rank. They depend on the rank count, so
  /// they go to summary.json's "run" block, not to the part's diagnostics.
  virtual std::vector<Diagnostic> rank_figures() const { return {}; }
  /// On ranks: the heaviest rank's load over the ranks' mean (by the weights its cuts are made
  /// with) when the part last looked at its cuts: a particle part at its last list rebuild, a
  /// mesh part at its first cut, then at its last look (every 100 steps). The same on every
  /// rank, no communication; 1 on one rank.
  virtual Real load_ratio() const { return 1; }
  /// On ranks, a part whose cuts may be made again: its measured load since they were last
  /// made (fields/balance.hpp), to which the time loop adds each step's compute seconds, and
  /// whether the cuts go by it (domain.balance = "time"). nullptr: the cuts stay (one rank).
  virtual fields::BusyClock* busy_clock() { return nullptr; }

  /// Checkpoints: everything the part needs to continue bit for bit after load_state() on a
  /// part freshly built from the same scenario (fields, accumulators, contact histories, and
  /// what its neighbour lists were built from, so that they are rebuilt identically).
  /// A method without checkpoint support says so when a checkpoint is asked for.
  virtual void save_state(parts::StateWriter& /*w*/) const {
    throw std::runtime_error(std::string("part '") + name() + "' (" + method() +
                             ") cannot write checkpoints yet");
  }
  virtual void load_state(parts::StateReader& /*r*/) {
    throw std::runtime_error(std::string("part '") + name() + "' (" + method() +
                             ") cannot read checkpoints yet");
  }

  /// Contacts with other parts: a particle part offers points, a solid part its surface. The
  /// forces of the contacts, found after compute_forces() on the same state, come back through
  /// add_contact_forces() (per particle, or per node of the solid; torques for rotating
  /// particles, else empty) and act in finish_step() and the next advance() like the part's own.
  virtual std::optional<ContactPoints<D>> contact_points() const { return std::nullopt; }
  virtual std::optional<ContactSurface<D>> contact_surface() const { return std::nullopt; }
  /// The nodes of a named group of the part's mesh file, ascending (null: no such group), for
  /// a contact restricted to it.
  virtual const std::vector<Index>* group_nodes(const std::string& /*group*/) const {
    return nullptr;
  }
  virtual void add_contact_forces(const std::vector<Vec<D>>& /*force*/,
                                  const std::vector<AxialVec<D>>& /*torque*/) {
    throw std::runtime_error(std::string("part '") + name() + "' (" + method() +
                             ") does not take part in contacts");
  }
  /// add_contact_forces() told where the forces can be nonzero: `touched` (ascending) holds
  /// every body given a force or torque by this evaluation; elsewhere both are zero. A part may
  /// then visit those and the bodies its previous contact forces touched, not all of its
  /// bodies, with the same results. The default is the call above.
  virtual void add_touched_contact_forces(const std::vector<Vec<D>>& force,
                                          const std::vector<AxialVec<D>>& torque,
                                          std::span<const Index> /*touched*/) {
    add_contact_forces(force, torque);
  }
  /// A spread part in contacts (docs/distributed.md, "Contacts on ranks"): where the entities
  /// of contact_points() (particles) or contact_surface() (a solid's nodes) sit in the whole
  /// part as one rank holds it (parts/whole_layout.hpp). Collective; valid until the part's
  /// next stage. Null on one rank.
  virtual const WholeLayout* contact_layout() const { return nullptr; }
  /// A spread solid part: the contact surface of the whole mesh, its faces numbered by the
  /// whole mesh's nodes in the order one rank lists them, given the positions of all nodes
  /// (`whole_x`, assembled by contact_layout()); its node arrays are left null. Collective.
  virtual std::optional<ContactSurface<D>> whole_contact_surface(
      const std::vector<Vec<D>>& /*whole_x*/) const {
    return std::nullopt;
  }
  /// A spread solid part: the whole mesh's nodes that whole_contact_surface reads and the
  /// contacts then read, ascending, after bringing the elements' erosion up to date from their
  /// owners: the surface's face nodes, or, when the surface is to be listed again, every node.
  /// `whole_x` need hold only these. Collective; call it before each whole_contact_surface.
  /// Null on one rank.
  virtual const std::vector<Index>* whole_surface_nodes() const { return nullptr; }

  /// Multi-rate stepping (solver/multi_rate.hpp), for a part in the middle of its step when
  /// the contacts are evaluated, lag_s before its step ends: contact_points() and
  /// contact_surface() then show the positions of that time on the part's straight path,
  /// x - lag_s v^{n+1/2} (v the velocity its last advance() drifted with). 0: its own
  /// positions again. Nothing else of the part changes.
  virtual void set_contact_lag(Real /*lag_s*/) {
    throw std::runtime_error(std::string("part '") + name() + "' (" + method() +
                             ") does not take part in contacts");
  }
  /// Multi-rate stepping: the contact forces (and torques) for the first half kick of the
  /// next step, where they differ from those add_contact_forces() gave this step's end
  /// (a part whose contacts are evaluated at a finer step than its own). Called after
  /// add_contact_forces() and before finish_step(); the part takes them when the step is
  /// finished (after any removal of its entities), without booking work: the work of the
  /// next step is booked with them.
  virtual void set_next_contact_forces(const std::vector<Vec<D>>& /*force*/,
                                       const std::vector<AxialVec<D>>& /*torque*/) {
    throw std::runtime_error(std::string("part '") + name() + "' (" + method() +
                             ") does not take part in contacts");
  }

  /// Counters worth reporting (e.g. safeguards that acted); empty by default.
  virtual std::vector<Diagnostic> diagnostics() const { return {}; }
  /// history.csv columns of the part's own (e.g. a moving wall's position and force), after
  /// the contacts' and probes' columns, and their values at the current state.
  virtual std::vector<std::string> history_columns() const { return {}; }
  virtual std::vector<Real> history_values() const { return {}; }
};

}  // namespace crater::parts
