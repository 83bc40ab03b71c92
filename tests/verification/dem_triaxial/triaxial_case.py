"""The 3D triaxial compression test of the paper's sand (issue 24's soil calibration): the
scenario and the reduction of its history.csv to stresses, strains, friction and dilatancy
angles. Used by test_triaxial.py and plot_triaxial.py (the figure of docs/validation.md); the
3D sibling of tests/verification/dem_biaxial.

Sample: a cube of side L filled by [parts.packing] method = "dense" (spheres, radii uniform in
4-10 mm: the 2.5:1 spread of the paper's coarse range), settled under gravity. Gravity is along
-z, the last axis, so the axial direction is z: its walls are the faces "back" (z min, the
floor: fixed, it reports its load) and "front" (z max, the loading platen); the four side walls
are "left"/"right" (x) and "bottom"/"top" (y) (docs/scenario-format.md: left/right = x,
bottom/top = y, back/front = z). The sample's weight adds rho_b g L = 1.8 kPa from top to bottom
(1.8 % of sigma_3); sigma_1 is taken as the mean of the platen's and the floor's, the mean
vertical stress over the height. The paper's sand: rho 1920, G 29 GPa, nu 0.2, mu 0.84, e 0.5,
Hertz-Mindlin, no rolling resistance. Walls are frictionless (smooth platens). Stages:
  1. 0 - T_CONS: the four side walls and the platen servo-controlled to sigma_3 (isotropic
     consolidation; at most 5 cm/s);
  2. from T_CONS: the platen moves down at eps_rate L (reached over RAMP_S, so that it does not
     strike the sample), the side walls hold sigma_3 (at most 0.5 m/s), to AXIAL_STRAIN.
Inertial number I = eps_rate d sqrt(rho / sigma_3) = 4.9e-4 at 0.25 /s (d = 14 mm, the mean
diameter): quasi-static (I < 1e-3; GDR MiDi 2004).

Reduction (compression positive; the sample's sides from the wall positions, their values at
T_CONS the reference):
  eps_1 = (H0 - H)/H0 (z), eps_x, eps_y likewise, eps_3 = (eps_x + eps_y)/2,
  eps_v = 1 - V/V0, V = H X Y (the small-strain eps_1 + eps_x + eps_y = eps_1 + 2 eps_3,
  "ev_small", leaves out the products of the strains: it reads -3.4 % for -2.5 % at
  eps_1 = 10 %, seed 1; the figure and the tests use 1 - V/V0);
  sigma_1 = (sigma_front + sigma_back)/2, sigma_3 = mean of the four side walls';
  mobilised friction sin(phi) = (sigma_1 - sigma_3)/(sigma_1 + sigma_3) (Mohr-Coulomb, c = 0);
  dilatancy (triaxial compression) sin(psi) = -(d eps_v/d eps_1) / (2 - d eps_v/d eps_1),
  the Mohr-Coulomb plastic potential at the triaxial-compression corner (Vermeer & de Borst
  1984, Heron 29(3); Schanz & Vermeer 1996, Geotechnique 46(1); as recalled), d eps_v/d eps_1
  the slope of a straight line fitted to eps_v against eps_1 over PSI_WINDOW (eps_1 = 1-4 %:
  from the end of the first contraction through the peak, where it dilates fastest).
  Bolton (1986)'s triaxial index is that slope itself, (-d eps_v/d eps_1)_max = 0.3 I_R,
  also reported ("dilation_rate").
Peak: the largest mean of phi over bins of BIN of eps_1; residual: the mean over RESIDUAL of
eps_1.
"""
import csv
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from scenario_blocks import SAND, box, compose_scenario, domain, output, part  # noqa: E402

L_M = 0.15
SIGMA3_PA = 1.0e5
T_CONS_S = 0.04
RAMP_S = 0.01
STRAIN_RATE = 0.25  # 1/s
AXIAL_STRAIN = 0.10
BIN = 0.005
RESIDUAL = (0.07, 0.10)
PSI_WINDOW = (0.01, 0.04)
SEEDS = (1, 2, 3)
SIDES = ("left", "right", "bottom", "top")  # x min, x max, y min, y max


