// The FEM part's class, internal to src/fem (fem_part.hpp is the public face): its data members
// and short members. fem_part.cpp defines the longer members (construction, the step's stages,
// output fields, checkpoints, erosion, loads and boundary conditions), with their comments, and
// instantiates the class for D = 2 and 3.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "fem/boundaries.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/explicit_solid.hpp"
#include "fem/fem_mesh_source.hpp"
#include "fem/mesh_state_layout.hpp"
#include "fem/settings.hpp"
#include "fields/balance.hpp"
#include "fields/field_set.hpp"
#include "materials/strength/strength.hpp"
#include "parallel/comm.hpp"
#include "parallel/parallel.hpp"
#include "parallel/rcb.hpp"
#include "parts/contact_points.hpp"
#include "parts/gathered_points.hpp"
#include "parts/on_ranks.hpp"
#include "parts/part.hpp"
#include "parts/setup.hpp"
#include "parts/whole_layout.hpp"

namespace crater::fem::detail {

template <int D>
struct Keepers;  // fem_ranks.cpp

template <int D>
class FemPart final : public parts::Part<D> {
 public:
  explicit FemPart(const PartSettings& settings);

  const std::string& name() const override { return name_; }
  const char* method() const override { return "fem"; }
  Index count() const override;
  Real mass_kg() const override { return total_mass(); }

  parts::StableStep stable_step() const override {
    parts::StableStep s;
    s.dt_s = last_.stable_dt_s;
    s.entity_id = last_.limiting_element;
    s.reason = material_.mass_scaling_min_step_s > 0
                   ? "element size / dilatational wave speed (with bulk viscosity, mass-scaled)"
                   : "element size / dilatational wave speed (with bulk viscosity)";
    return comm_ ? parts::smallest_step(*comm_, s) : s;
  }

  void compute_forces(Real t_s) override;
  std::optional<parts::Fault> check() const override;
  void advance(Real t_s, Real dt_s) override;
  void finish_step(Real dt_s) override;

  const std::vector<Index>* group_nodes(const std::string& group) const override {
    const auto it = group_nodes_.find(group);
    return it == group_nodes_.end() ? nullptr : &it->second;
  }

  std::optional<parts::ContactSurface<D>> contact_surface() const override {
    parts::ContactSurface<D> s;
    s.node_position = lagged_.view(mesh_.position);
    s.node_velocity = &mesh_.velocity;
    s.node_mass = &mesh_.mass;
    s.faces = &surface_faces_;
    s.face_element = &surface_element_;
    s.face_stiffness = &surface_stiffness_;
    s.revision = surface_revision_;
    return s;
  }

  void set_contact_lag(Real lag_s) override {
    lagged_.set(mesh_.position, lag_s, [&](Index i) { return mesh_.velocity[at(i)]; });
  }
  void set_next_contact_forces(const std::vector<Vec<D>>& force,
                               const std::vector<AxialVec<D>>& torque) override {
    if (static_cast<Index>(force.size()) != mesh_.node_count())
      throw std::logic_error("fem: next contact forces for another node count");
    next_contact_.set(force, torque, [&](const auto& f, const auto&) { contact_force_ = f; });
  }

  void add_contact_forces(const std::vector<Vec<D>>& force,
                          const std::vector<AxialVec<D>>& torque) override;
  parts::Energies energies() const override;

  const std::vector<Vec<D>>& points() const override { return mesh_.position; }
  std::vector<Vec<D>> points_numbered(const std::vector<Index>& numbers) const override;  // ranks

  parts::Geometry<D> geometry() const override;
  std::vector<fields::FieldView> point_fields() const override;
  std::vector<fields::FieldView> cell_fields() const override;
  void save_state(parts::StateWriter& w) const override;
  void load_state(parts::StateReader& r) override;
  std::vector<parts::Diagnostic> diagnostics() const override;

  // fem_ranks.cpp: the part on several ranks.
  void distribute(const parallel::Comm& comm) override;
  fields::BusyClock* busy_clock() override { return comm_ ? &busy_ : nullptr; }
  std::optional<parts::GatheredPoints<D>> gathered_points() const override;
  std::optional<parts::GatheredPoints<D>> own_piece() const override;
  std::optional<parts::OwnNumbers> own_numbers() const override;
  Real load_ratio() const override { return load_ratio_; }
  std::vector<parts::Diagnostic> rank_figures() const override;
  const parts::WholeLayout* contact_layout() const override;
  std::optional<parts::ContactSurface<D>> whole_contact_surface(
      const std::vector<Vec<D>>& whole_x) const override;
  const std::vector<Index>* whole_surface_nodes() const override;

