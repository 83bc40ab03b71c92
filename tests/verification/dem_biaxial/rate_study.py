"""Rate-dependent friction in the biaxial test (issue 24, paper section III-C): does a run show
the friction rise the law predicts? (docs/validation.md, "DEM: biaxial test".)

Law (src/dem/laws/rate_dependent_friction.hpp): per contact phi_dyn = phi_s (1 + beta
log10(rate / RATE0)), rate = |v_n| / (r1 + r2), phi_dyn >= phi_s.

Why not the paper's sand: with mu 0.84 the strength of a disk assembly has saturated in mu (the
first study, 2026-11-26: the law's share of the peak between 0.05 and 0.5 /s was -0.23 +- 0.88
deg, inside the scatter). Here the contacts are slippery, MU_S = 0.1 (phi_s 5.7 deg), where
the sample's friction angle follows mu (about 38 deg per unit of mu between 0.1 and 0.2, 27
between 0.2 and 0.3, measured on seed 1), and BETA = 1 (the paper: 0.05) so that a decade of
rate moves the contact angle by phi_s = 5.7 deg. Everything else is biaxial_case.scenario()
(the sand's stiffness, density, restitution, sigma_3 = 100 kPa, frictionless walls), except
that the dense bed is not settled under gravity (settle = false: every run of a seed starts
from the very same grains whatever its contact law; the consolidation loads them).

Method, per packing (seed), all runs to eps_1 = STRAIN at the two axial rates RATES (the top's
speed ramped over the first 0.25 % of strain at both), RATE0 a decade below the slower:
  law  : rate_dependent_friction on, mu = MU_S, at each rate;
  pred : the law off with the constant mu_dyn = tan(phi_dyn(rate)) of the nominal rate, at
         the same rate (the contacts' |v_n| / (r1 + r2) are taken to be the axial rate on
         average: in an affine compression at rate e, v_n / (r1 + r2) = e cos^2 theta);
  static: the law off at mu = MU_S, at each rate (the law's share, and the slope of the
         sample's angle in the contact angle for the effective contact rate below).
Measure: PHI_BAND, the mean of the mobilised friction angle over eps_1 = 0.25-1 % (from the
end of the ramp to past the peak, before the shear band: the most repeatable part of the curve).
Measured rise = law(fast) - law(slow); predicted rise = pred(fast) - pred(slow), paired on the
same packing, so that the packing's own strength cancels and the inertia of either rate (in
both) too. Effective contact rate: the contact angle phi_eff at which the law-on run would be
reproduced, interpolated linearly between static (phi_s) and pred (phi_dyn(nominal)), then
rate_eff = RATE0 10^((phi_eff / phi_s - 1) / BETA).

Inertial number I = rate d sqrt(rho / sigma_3) = 1.9e-4 and 1.9e-3 (d = 14 mm): quasi-static
at the slower rate, at the edge of it at the faster (both of a pair see the same rate).

    CRATER_BIN=build/release/bin/crater CRATER_TEST_TMP=/tmp/crater-rates \
        /usr/bin/python3 tests/verification/dem_biaxial/rate_study.py [seed ...]

Six runs per seed (three at each rate, about 30 s and 8 s on one core); writes
CRATER_TEST_TMP/biaxial_rate_friction/rates.json (per seed, and mean +- s.d. over the seeds).
Measured (2026-11-26, seeds 1-12): measured rise 2.87 +- 0.59 deg, predicted 3.11 +- 1.08 deg,
ratio of the means 0.922 (seeds 1-3: 2.87 / 3.04, 0.946); the law-off rise at mu 0.1 0.43 +-
0.20 deg; effective contact rate 0.45 (0.1 /s) and 0.36 (1 /s) of the nominal (geometric means).
"""
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from biaxial_case import SEEDS, T_CONS_S, reduce, scenario  # noqa: E402
from crater_test import crater, scratch  # noqa: E402
from scenario_blocks import SAND, material, write_scenario  # noqa: E402

MU_S = 0.1
BETA = 1.0
RATE0 = 0.01  # 1/s, friction_reference_strain_rate
RATES = (0.1, 1.0)  # 1/s
STRAIN = 0.015
RAMP_STRAIN = 0.0025
PHI_BAND = (0.0025, 0.01)  # of eps_1


def contact_angle(rate):
    """phi_dyn of the law at contact strain rate `rate` [deg]."""
    phi_s = math.degrees(math.atan(MU_S))
    return phi_s * (1 + BETA * math.log10(max(rate / RATE0, 1.0)))


def contact_mu(rate):
    return math.tan(math.radians(contact_angle(rate)))


