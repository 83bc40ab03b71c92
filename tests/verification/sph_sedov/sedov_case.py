"""The Sedov-Taylor point blast as a crater scenario: a quadrant (2D) or octant (3D) of the blast
between free-slip mirror walls, and its density peak against the self-similar solution
(tests/lib/sedov_exact.py). Used by test_sedov.py; the figures of docs/validation.md come from
there too."""
import math

import numpy as np

import sedov_exact
from crater_test import scratch
from scenario_blocks import AIR, box, material, write_scenario
from sph_profiles import binned_mean, frames, last_crossing, load_frame, run

GAMMA = 1.4
RHO0 = 1.0            # kg/m^3
ENERGY = 1.0          # J (3D) or J/m (2D): the whole blast; the model holds 1/2^D of it
SIDE = 1.0            # m, edge of the modelled quadrant / octant [0, SIDE]^D
R_LAST = 0.8 * SIDE   # m, exact shock radius at the last frame
FRAMES = 10           # frames at t_last/10, 2 t_last/10, ..., t_last: a decade in time
COUNTER = 1e-6        # ambient pressure / the blast zone's pressure
H_FACTOR = 1.3        # crater's default h / dx (the runs use the default SPH numerics)
WALLS = {2: ["left", "right", "bottom", "top"],
         3: ["left", "right", "bottom", "top", "back", "front"]}


def time_at_radius(radius, dim):
    """t at which the exact shock is at `radius`: R = xi0 (E t^2/rho0)^(1/(D+2)) inverted."""
    return (radius / sedov_exact.xi0(dim, GAMMA)) ** ((dim + 2) / 2.0) * math.sqrt(RHO0 / ENERGY)


def frame_times(dim):
    return [time_at_radius(R_LAST, dim) * k / FRAMES for k in range(1, FRAMES + 1)]


def zone_count(dim, r_zone):
    """Lattice sites (i + 1/2) dx, i >= 0, within r_zone (in dx) of the corner."""
    k = np.arange(int(math.ceil(r_zone)) + 1) + 0.5
    grids = np.meshgrid(*([k] * dim), indexing="ij")
    return int(np.count_nonzero(sum(g * g for g in grids) <= r_zone * r_zone))


def blast_pressure(dim, n, r_zone):
    """Zone pressure p_b that puts ENERGY / 2^D (the quadrant's or octant's share) into the
    zone's particles, each of volume dx^D, above the ambient p_0 = COUNTER p_b:
    (p_b - p_0) n_z dx^D / (gamma - 1) = ENERGY / 2^D."""
    volume = zone_count(dim, r_zone) * (SIDE / n) ** dim
    return (ENERGY / 2 ** dim) * (GAMMA - 1.0) / (volume * (1.0 - COUNTER))


def scenario(dim, n, r_zone, sph=None):
    """The corner blast: [0, SIDE]^D at rho0 and p_0 = COUNTER p_b, a zone of radius r_zone dx
    about the origin at p_b, mirror walls on every face, crater's default SPH numerics but for
    the keys of `sph` ([parts.sph])."""
    dx = SIDE / n
    t_last = time_at_radius(R_LAST, dim)
    p_b = blast_pressure(dim, n, r_zone)
    origin = [0.0] * dim
    shape = "disk" if dim == 2 else "sphere"
    corner = "quadrant" if dim == 2 else "octant"
    return {
        "scenario": {"name": f"sph-sedov-{dim}d", "dimension": dim, "end_time_s": t_last,
                     "description": f"Sedov-Taylor point blast in a {corner}, {n} particles "
                                    "per edge"},
        "output": {"interval_s": t_last / FRAMES, "history_every": 50},
        "domain": {"min_m": origin, "max_m": [SIDE] * dim},
        "materials": [material(AIR, name="gas", rho0_kg_m3=RHO0, gamma=GAMMA)],
        "parts": [{
            "name": "gas", "method": "sph", "material": "gas", "spacing_m": dx,
            "region": box(origin, [SIDE] * dim),
            "initial": {"density_kg_m3": RHO0, "pressure_pa": COUNTER * p_b},
            "sph": {"walls": WALLS[dim], "wall_slip": "free", **(sph or {})},
            "zones": [{"region": {"type": shape, "center_m": origin, "radius_m": r_zone * dx},
                       "pressure_pa": p_b}],
        }],
    }


# ---------------------------------------------------------------------------------------------
# Measurement
# ---------------------------------------------------------------------------------------------

def shell_edges(dx):
    """Shells of width dx about the origin, out to SIDE (whole inside the quadrant / octant)."""
    return np.arange(0.0, SIDE + 0.5 * dx, dx)


def radial_profile(r, density, dx):
    """(shell centres, mean density of the particles in each shell), empty shells left out."""
    edges = shell_edges(dx)
    means, counts = binned_mean(r, density, edges)
    centres = 0.5 * (edges[:-1] + edges[1:])
    good = counts > 0
    return centres[good], means[good]


