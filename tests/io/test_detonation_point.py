"""A detonation point must lie in its charge's region (boundary included): one outside was
accepted (exit 0) and the charge lit only when the front, run through the empty space to it,
arrived. The loader now refuses it with exit 2, naming file, line and key."""
import re
import sys
import unittest

from crater_test import SOURCE_DIR, crater, scratch

DEMO = (SOURCE_DIR / "scenarios" / "demo.toml").read_text()
POINT = "point_m = [0.0, 0.0]"  # the demo's charge: a disk of radius 0.1 m about (0, 0)


def with_point(name, point):
    assert DEMO.count(POINT) == 1
    path = scratch("detonation_point") / f"{name}.toml"
    path.write_text(DEMO.replace(POINT, f"point_m = {point}"))
    return path


class DetonationPoint(unittest.TestCase):
    def test_point_outside_the_charge_exits_2(self):
        path = with_point("outside", "[0.3, 0.0]")
        p = crater("check", path, check=False)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        line = DEMO.splitlines().index(POINT) + 1
        self.assertIn(f"{path}:{line}:", p.stderr)
        self.assertIn("detonation[0].point_m", p.stderr)
        self.assertRegex(p.stderr, r"inside the charge's region .*; it is at \(0\.3, 0\)")
        self.assertEqual(crater("run", path, "--out", scratch("detonation_point_run"), "--quiet",
                                check=False).returncode, 2)

    def test_point_just_outside_the_charge_exits_2(self):
        p = crater("check", with_point("just_outside", "[0.101, 0.0]"), check=False)
        self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
        self.assertRegex(p.stderr, r"it is at \(0\.101, 0\), 0\.001 m outside")

    def test_points_inside_and_on_the_boundary_are_accepted(self):
        # On the circle, to the rounding of a decimal written to 8 digits.
        for name, point in [("inside", "[0.05, -0.02]"), ("boundary", "[0.1, 0.0]"),
                            ("boundary_rounded", "[0.07071068, 0.07071068]")]:
            p = crater("check", with_point(name, point), check=False)
            self.assertEqual(p.returncode, 0, f"{point}: {p.stderr}")
            self.assertTrue(p.stdout.rstrip().endswith("ok"))

    def test_bundled_scenarios_still_pass(self):
        # The rule is the loader's, and `crater list` loads every bundled scenario, marking one
        # the loader refuses "(invalid: <its error>)". (A full `crater check` of each, which lays
        # the 3D scenes' beds of 20,000 spheres for a minute or more, is
        # tests/io/test_memory_estimate.py's.)
        listing = crater("list").stdout
        names = [line.split()[0] for line in listing.splitlines()
                 if line.strip() and not line[0].isspace()]
        self.assertIn("demo", names)
        self.assertIn("paper-3d", names)
        self.assertNotIn("(invalid", listing)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
