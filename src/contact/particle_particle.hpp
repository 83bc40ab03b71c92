// SPH particles against DEM grains: every overlapping pair, k = s_p E r_2 (3D) or s_p E (2D)
// with E the grains' Young's modulus; coupling.hpp's header comment has the equations.
#pragma once

#include <vector>

#include "contact/candidates.hpp"
#include "contact/pairing.hpp"

namespace crater::contact {

template <int D>
class ParticleParticle final : public Pairing<D> {
 public:
  /// `points` offers non-rotating particles (SPH), `other` the grains (DEM).
  ParticleParticle(const ContactSettings& settings, std::size_t points, std::size_t other,
                   const PartList<D>& parts)
      : Pairing<D>(settings, points, other, parts),
        grain_modulus_pa_(settings.grain_modulus_pa[other == settings.parts[0] ? 0 : 1]) {}

  void limit_step(const PartList<D>& parts, PairLimits& limits) const override;
  void apply(const PartList<D>& parts, Real dt_s, ContactForces<D>& out) override;

  /// A pair of overlapping particles, a of `points` and b of `other`.
  struct Pair {
    Index a = -1, b = -1;
    Real overlap = 0, dist = 0;
    Vec<D> d = Vec<D>::Zero();  // from b's centre to a's
  };
  /// The overlapping pairs, a ascending, then b ascending; with `kept`, the candidates come
  /// from the pairing's kept list (candidates.hpp) and the pairs are the same.
  static std::vector<Pair> pairs(const parts::ContactPoints<D>& a, const parts::ContactPoints<D>& b,
                                 CrossCandidates<D>* kept = nullptr);

 private:
  Real stiffness(const parts::ContactPoints<D>& grains, Index j) const;
  void add_load(const parts::ContactPoints<D>& grains, const Pair& pp) const;
  void measure_load(const PartList<D>& parts) const;

  Real grain_modulus_pa_;            // E of the grains [Pa]
  mutable CrossCandidates<D> kept_;  // the candidate pairs, kept between steps
};

}  // namespace crater::contact
