// A minimal explicit central-difference loop over the FEM kernels, for verification tests
// only (the solver's own loop will live in src/solver/). Prescribed velocity components are
// constant in time (fixed supports, symmetry planes, an imposed end velocity).
//
//   v^{n+1/2} = v^{n-1/2} + \Delta t f_int^n / m;  prescribed components overwritten;
//   x^{n+1} = x^n + \Delta t v^{n+1/2};  f_int^{n+1} = compute_internal_forces(...)
#pragma once

#include <vector>

#include "fem/explicit_solid.hpp"

namespace crater::fem::testing {

struct PrescribedVelocity {
  Index node = 0;
  int axis = 0;
  Real value = 0;  // [m/s]
};

template <int D>
class CentralDifference {
 public:
  CentralDifference(ExplicitMesh<D>& mesh, const SolidMaterial& material,
                    std::vector<PrescribedVelocity> prescribed)
      : mesh_(mesh), material_(material), prescribed_(std::move(prescribed)) {
    apply_prescribed();
    compute_internal_forces<D>(mesh_, material_, 0);
  }

  ForceReport step(Real dt) {
    for (std::size_t i = 0; i < mesh_.velocity.size(); ++i)
      mesh_.velocity[i] += dt / mesh_.mass[i] * mesh_.internal_force[i];
    apply_prescribed();
    for (std::size_t i = 0; i < mesh_.position.size(); ++i)
      mesh_.position[i] += dt * mesh_.velocity[i];
    const ForceReport report = compute_internal_forces<D>(mesh_, material_, dt);
    internal_energy_j_ += report.internal_energy_increment_j;
    hourglass_energy_j_ += report.hourglass_energy_increment_j;
    time_s_ += dt;
    return report;
  }

  Real time_s() const { return time_s_; }
  Real internal_energy_j() const { return internal_energy_j_; }
  Real hourglass_energy_j() const { return hourglass_energy_j_; }

 private:
  void apply_prescribed() {
    for (const PrescribedVelocity& p : prescribed_)
      mesh_.velocity[static_cast<std::size_t>(p.node)][p.axis] = p.value;
  }

  ExplicitMesh<D>& mesh_;
  const SolidMaterial& material_;
  std::vector<PrescribedVelocity> prescribed_;
  Real time_s_ = 0;
  Real internal_energy_j_ = 0;
  Real hourglass_energy_j_ = 0;
};

}  // namespace crater::fem::testing
