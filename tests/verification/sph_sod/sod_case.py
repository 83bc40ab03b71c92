"""The Sod shock tube as a crater scenario in a 2D strip, and its error against the exact
Riemann solution. Shared by test_sod.py (fast) and test_sod_convergence.py (slow)."""
import numpy as np

import exact_riemann
from crater_test import scratch
from scenario_blocks import box, write_scenario
from sph_profiles import frame_at, l1_relative, profile, run

GAMMA = 1.4
LEFT = (1.0, 0.0, 1.0)      # rho, u, p
RIGHT = (0.125, 0.0, 0.1)
X0 = 0.5                    # diaphragm
T_END = 0.2
ROWS = 12                   # particle rows across the strip (the flow is 1D)


def scenario(dx, rows=ROWS):
    height = rows * dx
    return {
        "scenario": {"name": "sph-sod", "dimension": 2, "end_time_s": T_END,
                     "description": f"Sod shock tube in a 2D strip, dx = {dx:g}"},
        "output": {"interval_s": T_END / 2, "history_every": 1000},
        "domain": {"min_m": [0.0, 0.0], "max_m": [1.0, height]},
        "materials": [{"name": "gas", "model": "ideal_gas", "rho0_kg_m3": 1.0,
                       "gamma": GAMMA}],
        "parts": [{
            "name": "gas", "method": "sph", "material": "gas", "spacing_m": dx,
            # The part fills the tube with the left state...
            "region": box([0.0, 0.0], [1.0, height]),
            "initial": {"density_kg_m3": LEFT[0], "pressure_pa": LEFT[2]},
            # ...free-slip Adami walls keep the flow 1D; no wave reaches the ends by T_END.
            "sph": {"walls": ["left", "right", "bottom", "top"], "wall_slip": "free"},
            # ...and one zone holds the right state.
            "zones": [{"region": box([X0, 0.0], [1.0, height]),
                       "density_kg_m3": RIGHT[0], "pressure_pa": RIGHT[2]}],
        }],
    }


def exact(x, t=T_END):
    return exact_riemann.sample(x, t, X0, LEFT, RIGHT, GAMMA)


def run_case(dx, tag, threads=1):
    """Runs the strip at spacing dx; returns a dict with the final frame, the density profile,
    its L1 error, the summary and the wall time."""
    d = scratch(f"sph_sod_{tag}")
    path = write_scenario(d / "sod.toml", scenario(dx),
                          comment=f"Sod shock tube, dx = {dx:g} (tests/verification/sph_sod)")
    summary, wall = run(path, d / "out", threads=threads)
    f0 = frame_at(d / "out", "gas", 0.0)
    f = frame_at(d / "out", "gas", T_END)
    x = f["x"][:, 0]
    # Bins of two spacings: each holds ~2 x ROWS particles where the gas is not rarefied.
    edges = np.linspace(0.0, 1.0, int(round(1.0 / (2 * dx))) + 1)
    xc, rho = profile(x, f["density"], edges)
    err = l1_relative(xc, rho, lambda s: exact(s)[0], 0.0, 1.0)
    return {"dx": dx, "summary": summary, "wall_s": wall, "frame0": f0, "frame": f,
            "xc": xc, "rho": rho, "l1": err, "height": ROWS * dx}
