# ctest-timeout: 300
"""The same two-sphere Hertz-Mindlin collision in crater and in LIGGGHTS (issue 4, DEM: "the
same collision run in LIGGGHTS gives the same force-time curve within 1 %").

Reference: LIGGGHTS-PUBLIC 3.8.0 (Debian 12 package `liggghts`), `pair_style gran model hertz
tangential history`, deck bench/peers/liggghts_hertz_pair/in.hertz_pair; its curves are checked
in as tests/data/liggghts_hertz_pair_3d.csv (regenerate: bench/peers/liggghts_hertz_pair/run.sh),
so this test needs no LIGGGHTS; where `liggghts` is installed it also reruns the deck and checks
the CSV is still what LIGGGHTS gives.

Scene (both codes): two equal sand grains, R = 2.5 mm, rho = 1920 kg/m^3, G = 29 GPa, nu = 0.2
(E = 69.6 GPa), friction 0.84, restitution 0.5, no gravity, surfaces 1e-6 m apart at t = 0,
approaching along x at 1 m/s relative (each +-0.5 m/s); fixed step dt = 1e-8 s in both codes
(0.45 % of the Rayleigh step 2.2227e-6 s; ~1600 steps per contact), both velocity Verlet
(kick-drift-kick) with the force evaluated at the half-kicked velocity. The force on grain 1 (the
one at -x) is compared every 10 steps (1e-7 s): crater's per-grain `force` (the total force; no
gravity, so the contact force) from the VTU frames (VTK's reader), LIGGGHTS' per-atom f.
  fn = F1 . n (n = (x1 - x2)/|x1 - x2|, > 0 repulsive),  ft = F1 . t (t = (n_y, -n_x, 0))
Contact duration: from the zero crossings of the overlap R1 + R2 - |x1 - x2| (linear
interpolation between rows).

Tolerances (issue 4): max_t |fn_crater - fn_LIGGGHTS| / max fn_LIGGGHTS <= 1 %; peak force and
contact duration each within 1 %.
  head_on  (vt = 0): measured (2026-11-22) curve 4e-8 %, peak 4e-8 %, duration 3e-11 %: the
           normal law (Hertz 4/3 E* sqrt(R*) d^3/2, Tsuji dashpot 2 sqrt(5/6) zeta sqrt(S_n m*),
           E* = E / (2 (1 - nu^2)) for equal spheres) and the integrator are LIGGGHTS' to
           round-off.
  oblique  (vt = 1 m/s relative along y, 45 deg): fn curve and peak 6e-4 %, duration 1e-4 %.
The oblique tangential force does NOT agree within 1 % (8.2 % of max |ft|), by design of crater's
friction rule (src/dem/laws/tangential_history.hpp), which departs from LIGGGHTS' in two ways:
  1. LIGGGHTS tests only the spring |k_t xi| against mu |F_n| and adds the dashpot on top while
     sticking, so its |F_t| exceeds mu F_n (here in the initial sliding phase, t = 1.1-2.5 us,
     15 rows; e.g. 4.64 N against mu F_n = 4.20 N at 1.6 us); crater caps the total at
     mu max(F_n, 0). The spring histories then differ for the rest of the contact.
     Alone: 6.6 % of max |ft|.
  2. LIGGGHTS' limit is mu |F_n|, so friction keeps acting while the Tsuji dashpot pulls
     (F_n < 0 over the last 18 % of the contact, 27 rows); crater's is mu max(F_n, 0): no
     friction then. Alone: 8.2 % (LIGGGHTS up to 0.57 N while crater gives 0).
(LIGGGHTS projects xi + v_t dt onto the tangent plane, crater rotates xi first, keeping its
length: no visible difference here.) test_oblique_tangential_vs_liggghts states the 1 %
criterion and is an expected failure; test_oblique_tangential_cause pins the cause: a 60-line
two-sphere replica of the scene reproduces LIGGGHTS' curve to 7e-9 % of max |ft| with LIGGGHTS'
friction rule and crater's curve to 2e-12 % with crater's rule (both checked at 1 %), so the two
codes differ only by that rule.
"""
import csv
import math
import os
import shutil
import subprocess
import sys
import unittest