def band_angle(history_csv):
    """Mean mobilised friction angle over PHI_BAND of eps_1 [deg]."""
    r = reduce(history_csv)
    if r["e1"].max() < PHI_BAND[1]:
        raise RuntimeError(f"{history_csv}: the run stopped at eps_1 = {r['e1'].max():.4f}, "
                           f"before the band's end {PHI_BAND[1]}")
    m = (r["e1"] >= PHI_BAND[0]) & (r["e1"] <= PHI_BAND[1])
    return float(r["phi"][m].mean())


def run(work, seed, rate, mu, law, strain=STRAIN):
    """One biaxial run to eps_1 = strain; returns its PHI_BAND angle [deg]. The frames stay
    where a run to STRAIN has them (a frame time ends a step), so that a shorter run that still
    passes PHI_BAND's end gives the same angle, bit for bit."""
    name = f"seed{seed}_{'law' if law else 'off'}_mu{mu:.4f}_rate{rate:g}"
    dem = {"rate_dependent_friction": True, "friction_rate_beta": BETA,
           "friction_reference_strain_rate": RATE0} if law else None
    write_scenario(work / f"{name}.toml",
                   scenario(seed, work / "cache", strain_rate=rate, axial_strain=strain, dem=dem,
                            ramp_s=RAMP_STRAIN / rate, material=material(SAND, friction=MU_S if
                                                                         law else mu),
                            settle=False, frame_s=(T_CONS_S + STRAIN / rate) / 2))
    crater("run", work / f"{name}.toml", "--out", work / name, "--force", "--quiet",
           timeout=1200)
    return band_angle(work / name / "history.csv")


def study_seed(work, seed, static=True, strain=STRAIN):
    """The runs of one packing (to eps_1 = strain); returns their angles, the rises and the
    effective rates."""
    lo, hi = RATES
    out = {"law": {}, "pred": {}, "static": {}}
    for rate in RATES:
        out["law"][rate] = run(work, seed, rate, MU_S, True, strain)
        out["pred"][rate] = run(work, seed, rate, contact_mu(rate), False, strain)
        if static:
            out["static"][rate] = run(work, seed, rate, MU_S, False, strain)
    res = {"seed": seed,
           "phi": {k: {f"{r:g}": v for r, v in d.items()} for k, d in out.items()},
           "rise_measured": out["law"][hi] - out["law"][lo],
           "rise_predicted": out["pred"][hi] - out["pred"][lo]}
    res["ratio"] = res["rise_measured"] / res["rise_predicted"]
    if static:
        phi_s = contact_angle(0.0)
        res["rise_static"] = out["static"][hi] - out["static"][lo]
        res["law_share_measured"] = res["rise_measured"] - res["rise_static"]
        res["law_share_predicted"] = res["rise_predicted"] - res["rise_static"]
        res["effective_rate"] = {}
        for rate in RATES:
            slope = (out["pred"][rate] - out["static"][rate]) / (contact_angle(rate) - phi_s)
            phi_eff = phi_s + (out["law"][rate] - out["static"][rate]) / slope
            res["effective_rate"][f"{rate:g}"] = RATE0 * 10 ** ((phi_eff / phi_s - 1) / BETA)
    return res


def summarise(per_seed):
    """Mean and sample standard deviation over the seeds of the scalar results."""
    keys = ["rise_measured", "rise_predicted", "ratio", "rise_static", "law_share_measured",
            "law_share_predicted"]
    summary = {}
    for k in keys:
        vals = np.array([s[k] for s in per_seed if k in s])
        if len(vals):
            summary[k] = {"mean": float(vals.mean()),
                          "sd": float(vals.std(ddof=1)) if len(vals) > 1 else float("nan")}
    m, p = summary["rise_measured"]["mean"], summary["rise_predicted"]["mean"]
    summary["ratio_of_means"] = m / p
    return summary


def main(seeds=SEEDS):
    work = scratch("biaxial_rate_friction")
    per_seed = []
    for seed in seeds:
        per_seed.append(study_seed(work, seed))
        print(json.dumps(per_seed[-1]), flush=True)
    out = {"contact_angle_deg": {f"{r:g}": contact_angle(r) for r in (0.0, *RATES)},
           "contact_mu": {f"{r:g}": contact_mu(r) for r in (0.0, *RATES)},
           "seeds": per_seed, "summary": summarise(per_seed)}
    (work / "rates.json").write_text(json.dumps(out, indent=1))
    print(json.dumps(out["summary"], indent=1))
    return out


if __name__ == "__main__":
    main(tuple(int(a) for a in sys.argv[1:]) or SEEDS)
