# ctest-processors: 2
"""Absorbing (viscous) wall: a compression pulse runs down a chain of equal grains into the
right face of the domain, which is a rigid wall or an absorbing wall (`absorbing_walls`).

The chain: N grains of mass m (2D: per metre of depth) touching on a line, linear springs k
between them (`contact = "linear_spring"`, e = 1, no gravity). For waves long against the pitch
a = 2r it is a bar of wave speed c = a sqrt(k/m) and impedance (force per velocity)
Z = (m/a) c = sqrt(k m). A dashpot eta (force eta v) on the end reflects the particle velocity by

    R = v_reflected / v_incident = (Z - eta) / (Z + eta)

(force balance at the end: Z v_i - Z v_r = eta (v_i + v_r); the impedance mismatch of
Lysmer & Kuhlemeyer 1969 and of any text on waves in bars, e.g. Graff, Wave Motion in Elastic
Solids, 1975, ch. 2), so eta = Z absorbs the pulse, eta = 2 Z returns -1/3 of it and a rigid
end (eta -> infinity) all of it, R = -1 (each a compression travelling back). crater's
absorbing wall gives a grain eta = rho c_p A with A = 2r (2D) or (2r)^2 (3D); with the bed
density rho = m / a^D (the chain's mass over its column) and c_p = a sqrt(k/m) it is eta = Z
exactly. A rigid wall (the linear spring k against the face, e = 1) reflects the whole pulse.

The pulse: a right-going wave set up at t = 0, velocity V sin^2 over L = 30 grains and the
matching overlaps delta = v a / c, starting at grain 40 of a chain of 240. The field splits
into right- and left-going parts w = (v +- c eps) / 2 (eps = overlap / a at each grain); the
incident amplitude is max |w_right| when the pulse is half-way, the reflected one max |w_left|
when the incident pulse has wholly reached the wall and the reflection is back in the chain
(the split reads under 1 % of left-going motion before any reflection; checked).

Expectations, with tolerances: rigid wall R < -0.97; matched absorbing wall |R| < 0.05 in 2D
and 3D (the continuum value is 0; the last grain's full mass is an end mass the continuum
does not have, and the chain disperses the pulse: about 3 % for 30 grains); eta = 2 Z:
R = -1/3 within 0.03. The dashpots' work goes into damping_j: kinetic + contact energy +
damping_j stays within 1 % of the initial energy (dissipation is integrated as power x dt,
first order). Each run is also compared with the same chain integrated here (numpy velocity
Verlet, same step, the wall as crater defines it): within 0.005.

Two more cases: the chain model with a Kelvin-Voigt end (the wall's spring k in parallel with
the matched dashpot), the design crater rejects, reflects almost everything (R < -0.9); and a
2D bed settled under gravity on an absorbing floor rests on the held reactions: without them
the floor grains would sink at W / (n eta); with them, over the second half of the run (after
the readjustment of the restart), they sink on average at less than 10 % of that, for each of
three packings (seeds 1-3; measured 0.7-6 %). The floor has no static stiffness, so as the bed
above rearranges, a floor grain loaded beyond its held reaction creeps: the bed does not come
wholly to rest (docs/validation.md). The absorbing chain runs bit-identically on 1 and 2
threads.
"""
import csv
import math
import sys
import unittest

import numpy as np

from crater_test import assert_bit_identical_runs, read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (BEADS, box, compose_scenario, domain, material, output, part,
                             particle, scenario_text, vec)

R, KN, V = 0.005, 1.0e6, 0.01
RHO = BEADS["rho0_kg_m3"]
N, X0, L = 240, 40, 30  # grains, pulse start (grain index), pulse length (grains)
A = 2 * R  # pitch


def mass(dim):
    return RHO * (math.pi * R**2 if dim == 2 else 4.0 / 3.0 * math.pi * R**3)


def wave_speed(dim):
    return A * math.sqrt(KN / mass(dim))


def chain(dim):
    """Positions and velocities of a right-going sin^2 pulse (x along the chain)."""
    c = wave_speed(dim)
    v = np.zeros(N)
    s = (np.arange(N) - X0) / L
    inside = (s >= 0) & (s <= 1)
    v[inside] = V * np.sin(np.pi * s[inside]) ** 2
    # overlap of contact (i, i+1): the mean of its grains' v a / c; x_{i+1} = x_i + a - delta_i
    delta = 0.5 * (v[:-1] + v[1:]) * A / c
    # The last grain touches the right face: build the chain from there.
    x = np.zeros(N)
    x[-1] = N * A - R
    for i in range(N - 2, -1, -1):
        x[i] = x[i + 1] - (A - delta[i])
    return x, v