def scenario(seed, cache_dir, strain_rate=STRAIN_RATE, axial_strain=AXIAL_STRAIN, dem=None,
             ramp_s=RAMP_S, side_m=L_M, history_every=50, radii_m=(0.004, 0.01),
             t_cons_s=T_CONS_S, gravity_m_s2=-9.81, packing=None):
    """The triaxial test of one packing (seed); `dem` adds [parts.dem] keys, `packing`
    [parts.packing] keys. The defaults are the case above; scaled(lam) gives the keywords of
    the same case with every length and time multiplied by lam (tests/verification/
    dem_grain_size)."""
    L = side_m
    end = t_cons_s + axial_strain / strain_rate
    motion = []
    for face, x in zip(SIDES, (0.0, L, 0.0, L)):
        motion += [{"face": face, "position_m": x, "stress_pa": SIGMA3_PA,
                    "max_speed_m_s": 0.05, "end_s": t_cons_s},
                   {"face": face, "stress_pa": SIGMA3_PA, "max_speed_m_s": 0.5,
                    "start_s": t_cons_s}]
    motion += [{"face": "front", "position_m": L, "stress_pa": SIGMA3_PA,
                "max_speed_m_s": 0.05, "end_s": t_cons_s},
               {"face": "front", "velocity_m_s": -strain_rate * L, "start_s": t_cons_s,
                "ramp_s": ramp_s},
               {"face": "back", "velocity_m_s": 0.0}]  # fixed: reports its load
    keys = {"radius_min_m": radii_m[0], "radius_max_m": radii_m[1], "seed": seed,
            "wall_friction": 0.0,
            "walls": [*SIDES, "back", "front"], "wall_motion": motion, **(dem or {})}
    return compose_scenario(
        "triaxial", 3, end,
        description="Triaxial compression of the paper's sand (tests/verification/dem_triaxial)",
        domain=domain([-0.1 * L, -0.1 * L, 0.0], [1.1 * L, 1.1 * L, 1.05 * L],
                      [0.0, 0.0, gravity_m_s2]),
        output=output(t_cons_s, history_every), materials=[SAND],
        parts=[part("soil", "dem", "sand", 2 * radii_m[1], box([0.0, 0.0, 0.0], [L, L, L]),
                    dem=keys,
                    packing={"method": "dense", "settle": True, "cache_dir": str(cache_dir),
                             **(packing or {})})])


def scaled(lam, gravity_scaled=True):
    """scenario() keywords of the case with every length (grains, sample) and time (stages,
    frames; so the strain rate / lam) multiplied by lam: the same inertial number. Velocities
    (servo limits, the platen's speed), stresses, densities and moduli are unchanged. With
    gravity_scaled, g / lam as well, so that rho g L / sigma_3 is unchanged and the case is
    similar to the unscaled one in every term (docs/validation.md, "DEM: the bed's properties
    do not depend on grain size"); settling may then last lam times longer, hence
    settle_max_time_s (2 s by default) x lam."""
    return {"strain_rate": STRAIN_RATE / lam, "ramp_s": RAMP_S * lam, "side_m": L_M * lam,
            "radii_m": (0.004 * lam, 0.01 * lam), "t_cons_s": T_CONS_S * lam,
            "gravity_m_s2": -9.81 / lam if gravity_scaled else -9.81,
            "packing": {"settle_max_time_s": 2.0 * lam}}


def reduce(history_csv, t_cons=T_CONS_S):
    """Stresses, strains and angles of one run's history.csv, from the start of shearing."""
    with open(history_csv) as f:
        rows = list(csv.DictReader(f))
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    w = "soil_wall_"
    t = col["time_s"]
    H = col[w + "front_position_m"] - col[w + "back_position_m"]
    X = col[w + "right_position_m"] - col[w + "left_position_m"]
    Y = col[w + "top_position_m"] - col[w + "bottom_position_m"]
    s1 = 0.5 * (col[w + "front_stress_pa"] + col[w + "back_stress_pa"])
    s3 = np.mean([col[w + f + "_stress_pa"] for f in SIDES], axis=0)
    i0 = int(np.searchsorted(t, t_cons))
    shear = slice(i0, None)
    e1 = (H[i0] - H) / H[i0]
    ex = (X[i0] - X) / X[i0]
    ey = (Y[i0] - Y) / Y[i0]
    ev = 1.0 - H * X * Y / (H[i0] * X[i0] * Y[i0])
    r = {"t": t[shear], "e1": e1[shear], "e3": 0.5 * (ex + ey)[shear], "ev": ev[shear],
         "ev_small": (e1 + ex + ey)[shear], "s1": s1[shear], "s3": s3[shear],
         "s3_consolidated": s3[i0 - 20:i0],
         "s_sides_consolidated": {f: col[w + f + "_stress_pa"][i0 - 20:i0] for f in SIDES},
         "s_sides": {f: col[w + f + "_stress_pa"][shear] for f in SIDES},
         "s_top_consolidated": col[w + "front_stress_pa"][i0 - 20:i0],
         "volume0_m3": float(H[i0] * X[i0] * Y[i0])}
    r["phi"] = np.degrees(np.arcsin((r["s1"] - r["s3"]) / (r["s1"] + r["s3"])))
    return r


