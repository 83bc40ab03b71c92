// The FEM part; see fem_part.hpp. Its class is in fem_part_impl.hpp; here are the class's
// longer members and make_fem_part.
#include "fem/fem_part.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/index.hpp"
#include "fem/boundaries.hpp"
#include "fem/explicit_mesh.hpp"
#include "fem/explicit_solid.hpp"
#include "fem/fem_mesh_source.hpp"
#include "fem/fem_output_fields.hpp"
#include "fem/fem_part_impl.hpp"
#include "fem/geostatic.hpp"
#include "fem/mesh_state_layout.hpp"
#include "parallel/parallel.hpp"
#include "parts/contact_points.hpp"
#include "parts/region.hpp"

namespace crater::fem {
namespace {

/// The element-loop material of a part.
SolidMaterial solid_material(const PartSettings& settings) {
  const Settings& f = settings.fem;
  SolidMaterial s;
  s.strength = settings.material.strength;
  s.damage = settings.material.damage;
  s.erode_at_full_damage = settings.material.erode_at_full_damage;
  s.density_kg_m3 = settings.rho0_kg_m3;
  s.initial_temperature_k = f.initial_temperature_k;
  s.hourglass.form = f.hourglass_stiffness ? HourglassForm::kStiffness : HourglassForm::kViscous;
  s.hourglass.coefficient = f.hourglass_coefficient;
  s.bulk_viscosity.quadratic = f.bulk_viscosity_quadratic;
  s.bulk_viscosity.linear = f.bulk_viscosity_linear;
  if (f.erosion_plastic_strain) s.erosion_plastic_strain = *f.erosion_plastic_strain;
  s.erode_inverted = f.erode_inverted;
  return s;
}

/// A tabulated history: linear between the points, zero before the first and after the last.
Real tabulated(const std::vector<Real>& t, const std::vector<Real>& v, Real time) {
  if (t.empty() || time < t.front() || time > t.back()) return 0;
  const auto hi = std::upper_bound(t.begin(), t.end(), time);
  if (hi == t.end()) return v.back();
  const std::size_t j = static_cast<std::size_t>(hi - t.begin());
  const Real w = (time - t[j - 1]) / (t[j] - t[j - 1]);
  return (1 - w) * v[j - 1] + w * v[j];
}

}  // namespace

namespace detail {

template <int D>
FemPart<D>::FemPart(const PartSettings& settings)
    : name_(settings.part.name), material_(solid_material(settings)) {
  const parts::PartSetup& pc = settings.part;
  MeshSource<D> source = build_mesh_source<D>(settings);
  if (source.reordered > 0)
    spdlog::warn(
        "part '{}': {} elements of {} were numbered clockwise (as seen along the normal); "
        "their node order was mirrored",
        name_, source.reordered, settings.fem.mesh_file);
  mesh_ = std::move(source.mesh);
  initialise(mesh_, material_);
  if (const auto& g = settings.fem.geostatic)  // the stress at t = 0 (a restart loads its own)
    apply_geostatic_stress(mesh_, material_, *g, pc.domain.gravity_m_s2, name_);
  // The erosion floor follows from the mesh at rest (the same on a restart).
  if (settings.fem.erosion_step_ratio > 0)
    material_.erosion_min_step_s =
        settings.fem.erosion_step_ratio * stable_time_step(mesh_, material_);
  // So does the mass-scaling floor.
  if (settings.fem.mass_scaling_step_ratio > 0) {
    material_.mass_scaling_min_step_s =
        settings.fem.mass_scaling_step_ratio * stable_time_step(mesh_, material_);
    mass_scaling_limit_ = settings.fem.mass_scaling_limit;
  }
  const Index nn = mesh_.node_count();
  for (int k = 0; k < D; ++k)
    gravity_[k] = pc.domain.gravity_m_s2[at(k)];
  Vec<D> v0;
  for (int k = 0; k < D; ++k)
    v0[k] = pc.initial.velocity_m_s[at(k)];
  mesh_.velocity.assign(at(nn), v0);
  // Zones set the initial velocity of the nodes inside them (later zones win).
  for (const auto& z : pc.zones) {
    if (!z.velocity_m_s) continue;
    Vec<D> vz;
    for (int k = 0; k < D; ++k)
      vz[k] = (*z.velocity_m_s)[at(k)];
    for (Index i = 0; i < nn; ++i)
      if (parts::region_contains<D>(z.region, mesh_.reference_position[at(i)]))
        mesh_.velocity[at(i)] = vz;
  }
  initial_mass_ = total_mass();

  live_elements_of_node_.assign(at(nn), 0);
  for (const auto& nodes : mesh_.elements)
    for (Index n : nodes)
      ++live_elements_of_node_[at(n)];
  element_accounted_.assign(at(mesh_.element_count()), 0);
  constrained_.assign(at(nn), 0);
  imposed_velocity_.assign(at(nn), Vec<D>::Zero());
  dashpot_of_node_.assign(at(nn), -1);
  acceleration_.assign(at(nn), Vec<D>::Zero());
  external_force_.assign(at(nn), Vec<D>::Zero());
  dashpot_force_.assign(at(nn), Vec<D>::Zero());
  contact_force_.assign(at(nn), Vec<D>::Zero());
  for (auto* book : {&work_external_, &work_damping_, &work_contact_, &eroded_mass_of_node_,
                     &eroded_kinetic_of_node_})
    book->assign(at(nn), 0);
  rebuild_surface();
  for (const auto& b : settings.fem.boundaries)
    apply_boundary_config(source, b);
  walls_ = rigid_walls<D>(settings.fem.rigid_walls, mesh_.position, name_);
  apply_symmetry_planes(pc);
  for (const auto& l : settings.fem.loads)
    add_pressure_load(source, l);
  for (auto& [name, set] : source.groups)  // for contacts restricted to a group
    group_nodes_.emplace(name, std::move(set.nodes));
  if (!loads_.empty()) load_force_.assign(at(nn), Vec<D>::Zero());
  impose_velocities();

  last_.stable_dt_s = stable_time_step(mesh_, material_);
}

template <int D>
void FemPart<D>::compute_forces(Real t_s) {
  if (!stale_) return;
  last_ = compute_internal_forces(mesh_, material_, dt_pending_);
  // The elements it names by their global numbers (on ranks).
  last_.limiting_element = global_element(last_.limiting_element);
  last_.inverted_element = global_element(last_.inverted_element);
  last_.first_mass_scaled_element = global_element(last_.first_mass_scaled_element);
  if (last_.first_mass_scaled_element >= 0 &&
      (mass_scaled_first_ < 0 || last_.first_mass_scaled_element < mass_scaled_first_))
    mass_scaled_first_ = last_.first_mass_scaled_element;
  if (last_.newly_eroded > 0) account_erosion();
  if (!loads_.empty()) pressure_forces(t_s);
  const Real dt = dt_pending_;
  const Index nn = mesh_.node_count();
  // New accelerations and the work of the external forces over the step just taken
  // (trapezoidal in the force: dx . (f^n + f^{n+1}) / 2 with dx = v^{n+1/2} dt).
  parallel::for_each(nn, [&](Index i) {
    const std::size_t u = at(i);
    const Real m = mesh_.mass[u];
    if (!(m > 0)) {
      acceleration_[u].setZero();
      external_force_[u].setZero();
      dashpot_force_[u].setZero();
      return;
    }
    const Vec<D>& v = mesh_.velocity[u];
    Vec<D> external = m * gravity_;
    if (!load_force_.empty()) external += load_force_[u];
    Vec<D> dashpot = Vec<D>::Zero();
    if (const Index d = dashpot_of_node_[u]; d >= 0) dashpot = -(dashpot_matrix_[at(d)] * v);
    Vec<D> f = mesh_.internal_force[u] + external + dashpot;
    for (int k = 0; k < D; ++k)
      if (constrained_[u] & (1u << k)) {
        external[k] -= f[k];  // the reaction holding the imposed component
        f[k] = 0;
      }
    acceleration_[u] = f / m;
    if (dt > 0) {
      work_external_[u] += Real(0.5) * dt * v.dot(external_force_[u] + external);
      work_damping_[u] -= Real(0.5) * dt * v.dot(dashpot_force_[u] + dashpot);
    }
    external_force_[u] = external;
    dashpot_force_[u] = dashpot;
  });
  stale_ = false;
}

template <int D>
std::optional<parts::Fault> FemPart<D>::check() const {
  // Every rank takes the same decisions (the mass added: a sum over all of them).
  if (material_.mass_scaling_min_step_s > 0) {
    const Real added = element_total([&](Index e) { return mesh_.added_mass_kg[at(e)]; });
    if (added > mass_scaling_limit_ * initial_mass_) {
      parts::Ranked first;
      if (mass_scaled_first_ >= 0) first.id = mass_scaled_first_;
      if (comm_) first = parts::smallest_over_ranks(*comm_, first);
      return parts::Fault{
          first.id,
          fmt::format("mass scaling has added {:.4g} kg, {:.3g} % of the part's initial mass, "
                      "past fem.mass_scaling_limit = {:.3g}; raise the limit, lower "
                      "fem.mass_scaling_step_ratio, or let crushed elements erode "
                      "(fem.erosion_step_ratio)",
                      added, 100 * added / initial_mass_, mass_scaling_limit_)};
    }
  }
  auto mine = [&]() -> std::optional<parts::Fault> {
    if (last_.inverted_element >= 0)
      return parts::Fault{last_.inverted_element,
                          "element inverted (volume <= 0): the mesh is tangled; lower "
                          "time.safety_factor or raise the hourglass coefficient"};
    const Index bad = first_index(mesh_.node_count(), [&](Index i) {
      return !ghost_node(i) &&
             (!acceleration_[at(i)].allFinite() || !mesh_.position[at(i)].allFinite());
    });
    if (bad >= 0)
      return parts::Fault{global_node(bad), "non-finite position or acceleration at node " +
                                                std::to_string(global_node(bad))};
    const Index bad_e = first_index(mesh_.element_count(), [&](Index e) {
      return !ghost_element(e) && !mesh_.stress[at(e)].allFinite();
    });
    if (bad_e >= 0) return parts::Fault{global_element(bad_e), "non-finite stress"};
    return std::nullopt;
  }();
  return comm_ ? parts::first_fault(*comm_, mine) : mine;
}

template <int D>
void FemPart<D>::advance(Real /*t_s*/, Real dt_s) {
  const Real half = Real(0.5) * dt_s;
  parallel::for_each(mesh_.node_count(), [&](Index i) {
    const std::size_t u = at(i);
    Vec<D>& v = mesh_.velocity[u];
    const Vec<D> a = total_acceleration(u);
    v += half * a;
    impose_velocity(u);
    if (!walls_.empty())
      work_external_[u] += hold_off_walls(walls_, mesh_.position[u], v, mesh_.mass[u], dt_s, a);
    mesh_.position[u] += dt_s * v;
  });
  if (comm_) refresh_ghosts();
  dt_pending_ = dt_s;
  stale_ = true;
  contact_pending_ = true;
  next_contact_.started();
}

template <int D>
void FemPart<D>::finish_step(Real dt_s) {
  const Real half = Real(0.5) * dt_s;
  parallel::for_each(mesh_.node_count(), [&](Index i) {
    const std::size_t u = at(i);
    mesh_.velocity[u] += half * total_acceleration(u);
    impose_velocity(u);
  });
  // Multi-rate: the next step may start with other contact forces than this one ended with.
  next_contact_.finished([&](const auto& f, const auto&) { contact_force_ = f; });
  if (comm_) rebalance();
}

template <int D>
void FemPart<D>::add_contact_forces(const std::vector<Vec<D>>& force,
                                    const std::vector<AxialVec<D>>& /*torque*/) {
  const Index nn = mesh_.node_count();
  if (static_cast<Index>(force.size()) != nn)
    throw std::logic_error("fem: contact forces for another node count");
  if (contact_pending_ && dt_pending_ > 0) {
    // Work of the contact forces over the step just taken (trapezoidal, v = v^{n+1/2}); on
    // imposed components the support takes the force, and does the opposite work.
    const Real half_dt = Real(0.5) * dt_pending_;
    parallel::for_each(nn, [&](Index i) {
      const std::size_t u = at(i);
      const Vec<D> mean = contact_force_[u] + force[u];
      work_contact_[u] += half_dt * mesh_.velocity[u].dot(mean);
      for (int k = 0; k < D; ++k)
        if (constrained_[u] & (1u << k))
          work_external_[u] -= half_dt * mesh_.velocity[u][k] * mean[k];
    });
  }
  contact_pending_ = false;
  contact_force_ = force;
}

template <int D>
parts::Energies FemPart<D>::energies() const {
  // Each sum over this rank's own entities and every rank's, by the reproducible sum (the
  // same bits for any rank and thread count). An eroded element's energies went to the eroded
  // account with it.
  auto live = [&](const std::vector<Real>& of_element) {
    return element_total([&](Index e) { return mesh_.eroded[at(e)] ? 0 : of_element[at(e)]; });
  };
  parts::Energies en;
  en.kinetic_j = node_total(
      [&](Index i) { return Real(0.5) * mesh_.mass[at(i)] * mesh_.velocity[at(i)].squaredNorm(); });
  en.internal_j = live(mesh_.internal_energy_j);
  en.hourglass_j = live(mesh_.hourglass_energy_j);
  en.external_work_j = node_total([&](Index i) { return work_external_[at(i)]; });
  en.damping_j = node_total(
      [&](Index i) { return work_damping_[at(i)] + mesh_.mass_scaling_dissipated_j[at(i)]; });
  en.eroded_j = element_total([&](Index e) {
                  return element_accounted_[at(e)]
                             ? mesh_.internal_energy_j[at(e)] + mesh_.hourglass_energy_j[at(e)]
                             : 0;
                }) +
                node_total([&](Index i) { return eroded_kinetic_of_node_[at(i)]; });
  en.contact_j = -node_total([&](Index i) { return work_contact_[at(i)]; });
  return en;
}

template <int D>
parts::Geometry<D> FemPart<D>::geometry() const {
  parts::Geometry<D> g;
  g.points = &mesh_.position;
  constexpr int kNodes = kElementNodes<D>;
  const Index ne = mesh_.element_count();
  g.connectivity.reserve(at(ne * kNodes));
  g.offsets.reserve(at(ne));
  for (const auto& nodes : mesh_.elements) {
    for (Index n : nodes)
      g.connectivity.push_back(n);
    g.offsets.push_back(static_cast<std::int64_t>(g.connectivity.size()));
  }
  g.cell_types.assign(at(ne), D == 2 ? std::uint8_t{9} : std::uint8_t{12});  // QUAD, HEXAHEDRON
  return g;
}

template <int D>
std::vector<fields::FieldView> FemPart<D>::point_fields() const {
  const Index nn = mesh_.node_count();
  displacement_.resize(at(nn));
  reaction_.assign(at(nn), Vec<D>::Zero());
  for (Index i = 0; i < nn; ++i) {
    const std::size_t u = at(i);
    displacement_[u] = mesh_.position[u] - mesh_.reference_position[u];
    // The supports' force: what the imposed components took off the node's other forces.
    const Vec<D> applied =
        mesh_.mass[u] * gravity_ + (load_force_.empty() ? Vec<D>::Zero().eval() : load_force_[u]);
    for (int k = 0; k < D; ++k)
      if ((constrained_[u] & (1u << k)) && mesh_.mass[u] > 0)
        reaction_[u][k] = external_force_[u][k] - applied[k];
  }
  return {vector_view(kVelocityInfo, mesh_.velocity),
          vector_view(kDisplacementInfo, displacement_),
          scalar_view(kNodeMassInfo, mesh_.mass),
          vector_view(kInternalForceInfo, mesh_.internal_force),
          vector_view(kReactionForceInfo, reaction_),
          vector_view(kContactForceInfo, contact_force_)};
}

template <int D>
std::vector<fields::FieldView> FemPart<D>::cell_fields() const {
  const Index ne = mesh_.element_count();
  von_mises_.resize(at(ne));
  pressure_.resize(at(ne));
  eroded_flag_.resize(at(ne));
  density_.resize(at(ne));
  for (Index e = 0; e < ne; ++e) {
    const materials::Mat3& s = mesh_.stress[at(e)];
    const Real p = -s.trace() / 3;
    const materials::Mat3 dev = s + p * materials::Mat3::Identity();
    von_mises_[at(e)] = std::sqrt(Real(1.5) * dev.cwiseProduct(dev).sum());
    pressure_[at(e)] = p;
    eroded_flag_[at(e)] = mesh_.eroded[at(e)];
    density_[at(e)] = material_.density_kg_m3 * mesh_.reference_volume[at(e)] /
                      std::max(mesh_.volume[at(e)], std::numeric_limits<Real>::min());
  }
  std::vector<fields::FieldView> out = {
      scalar_view(kVonMisesInfo, von_mises_),
      scalar_view(kPressureInfo, pressure_),
      scalar_view(kPlasticStrainInfo, mesh_.plastic_strain),
      scalar_view(kDensityInfo, density_),
  };
  if (material_.damage || is_hjc()) out.push_back(scalar_view(kDamageInfo, mesh_.damage));
  if (is_hjc())
    out.push_back(scalar_view(kPlasticVolumetricStrainInfo, mesh_.plastic_volumetric_strain));
  out.push_back(fields::FieldView{&kErodedInfo, 1, true, nullptr, eroded_flag_.data(), ne});
  if (const auto* jc = std::get_if<materials::JohnsonCookParams>(&material_.strength);
      jc && jc->thermal_softening)
    out.push_back(scalar_view(kTemperatureInfo, mesh_.temperature_k));
  return out;
}

template <int D>
void FemPart<D>::save_state(parts::StateWriter& w) const {
  if (comm_) {
    save_gathered(w);
    return;
  }
  w.tag("fem");
  for_each_state_vector(*this, [&](const auto& v, MeshEntity, const char*) { w.vector(v); });
  archive_values(w, *this, last_, mass_scaled_first_);
}

template <int D>
void FemPart<D>::load_state(parts::StateReader& r) {
  r.tag("fem");
  const std::size_t nn = mesh_.position.size(), ne = mesh_.elements.size();
  for_each_state_vector(*this, [&](auto& v, MeshEntity entity, const char* what) {
    const std::size_t n = entity == MeshEntity::node ? nn : ne;
    r.vector(v);
    if (v.size() != n)
      r.fail(fmt::format("part '{}': {} has {} entries, the mesh {}", name_, what, v.size(), n));
  });
  last_ = ForceReport{};
  archive_values(r, *this, last_, mass_scaled_first_);
  if (std::find(mesh_.eroded.begin(), mesh_.eroded.end(), 1) != mesh_.eroded.end())
    rebuild_surface();
}

template <int D>
Index FemPart<D>::count() const {
  return element_count_of([&](Index e) { return mesh_.eroded[at(e)] == 0; });
}

template <int D>
std::vector<parts::Diagnostic> FemPart<D>::diagnostics() const {
  Real max_plastic = 0;
  for (Index e = 0; e < mesh_.element_count(); ++e)
    if (!ghost_element(e)) max_plastic = std::max(max_plastic, mesh_.plastic_strain[at(e)]);
  std::vector<parts::Diagnostic> d = {
      {"elements", static_cast<Real>(comm_ ? whole_elements_ : mesh_.element_count())},
      {"nodes", static_cast<Real>(comm_ ? whole_nodes_ : mesh_.node_count())},
      {"eroded_elements",
       static_cast<Real>(element_count_of([&](Index e) { return mesh_.eroded[at(e)] != 0; }))},
      {"eroded_mass_kg", node_total([&](Index i) { return eroded_mass_of_node_[at(i)]; })},
      {"initial_mass_kg", initial_mass_},
      {"max_plastic_strain", comm_ ? comm_->max(max_plastic) : max_plastic}};
  if (material_.mass_scaling_min_step_s > 0) {
    const Real added = element_total([&](Index e) { return mesh_.added_mass_kg[at(e)]; });
    d.push_back({"mass_scaling_min_step_s", material_.mass_scaling_min_step_s});
    d.push_back({"added_mass_kg", added});
    d.push_back({"added_mass_fraction", added / initial_mass_});
    d.push_back({"mass_scaled_elements", static_cast<Real>(element_count_of([&](Index e) {
                   return mesh_.added_mass_kg[at(e)] > 0;
                 }))});
    d.push_back({"mass_scaling_dissipated_j",
                 node_total([&](Index i) { return mesh_.mass_scaling_dissipated_j[at(i)]; })});
  }
  return d;
}

/// The faces of live elements that no other live element shares, oriented outward, with
/// the LS-DYNA segment stiffness K A^2 / V of their element, taken in the reference
/// geometry: a face exposed by erosion on a crushed or stretched element would otherwise
/// carry a spring many times stiffer (K A^2 / V grows as the element flattens) and cut the
/// step for the rest of the run.
template <int D>
void FemPart<D>::rebuild_surface() {
  const SurfaceFaces<D> sf = surface_faces(mesh_, face_index_);
  surface_faces_ = sf.nodes;
  surface_element_ = sf.element;
  surface_stiffness_ = face_stiffness(sf, mesh_);
  ++surface_revision_;
}

template <int D>
std::vector<Real> FemPart<D>::face_stiffness(const SurfaceFaces<D>& sf,
                                             const ExplicitMesh<D>& mesh) const {
  const Real bulk = materials::bulk_modulus(materials::elastic_of(material_.strength));
  std::vector<Real> k(sf.nodes.size());
  for (std::size_t f = 0; f < k.size(); ++f)
    k[f] = bulk * sf.reference_area[f] * sf.reference_area[f] /
           mesh.reference_volume[at(sf.element[f])];
  return k;
}

/// Moves the mass, kinetic, internal and hourglass energy of the elements that failed in the
/// last force evaluation to the eroded account, in element order (deterministic); the faces
/// they uncover join the contact surface.
template <int D>
void FemPart<D>::account_erosion() {
  constexpr int kNodes = kElementNodes<D>;
  for (Index e = 0; e < mesh_.element_count(); ++e) {
    const std::size_t ue = at(e);
    if (!mesh_.eroded[ue] || element_accounted_[ue]) continue;
    element_accounted_[ue] = 1;
    const Real share =
        (material_.density_kg_m3 * mesh_.reference_volume[ue] + mesh_.added_mass_kg[ue]) / kNodes;
    for (Index n : mesh_.elements[ue]) {
      const std::size_t un = at(n);
      const Real removed = --live_elements_of_node_[un] == 0 ? mesh_.mass[un] : share;
      eroded_mass_of_node_[un] += removed;
      eroded_kinetic_of_node_[un] += Real(0.5) * removed * mesh_.velocity[un].squaredNorm();
      mesh_.mass[un] -= removed;
      if (live_elements_of_node_[un] == 0) {
        mesh_.mass[un] = 0;
        mesh_.velocity[un].setZero();
        mesh_.internal_force[un].setZero();
      }
    }
  }
  rebuild_surface();
}

/// The surface faces of a pressure load: those of the live mesh (outward numbering, as the
/// contact surface) with every node on the chosen face of the bounding box (or in the mesh
/// group) and the centre in the load's box (along the other axes).
template <int D>
void FemPart<D>::add_pressure_load(const MeshSource<D>& source, const LoadSettings& l) {
  const NodeSet<D> set = l.group.empty() ? face_node_set(mesh_, l.face) : source.group(l.group);
  std::vector<std::uint8_t> on_face(at(mesh_.node_count()), 0);
  for (Index n : set.nodes)
    on_face[at(n)] = 1;
  const int normal = static_cast<int>(l.face) / 2;
  const SurfaceFaces<D> sf = surface_faces(mesh_);
  PressureLoad load;
  load.time_s = l.time_s;
  load.pressure_pa = l.pressure_pa;
  for (std::size_t f = 0; f < sf.nodes.size(); ++f) {
    Vec<D> centre = Vec<D>::Zero();
    bool all = true;
    for (Index n : sf.nodes[f]) {
      all = all && on_face[at(n)];
      centre += mesh_.reference_position[at(n)] / Real(parts::kFaceNodes<D>);
    }
    if (!all) continue;
    if (l.region) {
      bool inside = true;
      for (int k = 0; k < D; ++k)
        if (k != normal &&
            (centre[k] < l.region->min_m[at(k)] || centre[k] > l.region->max_m[at(k)]))
          inside = false;
      if (!inside) continue;
    }
    load.faces.push_back(sf.nodes[f]);
    load.element.push_back(sf.element[f]);
  }
  if (load.faces.empty())
    throw std::runtime_error(fmt::format(
        "{}: line {}: part '{}': the pressure load selects no boundary face (none of the "
        "part's faces in its group, or on its bounding box's side with its centre in the "
        "load's box)",
        l.where.file, l.where.line, name_));
  loads_.push_back(std::move(load));
}

/// Nodal forces of the pressure loads at time t on the current geometry: per face
/// f = -p a, a the outward area vector ((t_y, -t_x) x 1 m in 2D, (x_2 - x_0) x (x_3 - x_1) / 2
/// in 3D), shared equally by its nodes (exact for straight segments and parallelograms).
/// Faces are visited in order, one thread: the sums are the same for any thread count.
template <int D>
void FemPart<D>::pressure_forces(Real t_s) {
  for (auto& f : load_force_)
    f.setZero();
  constexpr int kF = parts::kFaceNodes<D>;
  for (const PressureLoad& load : loads_) {
    const Real p = tabulated(load.time_s, load.pressure_pa, t_s);
    if (p == 0) continue;
    for (std::size_t f = 0; f < load.faces.size(); ++f) {
      if (mesh_.eroded[at(load.element[f])]) continue;
      const auto& nodes = load.faces[f];
      const Vec<D> share = (-p / Real(kF)) * numbered_face_area<D>(mesh_.position, nodes);
      for (Index n : nodes)
        load_force_[at(n)] += share;
    }
  }
}

/// Nodes of a boundary condition and, for dashpots, their boundary faces.
template <int D>
void FemPart<D>::apply_boundary_config(const MeshSource<D>& source, const BoundarySettings& b) {
  const NodeSet<D> set = b.face ? face_node_set(mesh_, *b.face) : source.group(b.group);
  switch (b.type) {
    case BoundaryType::Fixed:
      for (Index n : set.nodes) {
        constrained_[at(n)] = (1u << D) - 1;
        imposed_velocity_[at(n)].setZero();
      }
      break;
    case BoundaryType::Symmetry: {
      const int axis = set.normal_axis;
      if (axis < 0)
        throw std::runtime_error(
            fmt::format("part '{}': a symmetry boundary needs a plane normal to an axis", name_));
      for (Index n : set.nodes) {
        constrained_[at(n)] |= 1u << axis;
        imposed_velocity_[at(n)][axis] = 0;
      }
      break;
    }
    case BoundaryType::Velocity:
      for (Index n : set.nodes)
        for (int k = 0; k < D; ++k)
          if (b.components[at(k)]) {
            constrained_[at(n)] |= 1u << k;
            imposed_velocity_[at(n)][k] = b.velocity_m_s[at(k)];
          }
      break;
    case BoundaryType::NonReflecting:
      add_dashpots<D>(set.faces, materials::at_rest_elastic_of(material_.strength),
                      material_.density_kg_m3, dashpot_of_node_, dashpot_matrix_);
      break;
  }
}

/// The domain's planes of symmetry: the nodes on one (within 1e-9 of the domain's extent)
/// keep zero velocity normal to it, whatever else holds them. (A part cannot reach across
/// one: the reader holds its region or mesh inside the domain.)
template <int D>
void FemPart<D>::apply_symmetry_planes(const parts::PartSetup& pc) {
  for (const parts::Face face : pc.domain.symmetry_planes) {
    const int axis = static_cast<int>(face) / 2;
    if (axis >= D) continue;
    const Real plane = parts::face_coordinate(pc.domain, face);
    const Real tol = 1e-9 * (pc.domain.max_m[axis] - pc.domain.min_m[axis]);
    for (Index n = 0; n < mesh_.node_count(); ++n)
      if (std::abs(mesh_.reference_position[at(n)][axis] - plane) <= tol) {
        constrained_[at(n)] |= 1u << axis;
        imposed_velocity_[at(n)][axis] = 0;
      }
  }
}

template class FemPart<2>;
template class FemPart<3>;

}  // namespace detail

template <int D>
std::unique_ptr<parts::Part<D>> make_fem_part(const PartSettings& settings) {
  return std::make_unique<detail::FemPart<D>>(settings);
}

template std::unique_ptr<parts::Part<2>> make_fem_part<2>(const PartSettings&);
template std::unique_ptr<parts::Part<3>> make_fem_part<3>(const PartSettings&);

}  // namespace crater::fem