def scenario(dim, wall, density_factor=1.0):
    c = wave_speed(dim)
    tau = A / c  # a pitch per tau
    end = 2 * (N - X0 - L / 2) * tau  # incident centre half-way at end / 4, at the wall at end / 2
    dem = {"contact": "linear_spring", "normal_stiffness_n_m": KN}
    if wall == "rigid":
        dem.update(walls=["right"], wall_restitution=1.0)
    else:
        dem.update(absorbing_walls=["right"],
                   absorbing_wall_density_kg_m3=mass(dim) / A**dim * density_factor,
                   absorbing_wall_p_wave_speed_m_s=c)
    lo, hi = vec(dim, 0.0, -4 * R, -4 * R), vec(dim, N * A, 4 * R, 4 * R)
    x, v = chain(dim)
    return scenario_text(compose_scenario(
        f"absorbing-chain-{dim}d", dim, end, output=output(end / 4, history_every=10),
        domain=domain(lo, hi),
        materials=[material(BEADS, restitution=1.0)],
        parts=[part("chain", "dem", "beads", A, box(lo, hi), dem=dem,
                    particles=[particle(vec(dim, xi, 0.0), R, vec(dim, vi, 0.0))
                               for xi, vi in zip(x, v)])]))


def waves(path, dim):
    """(right-going, left-going) parts of the velocity field along the chain."""
    pts, arrays, _, _ = read_vtu(path)
    order = np.argsort(pts[:, 0])
    x = pts[order, 0]
    v = arrays["velocity"][order, 0]
    gap = np.diff(x)
    overlap = np.maximum(A - gap, 0.0)  # of contacts (i, i+1)
    eps = np.zeros(len(x))  # compressive strain at each grain: mean of its contacts
    eps[:-1] += 0.5 * overlap / A
    eps[1:] += 0.5 * overlap / A
    c = wave_speed(dim)
    return 0.5 * (v + c * eps), 0.5 * (v - c * eps)


def chain_model(dim, dt, end, wall_eta=None, wall_spring=None):
    """The same chain integrated here (velocity Verlet, step dt, to t = end): contact springs
    k, compression only; at the right face a dashpot eta and/or a spring acting while the last
    grain presses on it. Returns the reflection measured as run() measures it."""
    m, c = mass(dim), wave_speed(dim)
    x, v = chain(dim)
    wall = N * A

    def force(x, v):
        f = np.zeros(N)
        fc = KN * np.maximum(A - np.diff(x), 0.0)
        f[:-1] -= fc
        f[1:] += fc
        press = x[-1] + R - wall
        if press > 0:
            if wall_spring is not None:
                f[-1] -= wall_spring * press
            if wall_eta is not None:
                f[-1] -= max(wall_eta * v[-1], 0.0)
        return f

    def split():
        overlap = np.maximum(A - np.diff(x), 0.0)
        eps = np.zeros(N)
        eps[:-1] += 0.5 * overlap / A
        eps[1:] += 0.5 * overlap / A
        return 0.5 * (v + c * eps), 0.5 * (v - c * eps)

    f = force(x, v)
    steps = int(round(end / dt))
    incident = None
    for n in range(1, steps + 1):
        v += 0.5 * dt * f / m
        x += dt * v
        f = force(x, v)
        v += 0.5 * dt * f / m
        if n == steps // 4:
            incident = np.abs(split()[0]).max()
    left = split()[1]
    return left[np.argmax(np.abs(left))] / incident


