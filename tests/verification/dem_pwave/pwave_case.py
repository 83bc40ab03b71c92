"""The P-wave speed of a dense settled bed of the paper's sand, from a pulse (issue 24).

A column of the paper-20cm demo bed's grains (radii 8-20 mm, the paper's 2.5:1 spread; sand:
rho 1920 kg/m^3, G 29 GPa, nu 0.2, friction 0.84; Hertz-Mindlin, 2D disks as rows of spheres)
1 m wide and 2 m deep, laid dense and settled under gravity between frictionless rigid walls
(so the vertical stress is the overburden rho_b g z, no silo effect). At t = 0 the grains of the
top 6 cm move down at 5 mm/s: a compression pulse (stress rho_b c v ~ 1.6 kPa, small beside the
overburden below 0.2 m) runs down the column. Its front reaches depth z at t(z), the first
frame in which the grains between z - 5 cm and z + 5 cm move down at half their band's peak
speed; c_p is the slope of z against t(z) (least squares over 0.3-1.7 m). Run by
test_bed_p_wave.py (seed 1) and test_bed_p_wave_seeds_slow.py (seeds 1-3); `python3
pwave_case.py SEED...` prints the speeds.

`scale` (default 1) multiplies every length (grains, column, pulse, bands, depths) and time
(frames, duration) by lam and divides gravity by lam: the same case, similar in every term
(the stress at a depth lam z is the stress at z), with grains lam times as large
(tests/verification/dem_grain_size)."""
import sys

import numpy as np

from crater_test import crater, read_pvd, read_vtu, scratch
from scenario_blocks import SAND, box, compose_scenario, domain, output, part, write_scenario

WIDTH_M, DEPTH_M = 1.0, 2.0
PULSE_M, PULSE_SPEED_M_S = 0.06, 0.005
BAND_M = 0.05
FIT_M = (0.3, 1.7)
FRAME_S = 1e-4


def scenario(seed, cache, local_damping=0.157, end_time_s=0.016, scale=1.0):
    s = scale
    packing = {"method": "dense", "settle": True, "cache_dir": str(cache)}
    if s != 1.0:  # settling lasts s times longer (settle_max_time_s: 2 s by default)
        packing["settle_max_time_s"] = 2.0 * s
    return compose_scenario(
        f"p-wave-{seed}", 2, end_time_s * s,
        domain=domain([0.0, -DEPTH_M * s], [WIDTH_M * s, 1.0 * s], [0.0, -9.81 / s]),
        time={"safety_factor": 0.5}, output=output(FRAME_S * s, 1000), materials=[SAND],
        parts=[part("soil", "dem", "sand", 0.04 * s, box([0.0, -DEPTH_M * s], [WIDTH_M * s, 0.0]),
                    dem={"radius_min_m": 0.008 * s, "radius_max_m": 0.02 * s, "seed": seed,
                         "hertz_2d": "row_of_spheres", "local_damping": local_damping,
                         "walls": ["left", "right", "bottom"], "wall_friction": 0.0},
                    packing=packing,
                    zones=[{"region": box([0.0, -PULSE_M * s], [WIDTH_M * s, 0.5 * s]),
                            "velocity_m_s": [0.0, -PULSE_SPEED_M_S]}])])


def arrival_times(out, scale=1.0):
    """Per depth (band centres 0.2-1.8 m below the bed's top, x scale): the front's arrival
    [s]."""
    frames = [(t, read_vtu(out / f)) for t, f in read_pvd(out / "soil.pvd")]
    pts0 = frames[0][1][0]
    top = pts0[:, 1].max()
    depths = np.arange(0.2, 1.81, 0.1) * scale
    bands = [np.abs((top - pts0[:, 1]) - z) < BAND_M * scale for z in depths]
    down = np.array([[-(f[1]["velocity"][b, 1]).mean() for b in bands] for _, f in frames])
    times = np.array([t for t, _ in frames])
    arrive = []
    for j in range(len(depths)):
        peak = down[:, j].max()
        k = int(np.argmax(down[:, j] >= 0.5 * peak))
        # Linear interpolation between the frames around the crossing.
        if k > 0:
            a, b = down[k - 1, j], down[k, j]
            arrive.append(times[k - 1] + (0.5 * peak - a) / (b - a) * (times[k] - times[k - 1]))
        else:
            arrive.append(times[k])
    return depths, np.array(arrive), down.max(axis=0)


def p_wave_speed(depths, arrive, scale=1.0):
    lo, hi = FIT_M[0] * scale - 1e-9 * scale, FIT_M[1] * scale + 1e-9 * scale
    keep = (depths >= lo) & (depths <= hi)
    slope = np.polyfit(arrive[keep], depths[keep], 1)[0]
    return slope


def run_seed(seed, work, **kw):
    case = write_scenario(work / f"seed{seed}.toml", scenario(seed, work / "cache", **kw))
    out = work / f"seed{seed}"
    crater("run", case, "--out", out, "--force", "--quiet")
    scale = kw.get("scale", 1.0)
    depths, arrive, peaks = arrival_times(out, scale)
    return p_wave_speed(depths, arrive, scale), depths, arrive, peaks


if __name__ == "__main__":
    work = scratch("p_wave_case")
    for s in [int(a) for a in sys.argv[1:]] or [1]:
        c, depths, arrive, peaks = run_seed(s, work)
        print(f"seed {s}: c_p = {c:.1f} m/s")
        for z, t, p in zip(depths, arrive, peaks):
            print(f"  z {z:.2f} m  t {t * 1e3:.3f} ms  peak {p * 1e3:.3f} mm/s")
