"""The 2D (plane-strain) biaxial test of the paper's sand (issue 24): the scenario and the
reduction of its history.csv to stresses, strains, friction and dilatancy angles. Used by
test_biaxial.py and plot_biaxial.py (the figure of docs/validation.md).

Sample: a W x H = 0.2 m x 0.4 m box filled by [parts.packing] method = "dense" (about 400
disks, radii uniform in 4-10 mm: the 2.5:1 spread of the paper's coarse range), settled under
gravity (the dense method lays the bed from a floor, so gravity stays on: the sample's weight
adds rho_b g H = 6 kPa from top to bottom, 6 % of sigma_3; sigma_1 is taken as the mean of the
top and bottom walls', the mean vertical stress over the height). The paper's sand: rho 1920,
G 29 GPa, nu 0.2, mu 0.84, e 0.5, Hertz-Mindlin with hertz_2d = "row_of_spheres". Walls are
frictionless (smooth platens). Stages:
  1. 0 - T_CONS: the side walls and the top servo-controlled to sigma_3 (isotropic
     consolidation; at most 5 cm/s);
  2. from T_CONS: the top moves down at eps_rate H (reached over RAMP_S, so that it does not
     strike the sample), the side walls hold sigma_3 (at most 0.5 m/s), to AXIAL_STRAIN.
Inertial number I = eps_rate d sqrt(rho / sigma_3) = 4.9e-4 at 0.25 /s (d = 14 mm, the mean
diameter): quasi-static (I < 1e-3; GDR MiDi 2004: mu(I) rises by about I, a few 1e-4 here).

Reduction (compression positive; H, W from the wall positions, H0, W0 at T_CONS):
  eps_1 = (H0 - H)/H0, eps_3 = (W0 - W)/W0, eps_v = eps_1 + eps_3 (area), gamma = eps_1 - eps_3;
  sigma_1 = (sigma_top + sigma_bottom)/2, sigma_3 = (sigma_left + sigma_right)/2;
  mobilised friction sin(phi) = (sigma_1 - sigma_3)/(sigma_1 + sigma_3) (Mohr-Coulomb, c = 0);
  dilatancy (plane strain) sin(psi) = -d eps_v / d gamma (Bolton 1986), from a straight line
  fitted to eps_v against gamma over PSI_WINDOW of eps_1 (the rising, dilating part).
Peak: the largest mean of phi over bins of BIN of eps_1; residual: the mean over RESIDUAL of
eps_1.
"""
import csv
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from scenario_blocks import SAND, box, compose_scenario, domain, output, part  # noqa: E402

W_M, H_M = 0.2, 0.4
SIGMA3_PA = 1.0e5
T_CONS_S = 0.04
RAMP_S = 0.01
STRAIN_RATE = 0.25  # 1/s
AXIAL_STRAIN = 0.10
BIN = 0.005
RESIDUAL = (0.06, 0.10)
PSI_WINDOW = (0.0025, 0.02)
SEEDS = (1, 2, 3)


