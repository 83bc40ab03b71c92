"""Diagnostic of rate_study.py (docs/validation.md, "DEM: biaxial test", rate-dependent
friction): the contact strain rates |v_n| / (r1 + r2) the law sees, against the nominal axial
rate the prediction assumes.

Method: one law-on run of rate_study.py's case (seed, rate) to eps_1 = 1 % with a frame every
0.05 % of eps_1; in the frames of eps_1 = 0.375-1 % (nominal, from the start of shearing),
every touching pair of grains (centre distance < r1 + r2), v_n = (v_j - v_i) . n from the
frames' velocities. Prints the percentiles of |v_n| / (r1 + r2) over the nominal rate, the
fraction at or below the reference rate, the mean contact angle the law gives them and the
rate at which the law gives that angle. A snapshot of every contact, sliding or not: not the
rate of the sliding contacts at the moment they slide, which is what sets the strength.

    CRATER_BIN=build/release/bin/crater CRATER_TEST_TMP=/tmp/crater-rates \
        /usr/bin/python3 tests/verification/dem_biaxial/contact_rates.py SEED RATE

About 30 s (1 /s) to 1 minute (0.1 /s) on one core.
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
import rate_study as rs  # noqa: E402
from biaxial_case import T_CONS_S, scenario  # noqa: E402
from crater_test import TMP, crater, read_vtu  # noqa: E402
from scenario_blocks import SAND, material, write_scenario  # noqa: E402

FRAME_STRAIN = 0.0005
BAND = (rs.RAMP_STRAIN + 0.00125, 0.0105)  # of the nominal eps_1


def contact_rates(run_dir, rate):
    """|v_n| / (r1 + r2) [1/s] of every touching pair in the frames of BAND."""
    out = []
    for f in sorted(Path(run_dir).glob("soil_*.vtu")):
        p, a, _, t = read_vtu(f)
        e1 = (t - T_CONS_S) * rate
        if not BAND[0] <= e1 <= BAND[1]:
            continue
        x, v, r = p[:, :2], a["velocity"][:, :2], a["radius"]
        i, j = np.triu_indices(len(r), k=1)  # every pair: a few hundred grains
        d = x[j] - x[i]
        dist = np.linalg.norm(d, axis=1)
        touch = dist < r[i] + r[j]
        i, j, n = i[touch], j[touch], d[touch] / dist[touch, None]
        vn = np.einsum("ij,ij->i", v[j] - v[i], n)
        out.append(np.abs(vn) / (r[i] + r[j]))
    return out


def main(seed, rate):
    work = TMP / "biaxial_contact_rates"
    work.mkdir(parents=True, exist_ok=True)
    name = f"seed{seed}_rate{rate:g}"
    scn = scenario(seed, work / "cache", strain_rate=rate, axial_strain=0.01,
                   dem={"rate_dependent_friction": True, "friction_rate_beta": rs.BETA,
                        "friction_reference_strain_rate": rs.RATE0},
                   ramp_s=rs.RAMP_STRAIN / rate, material=material(SAND, friction=rs.MU_S),
                   settle=False)
    scn["output"]["interval_s"] = FRAME_STRAIN / rate
    write_scenario(work / f"{name}.toml", scn)
    crater("run", work / f"{name}.toml", "--out", work / name, "--force", "--quiet",
           timeout=1200)
    frames = contact_rates(work / name, rate)
    c = np.concatenate(frames)
    phi_s = rs.contact_angle(0.0)
    phi = phi_s * (1 + rs.BETA * np.log10(np.maximum(c / rs.RATE0, 1.0)))
    out = {"seed": seed, "rate": rate, "frames": len(frames), "contacts": int(c.size),
           "percentiles_over_nominal": {q: float(np.percentile(c, q) / rate)
                                        for q in (10, 25, 50, 75, 90)},
           "mean_over_nominal": float(c.mean() / rate),
           "at_or_below_rate0": float((c <= rs.RATE0).mean()),
           "mean_contact_angle_deg": float(phi.mean()),
           "law_angle_at_nominal_deg": rs.contact_angle(rate),
           "rate_of_mean_angle_over_nominal": float(
               rs.RATE0 * 10 ** ((phi.mean() / phi_s - 1) / rs.BETA) / rate)}
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main(int(sys.argv[1]), float(sys.argv[2]))