 private:
  static fields::FieldView scalar_view(const fields::FieldInfo& info, const std::vector<Real>& v) {
    return fields::FieldView{&info, 1, false, v.data(), nullptr, static_cast<Index>(v.size())};
  }
  static fields::FieldView vector_view(const fields::FieldInfo& info,
                                       const std::vector<Vec<D>>& v) {
    return fields::FieldView{&info,   D,
                             false,   v.empty() ? nullptr : v.front().data(),
                             nullptr, static_cast<Index>(v.size())};
  }

  /// The smallest i in [0, n) with pred(i), or -1 (the same answer for any thread count).
  template <class Pred>
  static Index first_index(Index n, Pred&& pred) {
    const Real found = parallel::min_over(n, std::numeric_limits<Real>::infinity(), [&](Index i) {
      return pred(i) ? static_cast<Real>(i) : std::numeric_limits<Real>::infinity();
    });
    return std::isfinite(found) ? static_cast<Index>(found) : Index{-1};
  }

  /// A Holmquist-Johnson-Cook part (its compaction state is saved and written).
  bool is_hjc() const {
    return std::holds_alternative<materials::HolmquistJohnsonCookLaw>(material_.strength);
  }

  /// Acceleration of the part's own forces plus the contacts' (zero on frozen nodes).
  Vec<D> total_acceleration(std::size_t u) const {
    const Real m = mesh_.mass[u];
    return m > 0 ? Vec<D>(acceleration_[u] + contact_force_[u] / m) : Vec<D>(Vec<D>::Zero());
  }

  void rebuild_surface();
  void build_node_layout(const parallel::Comm& comm);  // fem_ranks.cpp
  // fem_ranks.cpp: the cuts made again as elements erode, and this rank's share under them.
  void rebalance();
  void adopt_cuts(std::vector<int> element_owner, bool moving);
  void move_entities(const Keepers<D>& keep, const std::vector<Index>& nodes,
                     const std::vector<Index>& elements);
  void take_whole_setup(const std::vector<Index>& nodes, const std::vector<Index>& elements,
                        const std::vector<Index>& local_node,
                        const std::vector<Index>& local_element);
  Vec<D> rest_centre(Index whole_element) const;
  // The penalty stiffness K A^2 / V of each face's element, in the reference geometry.
  std::vector<Real> face_stiffness(const SurfaceFaces<D>& sf, const ExplicitMesh<D>& mesh) const;

  Real total_mass() const {
    return node_total([&](Index i) { return mesh_.mass[at(i)]; });
  }

  // On ranks (fem_ranks.cpp): whether local node i (element e) is another rank's, held here
  // for the elements of this rank's nodes; the global number of a local node or element.
  bool ghost_node(Index i) const { return !ghost_node_.empty() && ghost_node_[at(i)] != 0; }
  bool ghost_element(Index e) const {
    return !ghost_element_.empty() && ghost_element_[at(e)] != 0;
  }
  Index global_node(Index i) const { return node_id_.empty() ? i : node_id_[at(i)]; }
  Index global_element(Index e) const {
    return e < 0 || element_id_.empty() ? e : element_id_[at(e)];
  }
  // The sum of term(i) over this rank's own nodes (term(e) over its own elements) and every
  // rank's, by the reproducible sum: the same bits for any thread and rank count (collective
  // on ranks).
  template <class Term>
  Real node_total(Term&& term) const {
    return total_over(
        mesh_.node_count(), [&](Index i) { return ghost_node(i); }, term);
  }
  template <class Term>
  Real element_total(Term&& term) const {
    return total_over(
        mesh_.element_count(), [&](Index e) { return ghost_element(e); }, term);
  }
  template <class Ghost, class Term>
  Real total_over(Index n, Ghost&& ghost, Term&& term) const {
    std::vector<Real> terms;
    terms.reserve(at(n));
    for (Index k = 0; k < n; ++k)
      if (!ghost(k)) terms.push_back(term(k));
    return parallel::reproducible_sum(comm_ ? *comm_ : parallel::Comm{}, terms);
  }
  // The number of this rank's own elements with pred(e), over every rank (collective).
  template <class Pred>
  Index element_count_of(Pred&& pred) const {
    std::int64_t n = 0;
    for (Index e = 0; e < mesh_.element_count(); ++e)
      if (!ghost_element(e) && pred(e)) ++n;
    return static_cast<Index>(comm_ ? comm_->sum(n) : n);
  }
  // Ghost nodes: their positions and velocities from their owners (after every drift).
  void refresh_ghosts();

