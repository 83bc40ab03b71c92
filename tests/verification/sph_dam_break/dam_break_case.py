"""The Martin & Moyce (1952) dam break as a crater scenario (weakly compressible SPH, Tait EOS)
and its surge-front history. Shared by the fast and the slow dam-break tests."""
import math

import numpy as np

from crater_test import scratch
from scenario_blocks import box, write_scenario
from sph_profiles import frames, load_frame, run

# J. C. Martin and W. J. Moyce, "Part IV. An experimental study of the collapse of liquid columns
# on a rigid horizontal plane", Phil. Trans. R. Soc. Lond. A 244 (1952) 312-324,
# doi:10.1098/rsta.1952.0006. Column of width a and height n^2 a; here n^2 = 2 and
# a = 2 1/4 in = 0.05715 m (their larger column). Surge front Z = z / a against
# T = n t sqrt(g / a) = t sqrt(2 g / a). The points, T <= 2.5, are their Table 2 as
# transcribed in Ocellaris (github.com/TormodLandet/Ocellaris, scripts/plot_dam_break.py,
# "Data from Martin and Moyce (1952), Table 2 and 6"); Lethe's transcription
# (github.com/chaos-polymtl/lethe, examples/multiphysics/dam-break/dam-break-2d.py) agrees to
# +-0.02 in T, and PySPH's digitisation of their Fig. 3 for the same column
# (github.com/pypr/pysph, pysph/examples/db_exp_data.py) lies on the same curve (e.g. T = 1.997,
# Z = 2.292; T = 2.547, Z = 2.995). Z advances in steps of 0.5 in / a = 2/9: the times at which
# the front passed marks on the plane.
MM_T = np.array([0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32])
MM_Z = np.array([1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78])

A = 0.05715                 # m, column width
N2 = 2.0                    # column height / width
G = 9.81                    # m/s^2
RHO0 = 1000.0               # kg/m^3
GAMMA = 7.0
H = N2 * A                  # m, column height
# Weakly compressible: c0 >= 10 sqrt(2 g H) keeps density variations ~ 1 % (Monaghan 1994).
C0 = 15.0                   # m/s; 10 sqrt(2 g H) = 14.98 m/s
T_SCALE = math.sqrt(2 * G / A)   # T = t * T_SCALE
T_END = 2.6                 # in T
DT_OUT = 0.05               # in T
BOX_W = 6 * A               # the front stays below 4 a up to T = 2.6
BOX_H = 3 * A

# Numerics: Monaghan viscosity alpha = 0.1, beta = 0 (the usual weakly compressible SPH choice,
# e.g. the DualSPHysics dam-break cases, Crespo et al., Comput. Phys. Commun. 187 (2015) 204);
# no XSPH, no tensile correction, no physical viscosity. Walls: Adami, free slip (at this
# Reynolds number, ~ 1e5, the wall boundary layer does not set the front speed).
AV_ALPHA = 0.1


def hydrostatic_density(y):
    """Density of the Tait fluid in hydrostatic equilibrium under the free surface y = H."""
    b = RHO0 * C0 * C0 / GAMMA
    return RHO0 * (1 + RHO0 * G * (H - y) / b) ** (1 / GAMMA)


def scenario(dx):
    rows = int(round(H / dx))
    return {
        "scenario": {"name": "sph-dam-break", "dimension": 2, "end_time_s": T_END / T_SCALE,
                     "description": "Martin & Moyce (1952) dam break, n^2 = 2, a = 2.25 in"},
        "output": {"interval_s": DT_OUT / T_SCALE, "history_every": 100},
        "domain": {"min_m": [0.0, 0.0], "max_m": [BOX_W, BOX_H], "gravity_m_s2": [0.0, -G]},
        "materials": [{"name": "water", "model": "tait", "rho0_kg_m3": RHO0, "c0_m_s": C0,
                       "gamma": GAMMA, "background_pa": 0.0}],
        "parts": [{
            "name": "water", "method": "sph", "material": "water", "spacing_m": dx,
            "region": box([0.0, 0.0], [A, H]),
            "sph": {"walls": ["left", "right", "bottom"], "wall_slip": "free",
                    "av_alpha": AV_ALPHA, "av_beta": 0.0},
            # Hydrostatic start: one zone per particle row, density from the Tait law.
            "zones": [{"region": box([0.0, j * dx], [A, (j + 1) * dx]),
                       "density_kg_m3": hydrostatic_density((j + 0.5) * dx)}
                      for j in range(rows)],
        }],
    }


def run_case(dx, tag, threads=1):
    """Runs the dam break at spacing dx; returns T, Z (front) per frame, frames, summary."""
    d = scratch(f"sph_dam_break_{tag}")
    path = write_scenario(d / "dam.toml", scenario(dx),
                          comment=f"Martin & Moyce dam break, dx = {dx:g} m "
                                  "(tests/verification/sph_dam_break)")
    summary, wall = run(path, d / "out", threads=threads)
    ts, zs, fr = [], [], []
    for t, p in frames(d / "out", "water"):
        f = load_frame(p)
        # Each particle stands for a dx x dx cell: the water's edge is dx/2 past the last
        # particle centre (Z = 1 exactly at t = 0).
        zs.append((f["x"][:, 0].max() + 0.5 * dx) / A)
        ts.append(t * T_SCALE)
        fr.append((t, f))
    return {"dx": dx, "T": np.array(ts), "Z": np.array(zs), "frames": fr, "summary": summary,
            "wall_s": wall}


# Experiments lag an instantaneous release: the restraint takes a finite time to clear the
# column, so simulated fronts run ahead of Martin & Moyce's early points. Lethe's comparison
# with the same data (examples/multiphysics/dam-break/dam-break-2d.py, `time_correction =
# 0.175`) adds 0.175 to the simulated T; an interFoam (VOF) validation against the same points
# (github.com/vamseeachanta/digitalmodel, pull request 1260) uses the same +0.175 and reports a
# 9.8 % mean deviation without it. We adopt that published value unchanged (it is not fitted
# here): the simulated front at T - T_SHIFT is compared with the measurement at T.
T_SHIFT = 0.175


def front_errors(T, Z, shift=T_SHIFT):
    """Simulated front at the measured times (shifted by `shift`) and its relative error."""
    z_sim = np.interp(MM_T - shift, T, Z)
    return z_sim, z_sim / MM_Z - 1
