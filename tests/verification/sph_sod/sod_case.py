"""The Sod shock tube as a crater scenario in a 2D strip, and its error against the exact
Riemann solution. Shared by test_sod.py (fast) and test_sod_convergence.py (slow).

Run as a script it is the convergence study of docs/validation.md (Sod): L1 density error, its
share by region, the contact's pressure blip, steps and wall time per spacing, and the observed
orders, e.g. from the repository root after `make build`:

    PYTHONPATH=tests/lib /usr/bin/python3 tests/verification/sph_sod/sod_case.py 200 400 800 1600
    ... --conductivity 1 200 400 800 1600                (Price's artificial conductivity on)
    ... --h-factor 1.3,1.6,2.0,2.5 200 400 800 1600      (one h_factor per spacing)
    ... --density summation 200 400 800 1600             ([parts.sph] density)

(outputs under CRATER_TEST_TMP, else the system's temporary directory; one thread each).
"""
import argparse
import math
import sys

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


def scenario(dx, rows=ROWS, conductivity=0.0, h_factor=None, density=None):
    """The strip at spacing dx. conductivity: [parts.sph] conductivity_alpha (Price 2008);
    h_factor, density: [parts.sph] h_factor and density; each left out of the file when unset
    (the defaults)."""
    height = rows * dx
    sph = {"walls": ["left", "right", "bottom", "top"], "wall_slip": "free"}
    if conductivity:
        sph["conductivity_alpha"] = conductivity
    if h_factor is not None:
        sph["h_factor"] = h_factor
    if density is not None:
        sph["density"] = density
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
            "sph": sph,
            # ...and one zone holds the right state.
            "zones": [{"region": box([X0, 0.0], [1.0, height]),
                       "density_kg_m3": RIGHT[0], "pressure_pa": RIGHT[2]}],
        }],
    }


def exact(x, t=T_END):
    return exact_riemann.sample(x, t, X0, LEFT, RIGHT, GAMMA)


def waves(t=T_END):
    """Exact positions at t of the rarefaction's tail, the contact and the shock (Toro 2009,
    ch. 4: tail speed u* - a*_L, right shock speed)."""
    p_star, u_star = exact_riemann.star_state(LEFT, RIGHT, GAMMA)
    a_l = math.sqrt(GAMMA * LEFT[2] / LEFT[0])
    a_r = math.sqrt(GAMMA * RIGHT[2] / RIGHT[0])
    a_star_l = a_l * (p_star / LEFT[2]) ** ((GAMMA - 1) / (2 * GAMMA))
    s_r = RIGHT[1] + a_r * math.sqrt((GAMMA + 1) / (2 * GAMMA) * p_star / RIGHT[2]
                                     + (GAMMA - 1) / (2 * GAMMA))
    return X0 + (u_star - a_star_l) * t, X0 + u_star * t, X0 + s_r * t


# The regions of error_by_region, bounded by the exact waves (+- 0.03 around the contact and
# the shock, about 5 h at dx = 1/200).
REGIONS = ("rarefaction", "left star", "contact", "right star", "shock")


def error_by_region(xc, rho, n_fine=20000):
    """The L1 error of l1_relative on [0, 1], split into its shares (same units: fractions of
    the integral of the exact density) over REGIONS."""
    tail, contact, shock = waves()
    bounds = [0.0, tail, contact - 0.03, contact + 0.03, shock - 0.03, 1.0 + 1e-12]
    xf = (np.arange(n_fine) + 0.5) / n_fine
    ex = exact(xf)[0]
    dev = np.abs(np.interp(xf, xc, rho) - ex)
    return {name: float(dev[(xf >= a) & (xf < b)].sum() / np.abs(ex).sum())
            for name, a, b in zip(REGIONS, bounds, bounds[1:])}


def contact_blip(x, p):
    """The pressure blip at the contact discontinuity: the largest particle pressure within 0.03
    of the exact contact, where the exact pressure is p* throughout, as (p_max - p*) / p*."""
    p_star, _ = exact_riemann.star_state(LEFT, RIGHT, GAMMA)
    _, contact, _ = waves()
    return float((p[np.abs(x - contact) <= 0.03].max() - p_star) / p_star)


def run_case(dx, tag, threads=1, conductivity=0.0, h_factor=None, density=None):
    """Runs the strip at spacing dx; returns a dict with the final frame, the density profile,
    its L1 error and that error's shares by region, the contact's pressure blip, the summary and
    the wall time."""
    d = scratch(f"sph_sod_{tag}")
    path = write_scenario(d / "sod.toml", scenario(dx, conductivity=conductivity,
                                                   h_factor=h_factor, density=density),
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
            "xc": xc, "rho": rho, "l1": err, "regions": error_by_region(xc, rho),
            "blip": contact_blip(x, f["pressure"]), "height": ROWS * dx}


def describe(r):
    """One line on a run: L1 error, its shares, blip, steps and wall time."""
    shares = ", ".join(f"{k} {100 * v:.3f}" for k, v in r["regions"].items())
    return (f"dx = 1/{1 / r['dx']:.0f}: L1 {100 * r['l1']:.3f} % ({shares}); contact blip "
            f"{100 * r['blip']:+.0f} %; {r['summary']['steps']} steps, {r['wall_s']:.1f} s")


def main(argv):
    ap = argparse.ArgumentParser(description="Sod convergence study (docs/validation.md)")
    ap.add_argument("per_dx", type=int, nargs="+", help="1/dx of each run")
    ap.add_argument("--conductivity", type=float, default=0.0, help="conductivity_alpha")
    ap.add_argument("--h-factor", default=None,
                    help="h_factor: one for all runs, or one per spacing separated by commas")
    ap.add_argument("--density", default=None, help="[parts.sph] density")
    a = ap.parse_args(argv)
    hf = [float(v) for v in a.h_factor.split(",")] if a.h_factor else [None]
    hf = hf * len(a.per_dx) if len(hf) == 1 else hf
    if len(hf) != len(a.per_dx):
        ap.error("give one h_factor or one per spacing")
    runs = []
    for n, h in zip(a.per_dx, hf):
        tag = f"study_a{a.conductivity:g}_h{h if h else 'default'}_{a.density}_{n}"
        runs.append(run_case(1.0 / n, tag, conductivity=a.conductivity, h_factor=h,
                             density=a.density))
        print(describe(runs[-1]) + (f", h_factor {h:g}" if h else ""), flush=True)
    for p, q in zip(runs, runs[1:]):
        print(f"order 1/{1 / p['dx']:.0f} -> 1/{1 / q['dx']:.0f}: "
              f"{math.log2(p['l1'] / q['l1']):.3f}")


if __name__ == "__main__":
    main(sys.argv[1:])