  // The checkpoint's vectors in their order, each(vector, entity, what): the mesh's state,
  // then the part's (fem_part.cpp's save_state and load_state; fem_ranks.cpp gathers them).
  template <class Self, class Each>
  static void for_each_state_vector(Self& s, Each&& each) {
    constexpr MeshEntity node = MeshEntity::node, element = MeshEntity::element;
    for_each_mesh_state_vector(s.mesh_, s.is_hjc(), each);
    each(s.acceleration_, node, "accelerations");
    each(s.external_force_, node, "external forces");
    each(s.dashpot_force_, node, "dashpot forces");
    each(s.live_elements_of_node_, node, "node element counts");
    each(s.element_accounted_, element, "erosion records");
    each(s.contact_force_, node, "contact forces");
    each(s.work_external_, node, "external work");
    each(s.work_damping_, node, "dashpot work");
    each(s.work_contact_, node, "contact work");
    each(s.eroded_mass_of_node_, node, "eroded masses");
    each(s.eroded_kinetic_of_node_, node, "eroded kinetic energies");
  }
  // The checkpoint's values after the vectors, for both directions (`report` and
  // `mass_scaled_first`: the last force evaluation's findings, the whole part's on ranks).
  template <class Archive, class Self, class Report, class First>
  static void archive_values(Archive& a, Self& s, Report& report, First& mass_scaled_first) {
    a.value(s.contact_pending_);
    a.value(report.stable_dt_s);
    a.value(report.limiting_element);
    a.value(report.inverted_element);
    a.value(report.first_mass_scaled_element);
    a.value(s.dt_pending_);
    a.value(s.stale_);
    a.value(mass_scaled_first);
  }
  void save_gathered(parts::StateWriter& w) const;
  // Every vector with an entry per node or element that the part carries from step to step,
  // each(vector, entity): the checkpoint's, those allocated but not saved (the compaction state
  // of a law without it), and the boundary conditions; a cut made again moves them all.
  template <class Each>
  void for_each_carried_vector(Each&& each) {
    for_each_state_vector(*this, [&](auto& v, MeshEntity entity, const char*) { each(v, entity); });
    if (!is_hjc()) {
      each(mesh_.mu_max, MeshEntity::element);
      each(mesh_.plastic_volumetric_strain, MeshEntity::element);
    }
    each(constrained_, MeshEntity::node);
    each(imposed_velocity_, MeshEntity::node);
    each(dashpot_of_node_, MeshEntity::node);
    if (!loads_.empty()) each(load_force_, MeshEntity::node);
  }

  void impose_velocity(std::size_t u) {
    const unsigned c = constrained_[u];
    if (c == 0) return;
    for (int k = 0; k < D; ++k)
      if (c & (1u << k)) mesh_.velocity[u][k] = imposed_velocity_[u][k];
  }
  void impose_velocities() {
    for (Index i = 0; i < mesh_.node_count(); ++i)
      impose_velocity(at(i));
  }

  void account_erosion();
  void add_pressure_load(const MeshSource<D>& source, const LoadSettings& l);
  void pressure_forces(Real t_s);
  void apply_boundary_config(const MeshSource<D>& source, const BoundarySettings& b);
  void apply_symmetry_planes(const parts::PartSetup& pc);

  std::string name_;
  SolidMaterial material_;
  ExplicitMesh<D> mesh_;
  Vec<D> gravity_ = Vec<D>::Zero();
  Real initial_mass_ = 0;

  std::vector<RigidWall<D>> walls_;

  // Boundary conditions, per node: bit k of constrained_ = component k imposed.
  std::vector<std::uint8_t> constrained_;
  std::vector<Vec<D>> imposed_velocity_;
  std::vector<Index> dashpot_of_node_;  // index into dashpot_matrix_, or -1
  std::vector<MatD<D>> dashpot_matrix_;

  // Pressure loads ([[parts.fem.loads]]) and their nodal forces at the last force evaluation.
  struct PressureLoad {
    std::vector<Real> time_s, pressure_pa;
    std::vector<std::array<Index, parts::kFaceNodes<D>>> faces;
    std::vector<Index> element;
  };
  std::vector<PressureLoad> loads_;
  std::vector<Vec<D>> load_force_;  // empty without loads

  // State between stages.
  std::vector<Vec<D>> acceleration_;
  std::vector<Vec<D>> external_force_;  // gravity + reactions at the last force evaluation
  std::vector<Vec<D>> dashpot_force_;
  std::vector<Index> live_elements_of_node_;
  std::vector<std::uint8_t> element_accounted_;
  std::vector<Vec<D>> contact_force_;  // from the contacts at the last force evaluation
  bool contact_pending_ = false;       // the nodes moved since the contact forces were set
  parts::LaggedPositions<D> lagged_;   // node positions the contacts see (multi-rate stepping)
  parts::NextContactForces<D> next_contact_;  // for the next step's first half kick

