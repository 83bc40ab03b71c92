"""A heap of spheres poured in batches onto a floor, and the angle of its flanks; shared by
test_angle_of_repose.py (mu = 0.84) and test_angle_of_repose_sweep.py (mu = 0.2, 0.5, 0.84).

The reference, Zhou, Xu, Yu & Zulli, "An experimental and numerical study of the angle of
repose of coarse spheres", Powder Technol. 125 (2002) 45-54, doi:10.1016/S0032-5910(01)00520-4,
fits the angle of the heaps of their DEM runs (monosized spheres discharged from a plate) with
(their Eq. 5, no front and rear walls; as quoted in the Lethe documentation,
chaos-polymtl/lethe doc/source/examples/dem/plate-discharge, which reproduces 19.7 degrees for
its own inputs with it):

    theta = 68.61 mu_s,pp^0.27 mu_s,pw^0.22 mu_r,pp^0.06 mu_r,pw^0.12 d^-0.2   [degrees]

with d the diameter in mm and mu_r Zhou's rolling friction coefficients, lengths in mm (a
constant torque mu_r |F_n| against rolling; pp between particles, pw against the walls). A
standard deviation of 2 degrees is quoted with the fit.

Conversion of the rolling friction: crater's rolling resistance (Ai et al. 2011 model C) caps
the rolling torque at mu_r R* |F_n|, R* = r/2 between equal spheres and r against a wall, so
the same limiting torque is Zhou's mu_r,pp = mu_r d/4 and mu_r,pw = mu_r d/2 (mm). crater's
mu_r = 0.02 with d = 10 mm is Zhou's base case, mu_r,pp = 0.05 mm and mu_r,pw = 0.1 mm. The
models differ below the limit (Zhou's torque is constant while rolling; model C is an
elastic-plastic spring, k_r = 2.25 k_n mu_r^2 R*^2); the parameters are converted, the model is
not changed.

The run: spheres of radius uniform in [4.5, 5] mm (d = 9.5 mm on average), glass-like density
2500 kg/m^3, linear springs k_n = 2000 N/m (overlaps under the heap's weight below 1 % of r;
Zhou et al. find the angle insensitive to stiffness and damping), restitution 0.4, wall
(floor) friction 0.6 as Zhou's base case, no front and rear walls near the heap (the domain's
faces are 30 d from its axis). Batches of 150 spheres (a 5 x 6 x 5 block of pitch 1.1 d,
jittered, at rest) are dropped 0.6 d above the apex, 16 times, each followed by 0.25 s (the last
by 0.6 s); the velocities carry over between batches (each batch is a new run, the contact
springs restart from zero). The angle: the heap's surface is the highest sphere top in rings
of width d around its axis; a line is fitted to the rings whose height lies between 20 % and
80 % of the apex height (and above 1.5 d: the single layer of spheres that rolled away).
"""
import math

import numpy as np

from crater_test import read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (BEADS, box, compose_scenario, domain, material, output, part,
                             particle, scenario_text)

D = 0.010  # nominal diameter [m]
R_MIN, R_MAX = 0.45 * D, 0.5 * D
KN = 2.0e3  # linear springs [N/m]
ROLLING = 0.02  # crater's mu_r: Zhou's base case for d = 10 mm
WALL_FRICTION = 0.6
HALF = 0.3  # the domain's half-width [m]
BATCH = (5, 6, 5)
STAGES, STAGE_S, LAST_S = 16, 0.25, 0.6


def zhou_angle(mu, mu_wall=WALL_FRICTION, rolling=ROLLING, d_mm=1e3 * (R_MIN + R_MAX)):
    """Zhou et al. 2002 Eq. 5 [degrees], crater's mu_r converted to their lengths in mm."""
    mu_r_pp = rolling * d_mm / 4
    mu_r_pw = rolling * d_mm / 2
    return (68.61 * mu**0.27 * mu_wall**0.22 * mu_r_pp**0.06 * mu_r_pw**0.12
            * d_mm**-0.2)


def scenario(mu, grains, end, half=HALF, walls=("bottom", "left", "right", "back", "front", "top"),
             rolling=ROLLING, outflow="stop"):
    """The case's TOML: a box 2 half wide (x, z) and HALF high; drained_heap.py narrows it,
    takes walls away and removes the spheres that leave it (outflow)."""
    lo, hi = [-half, 0.0, -half], [half, HALF, half]
    return scenario_text(compose_scenario(
        "poured-heap", 3, end, output=output(end),
        domain=domain(lo, hi, gravity=[0.0, -9.81, 0.0], outflow=outflow),
        materials=[material(BEADS, friction=mu, restitution=0.4)],
        parts=[part("heap", "dem", "beads", D, box(lo, hi),
                    dem={"contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "rolling_friction": rolling, "rolling_damping": 0.3,
                         "walls": list(walls), "wall_friction": WALL_FRICTION,
                         "wall_restitution": 0.4},
                    particles=[particle(list(x), r, list(v)) for x, r, v in grains])]))


def batch(rng, apex):
    pitch = 1.1 * D
    nx, ny, nz = BATCH
    out = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                c = np.array([(i - (nx - 1) / 2) * pitch, apex + 0.6 * D + j * pitch,
                              (k - (nz - 1) / 2) * pitch])
                out.append((c + rng.uniform(-0.05 * D, 0.05 * D, 3), rng.uniform(R_MIN, R_MAX),
                            np.zeros(3)))
    return out


def surface(points, radius):
    """(ring radius, highest sphere top) of rings of width D around the vertical axis."""
    rho = np.hypot(points[:, 0], points[:, 2])
    top = points[:, 1] + radius
    ring = (rho / D).astype(int)
    rings = np.unique(ring)
    return (rings + 0.5) * D, np.array([top[ring == k].max() for k in rings])


def fitted_angle(rs, hs, floor=0.0):
    """(angle [deg], apex [m], points fitted) of the line through the surface heights hs at
    distances rs from the axis, over the heights between 20 % and 80 % of the apex (and above
    floor)."""
    apex = hs.max()
    fit = (hs > 0.2 * apex) & (hs < 0.8 * apex) & (hs > floor)
    slope = np.polyfit(rs[fit], hs[fit], 1)[0]
    return math.degrees(math.atan(-slope)), apex, int(fit.sum())


def flank_angle(points, radius):
    return fitted_angle(*surface(points, radius), floor=1.5 * D)


def pour(mu, seed=7, name=None):
    """Pours the heap; returns (angle [deg], apex height [m], rings fitted, grains, kinetic
    energy at the end [J])."""
    d = scratch(name or f"dem_repose_mu{mu}_s{seed}")
    rng = np.random.default_rng(seed)
    grains, apex = [], 0.0
    for stage in range(STAGES):
        grains += batch(rng, apex)
        (d / "case.toml").write_text(scenario(mu, grains, LAST_S if stage == STAGES - 1
                                              else STAGE_S))
        summary = run_scenario(d / "case.toml", d / "out", threads=1)
        _, frame = read_pvd(d / "out" / "heap.pvd")[-1]
        points, arrays, _, _ = read_vtu(d / "out" / frame)
        grains = list(zip(points, arrays["radius"], arrays["velocity"]))
        top = points[:, 1] + arrays["radius"]
        near = np.hypot(points[:, 0], points[:, 2]) < 2 * D
        apex = top[near].max() if near.any() else top.max()
    angle, height, rings = flank_angle(points, arrays["radius"])
    kinetic = summary["energy"]["final"]["kinetic_j"]
    return angle, height, rings, len(grains), kinetic
