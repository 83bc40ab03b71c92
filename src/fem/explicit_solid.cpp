// Element loop of the explicit solid; see explicit_solid.hpp.
#include "fem/explicit_solid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/index.hpp"
#include "fem/element_geometry.hpp"
#include "fem/kinematics.hpp"
#include "parallel/parallel.hpp"

namespace crater::fem {
namespace {

using materials::Mat3;

/// Per-element results of one force evaluation, reduced afterwards in a fixed order.
struct ElementResults {
  std::vector<Real> internal_energy_j;
  std::vector<Real> hourglass_energy_j;
  std::vector<Real> stable_dt_s;
  std::vector<Real> added_mass_kg;  // mass scaling in this evaluation
  std::vector<std::uint8_t> eroded_now;
  std::vector<std::uint8_t> inverted;
  explicit ElementResults(Index n)
      : internal_energy_j(at(n), 0),
        hourglass_energy_j(at(n), 0),
        stable_dt_s(at(n), std::numeric_limits<Real>::infinity()),
        added_mass_kg(at(n), 0),
        eroded_now(at(n), 0),
        inverted(at(n), 0) {}
};

/// The factor mass scaling has stretched element ue's step by so far: sqrt(m_e' / m_e).
template <int D>
Real scaled_step_factor(const ExplicitMesh<D>& mesh, const SolidMaterial& material,
                        std::size_t ue) {
  const Real added = mesh.added_mass_kg[ue];
  if (added == 0) return 1;
  return std::sqrt(1 + added / (material.density_kg_m3 * mesh.reference_volume[ue]));
}

template <class Law>
constexpr bool kIsHjc = std::is_same_v<Law, materials::HolmquistJohnsonCookLaw>;

/// Dilatational wave speed of an element at density rho [m/s]: \sqrt{M/\rho} with the law's
/// constant P-wave modulus M, or for HJC with the bound at the element's compression
/// (materials::hjc_wave_bulk_modulus).
template <class Law>
Real element_wave_speed(const Law& law, Real modulus, Real rho, Real rho0) {
  if constexpr (kIsHjc<Law>) {
    const Real bulk = materials::hjc_wave_bulk_modulus(law, rho / rho0 - Real(1));
    return std::sqrt((bulk + Real(4) / Real(3) * law.params.shear_modulus_pa) / rho);
  } else {
    return std::sqrt(modulus / rho);
  }
}

/// The stress update of element ue through its law, with its state (plastic strain, temperature,
/// damage; HJC: also \mu_{max}, \mu_p) carried forward. Returns the new stress and whether the
/// element's damage has failed it: Johnson-Cook damage ([materials.damage]) at D >= 1, HJC
/// damage at D >= 1 when the material's erode_at_full_damage is set.
struct PointUpdate {
  Mat3 stress;
  bool failed = false;
};
template <int D, class Law>
PointUpdate update_point(ExplicitMesh<D>& mesh, const SolidMaterial& material, const Law& law,
                         std::size_t ue, const Mat3& rotated, const Mat3& strain_increment, Real dt,
                         Real rho) {
  if constexpr (kIsHjc<Law>) {
    const materials::HjcStressUpdate up = materials::update_stress_of(
        law.params, law.eos, rotated, strain_increment,
        materials::HjcState{.damage = mesh.damage[ue],
                            .mu_max = mesh.mu_max[ue],
                            .plastic_volumetric_strain = mesh.plastic_volumetric_strain[ue],
                            .plastic_strain = mesh.plastic_strain[ue]},
        dt, rho);
    mesh.damage[ue] = up.state.damage;
    mesh.mu_max[ue] = up.state.mu_max;
    mesh.plastic_volumetric_strain[ue] = up.state.plastic_volumetric_strain;
    mesh.plastic_strain[ue] = up.state.plastic_strain;
    return {up.stress, material.erode_at_full_damage && up.state.damage >= Real(1)};
  } else {
    const materials::StressUpdate up = materials::update_stress_of(
        law, rotated, strain_increment,
        materials::MaterialPointState{.plastic_strain = mesh.plastic_strain[ue],
                                      .temperature_k = mesh.temperature_k[ue]},
        dt, rho);
    const Real d_eps = up.plastic_strain_increment;
    if (material.damage && d_eps > 0) {
      mesh.damage[ue] += materials::johnson_cook_damage_increment(
          *material.damage, d_eps, materials::stress_triaxiality(up.stress), d_eps / dt,
          mesh.temperature_k[ue]);
    }
    mesh.plastic_strain[ue] += d_eps;
    mesh.temperature_k[ue] += up.temperature_increment_k;
    return {up.stress, material.damage && materials::johnson_cook_failed(mesh.damage[ue])};
  }
}

/// The element loop for one strength law (resolved at compile time: no dispatch per element).
template <int D, class Law>
void update_elements(ExplicitMesh<D>& mesh, const SolidMaterial& material, const Law& law, Real dt,
                     ElementResults& out) {
  constexpr int kNodes = kElementNodes<D>;
  const Real rho0 = material.density_kg_m3;
  const Real modulus = materials::p_wave_modulus(materials::elastic_of(law));
  auto update = [&](Index e) {
    const std::size_t ue = at(e);
    NodeArray<D>& force = mesh.element_force[ue];
    const NodeArray<D> last_force = force;
    for (Vec<D>& f : force)
      f.setZero();
    if (mesh.eroded[ue]) return;
    const NodeArray<D> x = mesh.element_positions(e);
    const NodeArray<D> v = mesh.element_velocities(e);
    // An element that fails now: its forces of the last evaluation worked on its nodes over the
    // step just taken (half of the trapezoid, as the half kicks have it; the other half, with
    // its forces now zero, is nothing). That work is booked before the element's energy leaves
    // the part, or the nodes keep energy the element never gave up.
    auto erode = [&] {
      Real work = 0;
      for (int node = 0; node < kNodes; ++node) {
        work -= last_force[node].dot(v[node]);
      }
      work *= Real(0.5) * dt;
      out.internal_energy_j[ue] = work;
      mesh.internal_energy_j[ue] += work;
      mesh.eroded[ue] = 1;
      out.eroded_now[ue] = 1;
      mesh.stress[ue].setZero();
    };
    const UniformStrainGradients<D> g = uniform_strain_gradients<D>(x);
    if (!(g.volume > 0)) {
      if (material.erode_inverted) {
        erode();
      } else {
        out.inverted[ue] = 1;
      }
      return;
    }
    const Real rho = rho0 * mesh.reference_volume[ue] / g.volume;
    const Real c = element_wave_speed(law, modulus, rho, rho0);
    const Mat3 l = velocity_gradient<D>(v, g);
    const Mat3 d = rate_of_deformation(l);
    const Mat3 old_stress = mesh.stress[ue];
    Mat3 sigma = old_stress;
    if (dt > 0) {
      const Mat3 rotated = D == 2 ? jaumann_rotate_plane(old_stress, spin(l)(0, 1), dt)
                                  : jaumann_rotate(old_stress, spin(l), dt);
      const PointUpdate up = update_point<D>(mesh, material, law, ue, rotated, d * dt, dt, rho);
      sigma = up.stress;
      // A crushed element's step shrinks with its thickness; below the floor it erodes
      // rather than hold the whole model's step down (bulk viscosity of this step included).
      const bool too_small_a_step =
          material.erosion_min_step_s > 0 &&
          stable_element_step(material.bulk_viscosity, characteristic_length<D>(g), c, d.trace()) *
                  scaled_step_factor(mesh, material, ue) <
              material.erosion_min_step_s;
      if (up.failed || mesh.plastic_strain[ue] >= material.erosion_plastic_strain ||
          too_small_a_step) {
        erode();
        mesh.volume[ue] = g.volume;
        return;
      }
    }
    mesh.stress[ue] = sigma;
    mesh.volume[ue] = g.volume;

    const Real size = dth_root<D>(g.volume);
    const Real q = bulk_viscosity_pressure(material.bulk_viscosity, rho, c, size, d.trace());
    const Eigen::Matrix<Real, D, D> sigma_eff =
        sigma.template topLeftCorner<D, D>() - q * Eigen::Matrix<Real, D, D>::Identity();
    for (int node = 0; node < kNodes; ++node) {
      force[node] = -g.volume * (sigma_eff * g.b[node]);
    }

    const HourglassVectors<D> gamma = hourglass_shape_vectors<D>(x, g);
    const HourglassForces<D> hg =
        hourglass_forces<D>(material.hourglass, gamma, v, g.volume, rho, c, dt, mesh.hourglass[ue]);
    for (int node = 0; node < kNodes; ++node) {
      force[node] += hg.force[node];
    }

    const Real work =
        dt * g.volume * (Real(0.5) * (old_stress + sigma).cwiseProduct(d).sum() - q * d.trace());
    out.internal_energy_j[ue] = work;
    out.hourglass_energy_j[ue] = dt * hg.power_w;
    mesh.internal_energy_j[ue] += work;
    mesh.hourglass_energy_j[ue] += dt * hg.power_w;
    const Real own_step =
        stable_element_step(material.bulk_viscosity, characteristic_length<D>(g), c, d.trace());
    Real step = own_step * scaled_step_factor(mesh, material, ue);
    const Real floor = material.mass_scaling_min_step_s;
    if (floor > 0 && step < floor) {
      // The step grows as the square root of the element's mass: the mass that holds it at the
      // floor is m_e (floor / step_e)^2 (bulk viscosity taken at this evaluation's rate).
      const Real ratio = floor / own_step;
      const Real needed = rho0 * mesh.reference_volume[ue] * (ratio * ratio - 1);
      out.added_mass_kg[ue] = needed - mesh.added_mass_kg[ue];
      mesh.added_mass_kg[ue] = needed;
      step = floor;
    }
    out.stable_dt_s[ue] = step;
  };
  // Elements differ in cost (a yielding one iterates the rate law, an eroded one is skipped, and
  // both gather where the load is), so blocks of them are dealt out as threads come free.
  parallel::for_each_block(
      mesh.element_count(), 16,
      [&](Index first, Index last) {
        for (Index e = first; e < last; ++e)
          update(e);
      },
      parallel::Cost::heavy);  // an element's kinematics, stress update and hourglass forces
}

}  // namespace

template <int D>
void initialise(ExplicitMesh<D>& mesh, const SolidMaterial& material) {
  constexpr int kNodes = kElementNodes<D>;
  const Index ne = mesh.element_count();
  const Index nn = mesh.node_count();
  if (mesh.reference_position.size() != mesh.position.size()) {
    mesh.reference_position = mesh.position;
  }
  mesh.velocity.resize(at(nn), Vec<D>::Zero());
  mesh.internal_force.assign(at(nn), Vec<D>::Zero());
  mesh.mass.assign(at(nn), 0);
  mesh.stress.assign(at(ne), Mat3::Zero());
  mesh.plastic_strain.assign(at(ne), 0);
  mesh.temperature_k.assign(at(ne), material.initial_temperature_k);
  mesh.damage.assign(at(ne), 0);
  mesh.mu_max.assign(at(ne), 0);
  mesh.plastic_volumetric_strain.assign(at(ne), 0);
  mesh.reference_volume.assign(at(ne), 0);
  mesh.volume.assign(at(ne), 0);
  mesh.internal_energy_j.assign(at(ne), 0);
  mesh.hourglass_energy_j.assign(at(ne), 0);
  mesh.hourglass.assign(at(ne), HourglassState<D>::Zero());
  mesh.eroded.assign(at(ne), 0);
  mesh.added_mass_kg.assign(at(ne), 0);
  mesh.element_force.assign(at(ne), NodeArray<D>{});

  mesh.mass_scaling_dissipated_j.assign(at(nn), 0);
  for (Index e = 0; e < ne; ++e) {
    const UniformStrainGradients<D> g = uniform_strain_gradients<D>(mesh.element_positions(e));
    if (!(g.volume > 0)) {
      throw std::invalid_argument("fem::initialise: element " + std::to_string(e) +
                                  " has a non-positive volume (inverted or wrongly numbered)");
    }
    mesh.reference_volume[at(e)] = g.volume;
    mesh.volume[at(e)] = g.volume;
    for (Index node : mesh.elements[at(e)])
      mesh.mass[at(node)] += material.density_kg_m3 * g.volume / Real(kNodes);
  }
  build_node_adjacency(mesh);
}

template <int D>
void build_node_adjacency(ExplicitMesh<D>& mesh) {
  constexpr int kNodes = kElementNodes<D>;
  const Index ne = mesh.element_count();
  const Index nn = mesh.node_count();
  std::vector<Index> count(at(nn) + 1, 0);
  for (Index e = 0; e < ne; ++e)
    for (Index node : mesh.elements[at(e)])
      ++count[at(node) + 1];
  for (Index i = 0; i < nn; ++i) {
    count[at(i) + 1] += count[at(i)];
  }
  mesh.node_entry_offsets = count;
  mesh.node_entries.assign(at(count[at(nn)]), 0);
  std::vector<Index> fill(count.begin(), count.end() - 1);
  for (Index e = 0; e < ne; ++e) {
    for (int local = 0; local < kNodes; ++local) {
      const Index node = mesh.elements[at(e)][at(local)];
      mesh.node_entries[at(fill[at(node)]++)] = e * kNodes + local;
    }
  }
}

template <int D>
ForceReport compute_internal_forces(ExplicitMesh<D>& mesh, const SolidMaterial& material, Real dt) {
  constexpr int kNodes = kElementNodes<D>;
  const Index ne = mesh.element_count();
  ElementResults results(ne);
  std::visit([&](const auto& law) { update_elements<D>(mesh, material, law, dt, results); },
             material.strength);

  parallel::for_each(mesh.node_count(), [&](Index node) {
    Vec<D> f = Vec<D>::Zero();
    for (Index k = mesh.node_entry_offsets[at(node)]; k < mesh.node_entry_offsets[at(node) + 1];
         ++k) {
      const Index entry = mesh.node_entries[at(k)];
      f += mesh.element_force[at(entry / kNodes)][at(entry % kNodes)];
    }
    mesh.internal_force[at(node)] = f;
  });

  // One pass for the sums (each summed in the same fixed order as alone: the same bits) and
  // the first element of smallest step, the first inverted and the first mass-scaled (the sums
  // join the lower elements' on the left, so the first of a tie stays).
  struct Sums {
    Real internal = 0, hourglass = 0, added = 0;
    Index eroded = 0;
    Real dt = std::numeric_limits<Real>::infinity();
    Index dt_at = -1, inverted_at = -1, scaled_at = -1;
    Sums& operator+=(const Sums& o) {
      internal += o.internal;
      hourglass += o.hourglass;
      added += o.added;
      eroded += o.eroded;
      if (o.dt < dt) {
        dt = o.dt;
        dt_at = o.dt_at;
      }
      if (inverted_at < 0) inverted_at = o.inverted_at;
      if (scaled_at < 0) scaled_at = o.scaled_at;
      return *this;
    }
  };
  const Sums sums = parallel::deterministic_sum<Sums>(ne, [&](Index e) {
    return Sums{results.internal_energy_j[at(e)], results.hourglass_energy_j[at(e)],
                results.added_mass_kg[at(e)],     static_cast<Index>(results.eroded_now[at(e)]),
                results.stable_dt_s[at(e)],       e,
                results.inverted[at(e)] ? e : -1, results.added_mass_kg[at(e)] > 0 ? e : -1};
  });
  ForceReport report;
  report.internal_energy_increment_j = sums.internal;
  report.hourglass_energy_increment_j = sums.hourglass;
  report.newly_eroded = sums.eroded;
  if (sums.added > 0) {
    // The nodes take the added mass (a share per element node) and keep their momentum.
    report.mass_added_kg = sums.added;
    report.mass_scaling_dissipated_j =
        parallel::deterministic_sum<Real>(mesh.node_count(), [&](Index node) {
          Real added = 0;
          for (Index k = mesh.node_entry_offsets[at(node)];
               k < mesh.node_entry_offsets[at(node) + 1]; ++k)
            added += results.added_mass_kg[at(mesh.node_entries[at(k)] / kNodes)];
          if (added == 0) return Real(0);
          added /= Real(kNodes);
          Real& m = mesh.mass[at(node)];
          Vec<D>& v = mesh.velocity[at(node)];
          const Real before = Real(0.5) * m * v.squaredNorm();
          v *= m / (m + added);
          m += added;
          const Real given_up = before - Real(0.5) * m * v.squaredNorm();
          mesh.mass_scaling_dissipated_j[at(node)] += given_up;
          return given_up;
        });
  }
  report.stable_dt_s = sums.dt;
  if (sums.dt_at >= 0) report.limiting_element = sums.dt_at;
  report.inverted_element = sums.inverted_at;
  report.first_mass_scaled_element = sums.scaled_at;
  return report;
}

template <int D>
Real stable_time_step(const ExplicitMesh<D>& mesh, const SolidMaterial& material) {
  return std::visit(
      [&](const auto& law) {
        const Real modulus = materials::p_wave_modulus(materials::elastic_of(law));
        const Real rho0 = material.density_kg_m3;
        return parallel::min_over(
            mesh.element_count(), std::numeric_limits<Real>::infinity(), [&](Index e) {
              if (mesh.eroded.size() == mesh.elements.size() && mesh.eroded[at(e)]) {
                return std::numeric_limits<Real>::infinity();
              }
              const UniformStrainGradients<D> g =
                  uniform_strain_gradients<D>(mesh.element_positions(e));
              const Real rho = mesh.reference_volume.empty()
                                   ? rho0
                                   : rho0 * mesh.reference_volume[at(e)] / g.volume;
              return characteristic_length<D>(g) / element_wave_speed(law, modulus, rho, rho0);
            });
      },
      material.strength);
}

template <int D>
Real kinetic_energy(const ExplicitMesh<D>& mesh) {
  return parallel::deterministic_sum<Real>(mesh.node_count(), [&](Index i) {
    return Real(0.5) * mesh.mass[at(i)] * mesh.velocity[at(i)].squaredNorm();
  });
}

template void initialise<2>(ExplicitMesh<2>&, const SolidMaterial&);
template void initialise<3>(ExplicitMesh<3>&, const SolidMaterial&);
template void build_node_adjacency<2>(ExplicitMesh<2>&);
template void build_node_adjacency<3>(ExplicitMesh<3>&);
template ForceReport compute_internal_forces<2>(ExplicitMesh<2>&, const SolidMaterial&, Real);
template ForceReport compute_internal_forces<3>(ExplicitMesh<3>&, const SolidMaterial&, Real);
template Real stable_time_step<2>(const ExplicitMesh<2>&, const SolidMaterial&);
template Real stable_time_step<3>(const ExplicitMesh<3>&, const SolidMaterial&);
template Real kinetic_energy<2>(const ExplicitMesh<2>&);
template Real kinetic_energy<3>(const ExplicitMesh<3>&);

}  // namespace crater::fem