def peak_position(rc, rho):
    """(radius, value) of the largest shell mean, the radius refined by the vertex of the
    parabola through it and its two neighbours."""
    k = int(np.argmax(rho))
    if 0 < k < len(rho) - 1:
        a, b, c = rho[k - 1], rho[k], rho[k + 1]
        den = a - 2 * b + c
        if den < 0:
            return float(rc[k] + 0.5 * (rc[k + 1] - rc[k]) * (a - c) / den), float(b)
    return float(rc[k]), float(rho[k])


def measure(rc, rho):
    """The shock's radius as the density peak's (the exact density is largest at the shock)
    and, for comparison, the outer crossing of (rho_max + rho0)/2."""
    r_peak, rho_max = peak_position(rc, rho)
    return r_peak, rho_max, last_crossing(rc, rho, 0.5 * (rho_max + RHO0))


def projected_kernel(dim, h, x):
    """The Wendland C2 kernel of dimension D integrated over the plane of a front (the
    smoothing that a plane shock sees across it, per unit length of x), at offsets x."""
    def w(q):
        alpha = 7.0 / (4 * math.pi) if dim == 2 else 21.0 / (16 * math.pi)
        q = np.minimum(q, 2.0)
        return alpha / h ** dim * (1 - q / 2) ** 4 * (2 * q + 1)
    s = np.linspace(0.0, 2.0 * h, 401)[:, None]  # distance within the plane
    q = np.sqrt(x[None, :] ** 2 + s ** 2) / h
    weight = 2.0 if dim == 2 else 2 * math.pi * s  # line: both sides; plane: rings
    return np.trapz(weight * w(q), s[:, 0], axis=0)


def smoothed_exact_profile(dim, t, energy, dx, h):
    """The exact density at time t smoothed across the front by the kernel (h), then averaged
    over the same shells as the particles: what a perfect SPH solution at this resolution can
    show at best. (The smoothing ignores the shells' curvature: R >> h.)"""
    step = dx / 40
    r = np.arange(0.0, SIDE + 3 * h, step)
    rho = sedov_exact.profile(r, t, energy, RHO0, dim, GAMMA)[0]
    x = np.arange(-2 * h, 2 * h + 0.5 * step, step)
    k = projected_kernel(dim, h, x)
    k /= k.sum()
    pad = len(x)
    smooth = np.convolve(np.pad(rho, pad, mode="edge"), k, mode="same")[pad:-pad]
    # Shell means weighted by the shells' measure r^(D-1).
    edges = shell_edges(dx)
    idx = np.searchsorted(edges, r, side="right") - 1
    ok = idx < len(edges) - 1
    wts = r[ok] ** (dim - 1)
    means = (np.bincount(idx[ok], weights=wts * smooth[ok], minlength=len(edges) - 1)
             / np.bincount(idx[ok], weights=wts, minlength=len(edges) - 1))
    return 0.5 * (edges[:-1] + edges[1:]), means


# ---------------------------------------------------------------------------------------------
# The run
# ---------------------------------------------------------------------------------------------

def run_case(dim, n, r_zone, tag, sph=None):
    """Runs the corner blast; returns a dict with one row per frame after t = 0 (t, exact R,
    the peak's radius and value, the half-height radius, the peak's error relative to R and in
    dx), the blast energy deposited (2^D x the model's, from the first frame), the summary and
    the wall time."""
    dx = SIDE / n
    d = scratch(f"sph_sedov_{tag}")
    path = write_scenario(d / "sedov.toml", scenario(dim, n, r_zone, sph),
                          comment=f"Sedov-Taylor point blast, {dim}D "
                                  "(tests/verification/sph_sedov)")
    summary, wall = run(path, d / "out")
    fr = frames(d / "out", "gas")
    f0 = load_frame(fr[0][1])
    p_0 = float(np.min(f0["pressure"]))
    # The blast: the internal energy above the ambient's specific energy (which the ambient
    # pressure and rho0 set; a summed density differs from rho0 by the lattice sum's bias).
    e_amb = float(np.min(f0["specific_energy"]))
    energy = 2 ** dim * float(np.sum(f0["mass"] * (f0["specific_energy"] - e_amb)))
    xi = sedov_exact.xi0(dim, GAMMA)
    rows, profiles = [], []
    for t, p in fr[1:]:
        f = load_frame(p)
        r = np.linalg.norm(f["x"], axis=1)
        rc, rho = radial_profile(r, f["density"], dx)
        r_peak, rho_max, r_half = measure(rc, rho)
        big_r = float(sedov_exact.shock_radius(t, energy, RHO0, dim, GAMMA, xi=xi))
        rows.append({"t": t, "R": big_r, "r_peak": r_peak, "rho_max": rho_max,
                     "r_half": r_half, "err": r_peak / big_r - 1.0,
                     "peak_dx": (r_peak - big_r) / dx, "half_err": r_half / big_r - 1.0,
                     "r_max": float(r.max())})
        profiles.append((t, rc, rho))
    return {"dim": dim, "n": n, "dx": dx, "r_zone": r_zone, "summary": summary,
            "wall_s": wall, "frame0": f0, "energy": energy, "p_0": p_0,
            "zone_count": zone_count(dim, r_zone), "rows": rows, "profiles": profiles}