import numpy as np

from crater_test import SOURCE_DIR, read_pvd, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, material, output, part,
                             particle, scenario_text)

R, MU, E_REST = 2.5e-3, 0.84, 0.5
RHO, G, NU = SAND["rho0_kg_m3"], SAND["shear_modulus_pa"], SAND["poisson_ratio"]
VN, GAP, DT, STEPS, EVERY = 1.0, 1.0e-6, 1.0e-8, 1750, 10
CSV = SOURCE_DIR / "tests" / "data" / "liggghts_hertz_pair_3d.csv"
TOL = 0.01
VT = {"head_on": 0.0, "oblique": 1.0}


def scenario(vt):
    c = R + GAP / 2
    return scenario_text(compose_scenario(
        "liggghts-hertz-pair", 3, STEPS * DT, time={"fixed_dt_s": DT},
        output=output(EVERY * DT, history_every=100),
        domain=domain([-0.02, -0.02, -0.02], [0.02, 0.02, 0.02]),
        materials=[material(SAND, friction=MU, restitution=E_REST)],
        parts=[part("grains", "dem", "sand", 0.005,
                    box([-0.01, -0.005, -0.005], [0.01, 0.005, 0.005]),
                    particles=[particle([-c, 0.0, 0.0], R, [VN / 2, -vt / 2, 0.0]),
                               particle([c, 0.0, 0.0], R, [-VN / 2, vt / 2, 0.0])])]))


def read_liggghts(path=CSV):
    """{case: {step: (fn, ft, overlap)}} from the checked-in CSV."""
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    out = {}
    for r in rows:
        out.setdefault(r["case"], {})[int(r["step"])] = tuple(
            float(r[k]) for k in ("fn_N", "ft_N", "overlap_m"))
    return out


def pair_state(points, radius, force):
    """(fn, ft, overlap) of grain 1 (the one at lower x) from one frame."""
    i1 = int(np.argmin(points[:, 0]))
    i2 = 1 - i1
    d = points[i1] - points[i2]
    dist = float(np.linalg.norm(d))
    n = d / dist
    t = np.array([n[1], -n[0], 0.0])
    return float(force[i1] @ n), float(force[i1] @ t), float(radius[i1] + radius[i2] - dist)


_CRATER = {}


def run_crater(case):
    """{step: (fn, ft, overlap)} of crater's run of the case, read from the VTU frames."""
    if case not in _CRATER:
        d = scratch(f"dem_liggghts_{case}")
        path = d / "case.toml"
        path.write_text(scenario(VT[case]))
        summary = run_scenario(path, d / "out", threads=1)
        assert summary["status"] == "completed", summary
        out = {}
        for t, f in read_pvd(d / "out" / "grains.pvd"):
            pts, arrays, _, _ = read_vtu(d / "out" / f)
            step = round(t / DT)
            assert abs(t - step * DT) < 1e-3 * DT, (t, step)
            out[step] = pair_state(pts, arrays["radius"], arrays["force"])
        _CRATER[case] = out
    return _CRATER[case]


def contact_duration(steps, overlap):
    """Time between the overlap's zero crossings (linear interpolation between rows)."""
    inside = np.flatnonzero(overlap > 0)
    i, j = inside[0], inside[-1]

    def crossing(a, b):
        return (steps[a] + (steps[b] - steps[a]) * overlap[a] / (overlap[a] - overlap[b])) * DT

    return crossing(j, j + 1) - crossing(i - 1, i)


def curves(case):
    """Common steps and the (N, 3) arrays of (fn, ft, overlap): LIGGGHTS, crater."""
    lig = read_liggghts()[case]
    cra = run_crater(case)
    steps = np.array(sorted(set(lig) & set(cra)))
    return steps, np.array([lig[s] for s in steps]), np.array([cra[s] for s in steps])