def dilatancy_angle(slope):
    """sin(psi) of triaxial compression from d eps_v / d eps_1 (compression positive)."""
    return float(np.degrees(np.arcsin(np.clip(-slope / (2.0 - slope), -1, 1))))


def angles(r):
    """Peak and residual friction angle, the dilatancy angle [deg] and the curve of phi in
    bins of eps_1 (bin centres, means)."""
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
    slope = float(np.polyfit(e1[win], r["ev"][win], 1)[0])
    return {"phi_peak": float(means[k]), "e1_peak": float(centres[k]),
            "phi_residual": float(phi[res].mean()) if res.any() else float("nan"),
            "psi": dilatancy_angle(slope), "dilation_rate": -slope,
            "ev_contraction_max": float(r["ev"].max()), "ev_end": float(r["ev"][-1]),
            "bins": (np.array(centres), means)}


def solid_fraction(centres, radii, lo, hi, margin, h=5e-4):
    """Solid fraction of the spheres in the box [lo + margin, hi - margin] (per axis), by
    counting the points of a grid of spacing h that lie inside a sphere (a sphere's cap that
    crosses the box's faces counts for its part inside). margin = 0: the whole sample, wall
    layers included; margin = 2 r_max: the interior, away from the walls' looser layers (the
    value that compares with a random packing's 0.64)."""
    a = np.asarray(lo, float) + margin
    b = np.asarray(hi, float) - margin
    n = np.maximum(np.round((b - a) / h).astype(int), 1)
    axes = [a[d] + (np.arange(n[d]) + 0.5) * (b[d] - a[d]) / n[d] for d in range(3)]
    full = np.zeros(tuple(n), dtype=bool)
    for c, r in zip(centres, radii):
        idx = []
        for d in range(3):
            i0 = np.searchsorted(axes[d], c[d] - r)
            i1 = np.searchsorted(axes[d], c[d] + r)
            idx.append((i0, i1))
        if any(i0 >= i1 for i0, i1 in idx):
            continue
        gx, gy, gz = (axes[d][idx[d][0]:idx[d][1]] - c[d] for d in range(3))
        inside = (gx[:, None, None] ** 2 + gy[None, :, None] ** 2
                  + gz[None, None, :] ** 2) <= r * r
        full[idx[0][0]:idx[0][1], idx[1][0]:idx[1][1], idx[2][0]:idx[2][1]] |= inside
    return float(full.mean())


def frame_solid_fractions(out_dir, t, r_max=0.01, h=5e-4):
    """(whole, interior) solid fraction of the frame of soil.pvd nearest time t (a frame
    every T_CONS_S): the grains' volume over the walls' box of that moment (history.csv), and
    solid_fraction() 2 r_max inside that box."""
    from crater_test import read_pvd, read_vtu
    out_dir = Path(out_dir)
    frames = read_pvd(out_dir / "soil.pvd")
    tf, name = min(frames, key=lambda f: abs(f[0] - t))
    pts, fields, _, _ = read_vtu(out_dir / name)
    with open(out_dir / "history.csv") as f:
        rows = list(csv.DictReader(f))
    row = min(rows, key=lambda x: abs(float(x["time_s"]) - tf))
    w = "soil_wall_"
    lo = [float(row[w + k + "_position_m"]) for k in ("left", "bottom", "back")]
    hi = [float(row[w + k + "_position_m"]) for k in ("right", "top", "front")]
    r = fields["radius"]
    whole = float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / np.prod(np.subtract(hi, lo)))
    return whole, solid_fraction(pts, r, lo, hi, 2 * r_max, h)