def scenario(seed, cache_dir, strain_rate=STRAIN_RATE, axial_strain=AXIAL_STRAIN, dem=None,
             ramp_s=RAMP_S, material=SAND, settle=True, frame_s=None):
    """The biaxial test of one packing (seed); `dem` adds [parts.dem] keys, `material` replaces
    the sand block (e.g. another contact friction), settle = False leaves the dense method's
    bed unsettled (the same grains whatever the contact law: consolidation loads it); frames
    every frame_s (default: half the run; a frame time ends a step, so it changes the run)."""
    end = T_CONS_S + axial_strain / strain_rate
    motion = []
    for face, x in (("left", 0.0), ("right", W_M)):
        motion += [{"face": face, "position_m": x, "stress_pa": SIGMA3_PA,
                    "max_speed_m_s": 0.05, "end_s": T_CONS_S},
                   {"face": face, "stress_pa": SIGMA3_PA, "max_speed_m_s": 0.5,
                    "start_s": T_CONS_S}]
    motion += [{"face": "top", "position_m": H_M, "stress_pa": SIGMA3_PA, "max_speed_m_s": 0.05,
                "end_s": T_CONS_S},
               {"face": "top", "velocity_m_s": -strain_rate * H_M, "start_s": T_CONS_S,
                "ramp_s": ramp_s},
               {"face": "bottom", "velocity_m_s": 0.0}]  # fixed: reports its load
    keys = {"radius_min_m": 0.004, "radius_max_m": 0.01, "hertz_2d": "row_of_spheres",
            "seed": seed, "wall_friction": 0.0, "walls": ["left", "right", "bottom", "top"],
            "wall_motion": motion, **(dem or {})}
    return compose_scenario(
        "biaxial", 2, end,
        description="Plane-strain biaxial test of the paper's sand (tests/verification/dem_biaxial)",
        domain=domain([-0.1 * W_M, 0.0], [1.1 * W_M, 1.05 * H_M], [0.0, -9.81]),
        output=output(frame_s or end / 2, 50), materials=[material],
        parts=[part("soil", "dem", "sand", 0.02, box([0.0, 0.0], [W_M, H_M]), dem=keys,
                    packing={"method": "dense", "settle": settle, "cache_dir": str(cache_dir)})])


def reduce(history_csv, t_cons=T_CONS_S):
    """Stresses, strains and angles of one run's history.csv, from the start of shearing."""
    with open(history_csv) as f:
        rows = list(csv.DictReader(f))
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    w = "soil_wall_"
    t = col["time_s"]
    H = col[w + "top_position_m"] - col[w + "bottom_position_m"]
    W = col[w + "right_position_m"] - col[w + "left_position_m"]
    s1 = 0.5 * (col[w + "top_stress_pa"] + col[w + "bottom_stress_pa"])
    s3 = 0.5 * (col[w + "left_stress_pa"] + col[w + "right_stress_pa"])
    i0 = int(np.searchsorted(t, t_cons))
    shear = slice(i0, None)
    e1 = (H[i0] - H) / H[i0]
    e3 = (W[i0] - W) / W[i0]
    r = {"t": t[shear], "e1": e1[shear], "e3": e3[shear], "ev": (e1 + e3)[shear],
         "s1": s1[shear], "s3": s3[shear], "s3_consolidated": s3[i0 - 20:i0],
         "s_top_consolidated": col[w + "top_stress_pa"][i0 - 20:i0]}
    r["gamma"] = r["e1"] - r["e3"]
    r["phi"] = np.degrees(np.arcsin((r["s1"] - r["s3"]) / (r["s1"] + r["s3"])))
    return r


def angles(r):
    """Peak and residual friction angle, the largest dilatancy angle [deg] and the curve of
    phi in bins of eps_1 (bin centres, means)."""
    e1, phi = r["e1"], r["phi"]
    edges = np.arange(0.0, e1.max() + 1e-12, BIN)
    centres, means = [], []
    for lo in edges:
        m = (e1 >= lo) & (e1 < lo + BIN)
        if m.sum() >= 5:
            centres.append(lo + BIN / 2)
            means.append(phi[m].mean())
    means = np.array(means)
    k = int(np.argmax(means))
    res = (e1 >= RESIDUAL[0]) & (e1 <= RESIDUAL[1])
    win = (e1 >= PSI_WINDOW[0]) & (e1 <= PSI_WINDOW[1])
    slope = np.polyfit(r["gamma"][win], r["ev"][win], 1)[0]
    return {"phi_peak": float(means[k]), "e1_peak": float(centres[k]),
            "phi_residual": float(phi[res].mean()) if res.any() else float("nan"),
            "psi": float(np.degrees(np.arcsin(np.clip(-slope, -1, 1)))),
            "ev_end": float(r["ev"][-1]), "bins": (np.array(centres), means)}