def run(dim, wall, density_factor=1.0):
    d = scratch(f"dem_absorbing_{dim}d_{wall}_{density_factor}")
    (d / "case.toml").write_text(scenario(dim, wall, density_factor))
    summary = run_scenario(d / "case.toml", d / "out", threads=1)
    frames = read_pvd(d / "out" / "chain.pvd")
    right_mid, left_mid = waves(d / "out" / frames[1][1], dim)
    right_end, left_end = waves(d / "out" / frames[4][1], dim)
    incident = np.abs(right_mid).max()
    floor = np.abs(left_mid).max() / incident  # what the split reads before any reflection
    i = np.argmax(np.abs(left_end))
    reflected = left_end[i] / incident  # signed: < 0 a compression travelling back
    with open(d / "out" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    e0 = float(rows[0]["kinetic_j"]) + float(rows[0]["contact_j"])
    last = rows[-1]
    e_end = float(last["kinetic_j"]) + float(last["contact_j"])
    damping = float(last["damping_j"])
    print(f"{dim}D {wall} (density x {density_factor}): incident {incident:.4e} m/s "
          f"(V = {V}), reflected {reflected:+.4f} x incident (split floor {floor:.4f}); "
          f"energy left {e_end / e0:.4f}, "
          f"damping_j {damping / e0:.4f}, balance {(e_end + damping) / e0 - 1:+.2e}",
          file=sys.stderr)
    assert floor < 0.01, f"the left/right split reads {floor} before any reflection"
    dt = float(rows[1]["dt_s"])
    z = math.sqrt(KN * mass(dim))
    model = chain_model(dim, dt, float(last["time_s"]),
                        wall_spring=KN if wall == "rigid" else None,
                        wall_eta=None if wall == "rigid" else density_factor * z)
    print(f"  the same chain integrated by the test: reflected {model:+.4f}", file=sys.stderr)
    return summary, incident, reflected, model, e0, e_end, damping


class AbsorbingWall(unittest.TestCase):
    def test_rigid_wall_reflects(self):
        _, incident, reflected, model, e0, e_end, damping = run(2, "rigid")
        self.assertAlmostEqual(incident / V, 1.0, delta=0.03)
        self.assertLess(reflected, -0.97)
        self.assertAlmostEqual(reflected, model, delta=0.005)
        self.assertEqual(damping, 0.0)

    def check_matched(self, dim):
        summary, incident, reflected, model, e0, e_end, damping = run(dim, "absorbing")
        self.assertEqual(summary["status"], "completed")
        self.assertAlmostEqual(incident / V, 1.0, delta=0.03)
        self.assertLess(abs(reflected), 0.05)
        self.assertAlmostEqual(reflected, model, delta=0.005)
        self.assertLess(abs((e_end + damping) / e0 - 1), 0.01)
        self.assertGreater(damping / e0, 0.9)

    def test_matched_2d(self):
        self.check_matched(2)

    def test_matched_3d(self):
        self.check_matched(3)

    def test_twice_the_impedance(self):
        _, incident, reflected, model, e0, e_end, damping = run(2, "absorbing",
                                                                density_factor=2.0)
        self.assertAlmostEqual(reflected, -1.0 / 3.0, delta=0.03)
        self.assertAlmostEqual(reflected, model, delta=0.005)
        self.assertLess(abs((e_end + damping) / e0 - 1), 0.01)

    def test_bit_identical_on_1_and_2_threads(self):
        d = scratch("dem_absorbing_threads")
        (d / "case.toml").write_text(scenario(3, "absorbing", 1.5))
        assert_bit_identical_runs(d / "case.toml", d)

    def test_why_the_reaction_is_held(self):
        # Not crater: the chain model above with the wall's elastic spring k in parallel with
        # the matched dashpot (a Kelvin-Voigt wall), the design src/dem/laws/absorbing_wall.hpp
        # rejects. The spring holds the end for any pulse much longer than sqrt(m/k).
        z = math.sqrt(KN * mass(2))
        dt = 0.9 * 0.17 * math.sqrt(mass(2) / KN)
        end = 2 * (N - X0 - L / 2) * A / wave_speed(2)
        kv = chain_model(2, dt, end, wall_eta=z, wall_spring=KN)
        print(f"Kelvin-Voigt wall (spring k + dashpot sqrt(k m)): reflected {kv:+.4f}",
              file=sys.stderr)
        self.assertLess(kv, -0.9)

    def test_settled_bed_rests_on_absorbing_floor(self):
        # A bed settled under gravity with an absorbing floor (rigid while settling) rests on
        # the held reactions. The run starts from the saved packing without tangential
        # springs, so the bed readjusts (with a rigid floor too: 0.05 r on average) and the
        # floor, having no stiffness, follows it. Without the held reactions the floor grains
        # would sink at W / (n eta), about 40 mm/s here; the test measures their mean sinking
        # rate over the second half of the run. A single end-of-run speed is not a robust
        # measure: one grain of the creeping floor may be caught moving (up to 40 % of the
        # free rate in a frame, depending on the packing).
        for seed in (1, 2, 3):
            with self.subTest(seed=seed):
                d = scratch(f"dem_absorbing_bed_{seed}")
                (d / "case.toml").write_text(bed_scenario(d / "cache", seed))
                summary = run_scenario(d / "case.toml", d / "out", threads=1)
                self.assertEqual(summary["status"], "completed")
                frames = read_pvd(d / "out" / "bed.pvd")
                self.assertEqual([round(t, 6) for t, _ in frames], [0.0, 0.2, 0.4])
                # Grains are matched by id: a floor grain that creeps until its centre crosses
                # the face leaves the model (absorbing faces transmit), so a later frame may
                # hold fewer; the rate is measured on the grains of every frame.
                frame_heights, radius = [], {}
                for _, name in frames:
                    p, a, _, _ = read_vtu(d / "out" / name)
                    ids = a["id"].astype(np.int64)
                    frame_heights.append(dict(zip(ids, p[:, 1])))
                    radius.update(zip(ids, a["radius"]))
                kept = sorted(set.intersection(*(set(h) for h in frame_heights)))
                heights = [np.array([h[i] for i in kept]) for h in frame_heights]
                r = np.array([radius[i] for i in kept])
                left = len(frame_heights[0]) - len(kept)
                floor = heights[0] - r < 1e-3 * r  # grains touching the floor at t = 0
                rate = (heights[1] - heights[2])[floor].mean() / (frames[2][0] - frames[1][0])
                weight = summary["parts"][0]["mass_kg"] * 9.81
                eta = RHO * math.pi / 4 * wave_speed(2) * A  # the default bed impedance, roughly
                free = weight / (floor.sum() * eta)
                print(f"bed on an absorbing floor (seed {seed}): {floor.sum()} floor grains sink "
                      f"{(heights[0] - heights[2])[floor].mean() / R:.3f} r on average in "
                      f"{frames[-1][0]:.2g} s, in the second half at {rate:.1e} m/s = "
                      f"{rate / free:.3f} x W / (n eta) = {free:.1e} m/s; {left} grain(s) "
                      f"crept through the floor and left",
                      file=sys.stderr)
                self.assertGreater(floor.sum(), 10)
                self.assertLess(rate, 0.10 * free)

    def test_grain_through_the_face_leaves(self):
        # An absorbing face transmits: a grain whose centre crosses it leaves the model (with
        # or without domain.outflow = "remove"), its energy booked (left_domain_energy_j, in
        # eroded_j), instead of being put back against the bed. While it crosses the layer
        # 0 < gap < r the dashpot alone acts, m dv/dx = -eta, so it leaves at
        # V - eta r / m = V / 2 (exact for the continuous motion; the explicit dashpot is first
        # order in the step: about 50 steps over the layer here, tolerance 3 %), and the
        # dashpot took (3/8) m V^2 (damping_j).
        for dim in (2, 3):
            for outflow in (None, "remove"):
                with self.subTest(dim=dim, outflow=outflow):
                    d = scratch(f"dem_absorbing_through_{dim}d_{outflow}")
                    (d / "case.toml").write_text(through_scenario(dim, outflow))
                    summary = run_scenario(d / "case.toml", d / "out", threads=1)
                    self.assertEqual(summary["status"], "completed")
                    diag = summary["parts"][0]["diagnostics"]
                    self.assertEqual(summary["parts"][0]["count"], 1)
                    self.assertEqual(diag["left_domain_count"], 1)
                    m = mass(dim)
                    e0 = 0.5 * m * V_THROUGH**2
                    left = diag["left_domain_energy_j"]
                    damping = summary["energy"]["final"]["damping_j"]
                    print(f"{dim}D grain through an absorbing face (outflow {outflow}): leaves "
                          f"with {left / e0:.4f} of its energy (exact 0.25), dashpot "
                          f"{damping / e0:.4f} (0.75), balance "
                          f"{summary['energy']['balance_error']:.1e}", file=sys.stderr)
                    self.assertAlmostEqual(math.sqrt(left / e0), 0.5, delta=0.5 * 0.03)
                    self.assertAlmostEqual(damping / e0, 0.75, delta=0.75 * 0.03)
                    self.assertLess(abs(summary["energy"]["balance_error"]), 0.01)


    def test_face_is_open_above_the_ground(self):
        # The face is the ground beyond the model: it reaches up to the highest grain centre
        # that touched it at t = 0, and is open above. A grain shot at it above that height
        # leaves untouched, in free flight under gravity: with the crossing at t = 0.05 s (the
        # removal at the end of that step), it carries 0.5 m (V^2 + (g t)^2), within 1e-3 (a
        # step of 1e-4 s moves g t by 2e-3 of it). A dashpot would have taken 3/4 of its
        # energy (test_grain_through_the_face_leaves).
        for dim in (2, 3):
            with self.subTest(dim=dim):
                d = scratch(f"dem_absorbing_open_{dim}d")
                (d / "case.toml").write_text(open_face_scenario(dim))
                summary = run_scenario(d / "case.toml", d / "out", threads=1)
                self.assertEqual(summary["status"], "completed")
                diag = summary["parts"][0]["diagnostics"]
                self.assertEqual(diag["left_domain_count"], 1)
                t = 0.05 / V_THROUGH
                exact = 0.5 * mass(dim) * (V_THROUGH**2 + (9.81 * t) ** 2)
                left = diag["left_domain_energy_j"]
                print(f"{dim}D grain over the ground at an absorbing face: leaves with "
                      f"{left / exact:.5f} of free flight's energy", file=sys.stderr)
                self.assertAlmostEqual(left / exact, 1.0, delta=1e-3)


def open_face_scenario(dim):
    """Gravity down y; one grain at rest touching the right face (absorbing) at y = -0.05 m sets
    the face's top; one shot at the face from x = 0.15 m at y = 0, above that top."""
    lo, hi = vec(dim, 0.0, -0.1, -0.1), vec(dim, 0.2, 0.1, 0.1)
    return scenario_text(compose_scenario(
        f"absorbing-open-{dim}d", dim, 0.06, output=output(0.03),
        domain=domain(lo, hi, gravity=vec(dim, 0.0, -9.81)),
        materials=[material(BEADS, restitution=1.0)],
        parts=[part("grains", "dem", "beads", A, box(lo, hi),
                    dem={"contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "absorbing_walls": ["right"], "absorbing_wall_density_kg_m3": RHO,
                         "absorbing_wall_p_wave_speed_m_s":
                             0.5 * mass(dim) / (R * (A if dim == 2 else A * A)) / RHO},
                    particles=[particle(vec(dim, 0.2 - 0.999 * R, -0.05), R),
                               particle(vec(dim, 0.15, 0.0), R, vec(dim, V_THROUGH, 0.0))])]))


def through_scenario(dim, outflow):
    """One grain shot at the right face (absorbing, eta r / m = 1/2: it crosses at V / 2) and one
    at rest far from every face (the part keeps a grain)."""
    m = mass(dim)
    area = A if dim == 2 else A * A
    rho_c = 0.5 * m / (R * area)  # eta = rho c area = m / (2 r)
    lo, hi = vec(dim, 0.0, -0.1, -0.1), vec(dim, 0.2, 0.1, 0.1)
    return scenario_text(compose_scenario(
        f"absorbing-through-{dim}d", dim, 0.1, output=output(0.05, history_every=1),
        domain=domain(lo, hi, outflow=outflow),
        materials=[material(BEADS, restitution=1.0)],
        parts=[part("grains", "dem", "beads", A, box(lo, hi),
                    dem={"contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "absorbing_walls": ["right"], "absorbing_wall_density_kg_m3": RHO,
                         "absorbing_wall_p_wave_speed_m_s": rho_c / RHO},
                    particles=[particle(vec(dim, 0.15, 0.0), R, vec(dim, V_THROUGH, 0.0)),
                               particle(vec(dim, 0.05, 0.0), R)])]))


V_THROUGH = 1.0  # m/s


def bed_scenario(cache, seed):
    return scenario_text(compose_scenario(
        "absorbing-bed", 2, 0.4, output=output(0.2),
        domain=domain([0.0, 0.0], [0.2, 0.2], gravity=[0.0, -9.81]),
        materials=[BEADS],
        parts=[part("bed", "dem", "beads", A, box([0.0, 0.0], [0.2, 0.08]),
                    packing={"method": "random", "porosity": 0.2, "settle": True,
                             "cache_dir": cache},
                    dem={"seed": seed, "contact": "linear_spring", "normal_stiffness_n_m": KN,
                         "radius_min_m": 0.8 * R, "radius_max_m": R,
                         "walls": ["left", "right"], "absorbing_walls": ["bottom"]})]))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
