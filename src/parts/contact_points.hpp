// What a particle part keeps for the contacts with other parts (src/contact/), besides the
// ContactPoints view of its fields (part.hpp): the work those forces do on it.
#pragma once

#include "core/types.hpp"
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
  /// rotating particles), once per advance: dt/2 times the deterministic sum over [0, n).
  template <class Power>
  void settle(Index n, Power&& power) {
    if (pending && last_dt_s > 0) {
      const Real half_dt = Real(0.5) * last_dt_s;
      work_j += parallel::deterministic_sum<Real>(n, [&](Index i) { return half_dt * power(i); });
    }
    pending = false;
  }
};

}  // namespace crater::parts