def two_sphere_replica(vt, liggghts_rule):
    """Both codes' scheme for this scene in a few lines: velocity Verlet with the force at the
    half-kicked velocity, Hertz normal force with the Tsuji dashpot, Mindlin history spring, lever
    arms R - d/2; only the friction rule is switchable (see the docstring). Returns
    {step: (fn, ft)} every EVERY steps."""
    e = 2 * G * (1 + NU)
    e_eff, g_eff = e / (2 * (1 - NU**2)), e / (4 * (2 - NU) * (1 + NU))
    m = RHO * 4 / 3 * math.pi * R**3
    inertia, m_eff, r_eff = 0.4 * m * R * R, m / 2, R / 2
    log_e = math.log(E_REST)
    damp = 2 * math.sqrt(5 / 6) * (-log_e / math.sqrt(math.pi**2 + log_e**2))
    x = [np.array([-(R + GAP / 2), 0.0, 0.0]), np.array([R + GAP / 2, 0.0, 0.0])]
    v = [np.array([VN / 2, -vt / 2, 0.0]), np.array([-VN / 2, vt / 2, 0.0])]
    w = [np.zeros(3), np.zeros(3)]
    f, tq = [np.zeros(3)] * 2, [np.zeros(3)] * 2
    xi = np.zeros(3)
    out = {0: (0.0, 0.0)}
    for step in range(1, STEPS + 1):
        for i in range(2):
            v[i] = v[i] + 0.5 * DT / m * f[i]
            w[i] = w[i] + 0.5 * DT / inertia * tq[i]
            x[i] = x[i] + DT * v[i]
        d = x[0] - x[1]
        n = d / np.linalg.norm(d)
        overlap = 2 * R - np.linalg.norm(d)
        if overlap > 0:
            arm = R - overlap / 2
            vrel = v[0] - v[1] - np.cross(w[0], arm * n) - np.cross(w[1], arm * n)
            vn = vrel @ n
            vtan = vrel - vn * n
            root = math.sqrt(r_eff * overlap)
            s_n, s_t = 2 * e_eff * root, 8 * g_eff * root
            fn = 4 / 3 * e_eff * root * overlap - damp * math.sqrt(s_n * m_eff) * vn
            if liggghts_rule:  # add, then project onto the tangent plane
                trial = xi + vtan * DT
                trial = trial - (trial @ n) * n
                limit = MU * abs(fn)
            else:  # rotate into the tangent plane keeping the length, then add
                p = xi - (xi @ n) * n
                p = p * (np.linalg.norm(xi) / np.linalg.norm(p)) if np.linalg.norm(p) > 0 else p
                trial = p + vtan * DT
                limit = MU * max(fn, 0.0)
            spring = -s_t * trial
            if np.linalg.norm(spring) > limit:
                xi = trial * (limit / np.linalg.norm(spring))
                ft = spring * (limit / np.linalg.norm(spring))
            else:
                xi = trial
                ft = spring - damp * math.sqrt(s_t * m_eff) * vtan
                if not liggghts_rule and np.linalg.norm(ft) > limit:
                    ft = ft * (limit / np.linalg.norm(ft))
            f1 = fn * n + ft
            f = [f1, -f1]
            tq = [np.cross(-arm * n, ft), np.cross(arm * n, -ft)]
        else:
            xi = np.zeros(3)
            f, tq = [np.zeros(3)] * 2, [np.zeros(3)] * 2
        for i in range(2):
            v[i] = v[i] + 0.5 * DT / m * f[i]
            w[i] = w[i] + 0.5 * DT / inertia * tq[i]
        if step % EVERY == 0:
            t = np.array([n[1], -n[0], 0.0])
            out[step] = (float(f[0] @ n), float(f[0] @ t))
    return out


