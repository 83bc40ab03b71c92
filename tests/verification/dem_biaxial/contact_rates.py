"""Diagnostic of rate_study.py (docs/validation.md, "DEM: biaxial test", rate-dependent friction):
the contact strain rates |v_n| / (r1 + r2) the law sees, sampled from frames of a law-on run
(a frame every 0.05 % of eps_1, those in eps_1 = 0.375-1 %; every touching pair of grains, from
the frames' positions, radii and velocities). Prints their percentiles over the nominal rate,
the fraction at or below the reference rate and the mean contact angle the law gives them.

    CRATER_BIN=... CRATER_TEST_TMP=... /usr/bin/python3 contact_rates.py SEED RATE
"""
import sys, json, math
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
import numpy as np
import rate_study as rs
from biaxial_case import scenario, T_CONS_S
from crater_test import TMP, crater, read_vtu
from scenario_blocks import SAND, material, write_scenario
from scipy.spatial import cKDTree
work = TMP / "biaxial_contact_rates"; work.mkdir(parents=True, exist_ok=True)
seed, rate = int(sys.argv[1]), float(sys.argv[2])
name = f"s{seed}_r{rate:g}"
scn = scenario(seed, work / "cache", strain_rate=rate, axial_strain=0.01, dem={"rate_dependent_friction": True, "friction_rate_beta": rs.BETA, "friction_reference_strain_rate": rs.RATE0}, ramp_s=rs.RAMP_STRAIN / rate, material=material(SAND, friction=rs.MU_S), settle=False)
scn["output"]["interval_s"] = 0.0005 / rate  # a frame every 0.05 % of strain
write_scenario(work / f"{name}.toml", scn)
if not (work / name / "summary.json").exists():
    crater("run", work / f"{name}.toml", "--out", work / name, "--force", "--quiet", timeout=1200)
rates = []
for f in sorted((work / name).glob("soil_*.vtu")):
    p, a, n, t = read_vtu(f)
    e1 = (t - T_CONS_S) * rate  # nominal (ramp ignored)
    if t < T_CONS_S + (0.0025 + 0.00125) / rate or e1 > 0.0105: continue
    x = p[:, :2]; v = a["velocity"][:, :2]; r = a["radius"]
    tree = cKDTree(x)
    pairs = np.array(sorted(tree.query_pairs(2 * r.max())))
    i, j = pairs[:, 0], pairs[:, 1]
    d = x[j] - x[i]; dist = np.linalg.norm(d, axis=1)
    touch = dist < r[i] + r[j]
    i, j, d, dist = i[touch], j[touch], d[touch], dist[touch]
    nrm = d / dist[:, None]
    vn = np.einsum("ij,ij->i", v[j] - v[i], nrm)
    rates.append(np.abs(vn) / (r[i] + r[j]))
c = np.concatenate(rates)
phi_s = math.degrees(math.atan(rs.MU_S))
phi = phi_s * (1 + rs.BETA * np.log10(np.maximum(c / rs.RATE0, 1.0)))
phi_mean = phi.mean()
out = {"run": name, "frames": len(rates), "contacts": int(c.size),
       "rate_over_nominal_pct": {q: float(np.percentile(c, q) / rate) for q in (10, 25, 50, 75, 90)},
       "mean_over_nominal": float(c.mean() / rate),
       "geo_mean_over_nominal": float(np.exp(np.log(np.maximum(c, 1e-12)).mean()) / rate),
       "below_rate0": float((c <= rs.RATE0).mean()),
       "mean_contact_angle": float(phi_mean), "law_at_nominal": rs.contact_angle(rate),
       "eff_rate_from_mean_angle_over_nominal": float(rs.RATE0 * 10 ** ((phi_mean / phi_s - 1) / rs.BETA) / rate)}
print(json.dumps(out))
