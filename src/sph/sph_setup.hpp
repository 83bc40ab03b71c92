// How an SPH part's particles are laid and start (sph_part.cpp's constructor): the lattice of
// the part and of zones with their own spacing, the initial state of each particle, and its
// lighting time for a programmed burn.
#pragma once

#include <optional>
#include <vector>

#include "core/types.hpp"
#include "parts/setup.hpp"

namespace crater::sph {

/// The particles' positions, in the order they are numbered, and each one's lattice pitch.
template <int D>
struct ParticleLattice {
  std::vector<Vec<D>> x;
  std::vector<Real> pitch;
};

/// The part's lattice at `spacing` over its region (less carved regions), except where a zone
/// with its own spacing lays its own (equal-mass particles across a density jump, as a shock
/// tube wants): the part's points first, then each such zone's in zone order.
template <int D>
ParticleLattice<D> particle_lattice(const parts::PartSetup& setup, Real spacing);

/// A particle's initial state: the part's, then that of the last zone containing it.
template <int D>
struct StartState {
  Real rho = 0;
  std::optional<Real> pressure;  // unset: from the EOS's default (see SphPart)
  Vec<D> v;
};

template <int D>
StartState<D> start_state(const parts::PartSetup& setup, Real rho0, const Vec<D>& x);

/// Programmed burn: a particle lights when the detonation front, running at d_cj from the
/// nearest detonation point, reaches it; without detonation points (or for a material that
/// does not burn) it is lit at t = 0.
template <int D>
Real lighting_time(const parts::PartSetup& setup, bool explosive, Real d_cj, const Vec<D>& x);

}  // namespace crater::sph