class LiggghtsForceTime(unittest.TestCase):
    def check_normal(self, case):
        steps, lig, cra = curves(case)
        self.assertGreater(len(steps), 170, "frames missing")
        peak_l, peak_c = lig[:, 0].max(), cra[:, 0].max()
        curve = np.abs(cra[:, 0] - lig[:, 0]).max() / peak_l
        tc_l, tc_c = contact_duration(steps, lig[:, 2]), contact_duration(steps, cra[:, 2])
        print(f"{case}: fn peak crater {peak_c:.6f} N, LIGGGHTS {peak_l:.6f} N "
              f"({100 * (peak_c / peak_l - 1):+.2e} %); contact crater {tc_c:.6e} s, LIGGGHTS "
              f"{tc_l:.6e} s ({100 * (tc_c / tc_l - 1):+.2e} %); max |dfn| / max fn = "
              f"{100 * curve:.2e} %", file=sys.stderr)
        self.assertLessEqual(curve, TOL)
        self.assertLessEqual(abs(peak_c / peak_l - 1), TOL)
        self.assertLessEqual(abs(tc_c / tc_l - 1), TOL)
        return steps, lig, cra

    def test_head_on(self):
        _, lig, cra = self.check_normal("head_on")
        self.assertEqual(np.abs(lig[:, 1]).max(), 0.0)
        self.assertLess(np.abs(cra[:, 1]).max(), 1e-9 * lig[:, 0].max())

    def test_oblique_normal(self):
        self.check_normal("oblique")

    @unittest.expectedFailure
    def test_oblique_tangential_vs_liggghts(self):
        """The 1 % criterion on ft: fails by design (8.2 %), see the docstring."""
        _, lig, cra = curves("oblique")
        err = np.abs(cra[:, 1] - lig[:, 1]).max() / np.abs(lig[:, 1]).max()
        print(f"oblique: max |dft| / max |ft| = {100 * err:.2f} % (crater's friction rule)",
              file=sys.stderr)
        self.assertLessEqual(err, TOL)

    def test_oblique_tangential_cause(self):
        """Crater and LIGGGHTS differ in ft only by the friction rule."""
        steps, lig, cra = curves("oblique")
        scale = np.abs(lig[:, 1]).max()
        for rule, ref, name in ((True, lig, "LIGGGHTS"), (False, cra, "crater")):
            rep = two_sphere_replica(VT["oblique"], liggghts_rule=rule)
            ft = np.array([rep[s][1] for s in steps])
            err = np.abs(ft - ref[:, 1]).max() / scale
            print(f"oblique: replica with {name}'s friction rule vs {name}: max |dft| / max |ft| "
                  f"= {100 * err:.2e} %", file=sys.stderr)
            self.assertLessEqual(err, TOL)
        # The rows where LIGGGHTS' ft breaks crater's bound |ft| <= mu max(fn, 0).
        over = np.abs(lig[:, 1]) > MU * np.maximum(lig[:, 0], 0) * (1 + 1e-9)
        print(f"oblique: LIGGGHTS |ft| > mu max(fn, 0) in {over.sum()} of "
              f"{(lig[:, 2] > 0).sum()} contact rows", file=sys.stderr)
        self.assertTrue(np.all(np.abs(cra[:, 1]) <= MU * np.maximum(cra[:, 0], 0) * (1 + 1e-9)
                               + 1e-12))

    def test_reference_reproduces(self):
        """Where LIGGGHTS is installed: the deck still gives the checked-in CSV."""
        if shutil.which("liggghts") is None and shutil.which("lmp_auto") is None:
            self.skipTest("liggghts not installed (the checked-in CSV is used)")
        d = scratch("dem_liggghts_rerun")
        subprocess.run([str(SOURCE_DIR / "bench" / "peers" / "liggghts_hertz_pair" / "run.sh"),
                        str(d / "rerun.csv")], check=True, capture_output=True, timeout=120,
                       env=os.environ)
        new, old = read_liggghts(d / "rerun.csv"), read_liggghts()
        for case in old:
            self.assertEqual(sorted(new[case]), sorted(old[case]))
            a = np.array([new[case][s] for s in sorted(old[case])])
            b = np.array([old[case][s] for s in sorted(old[case])])
            self.assertLess(np.abs(a[:, :2] - b[:, :2]).max(), 1e-6 * np.abs(b[:, 0]).max())


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