  // Contact surface (parts::ContactSurface).
  std::vector<std::array<Index, parts::kFaceNodes<D>>> surface_faces_;
  std::vector<Index> surface_element_;
  std::vector<Real> surface_stiffness_;
  std::uint64_t surface_revision_ = 0;
  FaceIndex<D> face_index_;  // the mesh's faces by key, for rebuild_surface
  std::map<std::string, std::vector<Index>> group_nodes_;  // the mesh file's physical groups
  ForceReport last_;
  Real dt_pending_ = 0;  // the step the nodes moved by since the last force evaluation
  bool stale_ = true;    // the nodes moved since then

  // Accounts per node since t = 0 [J], [kg], summed when asked (energies, diagnostics) so that
  // the sums have the same bits on any rank count: the work of the external forces (gravity,
  // reactions, walls, the supports' share of the contacts), the dashpots' dissipation (mass
  // scaling's is the mesh's), the contacts' work, and the mass and kinetic energy that left the
  // node with its eroded elements. An eroded element's internal and hourglass energy stays in
  // its own entries (frozen at its failure).
  std::vector<Real> work_external_;
  std::vector<Real> work_damping_;
  std::vector<Real> work_contact_;
  std::vector<Real> eroded_mass_of_node_;
  std::vector<Real> eroded_kinetic_of_node_;
  // Mass scaling: the limit (fraction of initial_mass_) and the lowest-numbered (global)
  // element scaled so far here, or -1 (the mass added is the mesh's added_mass_kg).
  Real mass_scaling_limit_ = 0;
  Index mass_scaled_first_ = -1;

  // On ranks (fem_ranks.cpp; all empty on one rank): the elements this rank owns (a bisection
  // of their centres at rest) and those of its own nodes (a node is the rank's of its
  // lowest-numbered element); the nodes of those elements, ascending in their global numbers.
  const parallel::Comm* comm_ = nullptr;
  std::vector<Index> node_id_, element_id_;  // local -> global number
  std::vector<std::uint8_t> ghost_node_, ghost_element_;
  /// The owners' values of every ghost node, `bytes` each (collective; fem_ranks.cpp).
  template <class Pack, class Unpack>
  void exchange_ghost_nodes(std::size_t bytes, Pack&& pack, Unpack&& unpack) const;
  // On ranks: the heaviest rank's load over the mean, at the first cut (elements) or the last
  // look at the cuts (rebalance: live elements, or measured time).
  Real load_ratio_ = 1;
  std::vector<int> element_owner_, node_owner_;  // per whole element and node: its rank
  std::optional<parallel::RcbTree<D>> cuts_;     // the last cuts made again (none: the first)
  fields::BusyClock busy_;                       // the measured load since the cuts (by time)
  Index count_window_ = 0;                       // steps since the last look (by count)
  Index rebalances_ = 0;                         // how often the cuts were made again
  std::vector<PressureLoad> whole_loads_;        // loads_ in the whole mesh's numbering
  std::map<std::string, std::vector<Index>> whole_group_nodes_;  // group_nodes_, likewise
  std::vector<std::vector<Index>> send_nodes_;     // per rank: own nodes it holds, ascending
  std::vector<std::vector<Index>> receive_nodes_;  // per rank: its nodes held here, ascending
  Index whole_nodes_ = 0, whole_elements_ = 0;
  std::vector<ElementNodes<D>> whole_elements_nodes_;  // the root's: the frames' cells
  // The contacts on ranks see the surface of the whole mesh (whole_contact_surface): the mesh
  // as it was before the cut, its erosion brought up to date from the elements' owners.
  mutable ExplicitMesh<D> whole_mesh_;
  mutable parts::WholeLayout node_layout_;  // contact_layout(): nodes in their numbering
  mutable std::vector<std::array<Index, parts::kFaceNodes<D>>> whole_faces_;
  mutable std::vector<Index> whole_face_element_;
  mutable std::vector<Real> whole_face_stiffness_;
  mutable FaceIndex<D> whole_face_index_;      // whole_mesh_'s faces by key
  mutable std::uint64_t whole_revision_ = 0;   // of whole_faces_ (0: none built yet)
  mutable std::uint64_t synced_revision_ = 0;  // surface_revision_ when last brought up to date
  mutable bool whole_relist_ = false;          // erosion synced, the faces not yet listed again
  mutable std::vector<Index> whole_surface_nodes_;  // whole_surface_nodes()

  // Output scratch.
  mutable std::vector<Vec<D>> displacement_;
  mutable std::vector<Vec<D>> reaction_;  // the supports' force on each node (point_fields)
  mutable std::vector<Real> von_mises_, pressure_, density_;
  mutable std::vector<std::int64_t> eroded_flag_;
};

}  // namespace crater::fem::detail
