"""The command-line contract (DESIGN section 1): version, list, check, exit codes, run
directory protection, numerical failure (exit 3, part/entity/time named, last state written)."""
import json
import re
import sys
import unittest

from crater_test import SOURCE_DIR, crater, read_vtu, scratch
from scenario_blocks import (AIR, SAND, box, compose_scenario, domain, material, part,
                             scenario_text)


class Cli(unittest.TestCase):
    def test_version(self):
        p = crater("--version")
        self.assertRegex(p.stdout, r"^crater \d+\.\d+\.\d+")

    def test_list_names_bundled_scenarios(self):
        p = crater("list")
        self.assertIn("demo", p.stdout)
        bundled = sorted(f.stem for f in (SOURCE_DIR / "scenarios").glob("*.toml"))
        # One line per scenario; a scenario's levels on an indented line after it.
        listed = sorted(line.split()[0] for line in p.stdout.splitlines()
                        if line.strip() and not line[0].isspace())
        self.assertEqual(listed, bundled)

    def test_check_prints_counts_masses_and_steps(self):
        p = crater("check", "demo")
        self.assertRegex(p.stdout, r"charge\s+sph\s+\d+\s+[\d.]+\s+[\d.e+-]+")
        self.assertIn("global step", p.stdout)

    def test_bad_command_line_exits_2(self):
        self.assertEqual(crater("run", check=False).returncode, 2)
        self.assertEqual(crater("frobnicate", check=False).returncode, 2)
        self.assertEqual(crater("run", "demo", "--threads", "0", check=False).returncode, 2)
        p = crater("run", "no-such-scenario", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("no bundled scenario", p.stderr)

    def test_quiet_run_prints_nothing(self):
        # Issue 28's trap: --quiet still printed two info: lines.
        out = scratch("cli_quiet")
        p = crater("run", "demo", "--out", out, "--force", "--quiet", "--set",
                   "scenario.end_time_s=1e-5")
        self.assertEqual((p.stdout, p.stderr), ("", ""))
        # Warnings are still shown: here an output interval longer than the run.
        short = ["--set", "scenario.end_time_s=2e-6"]
        quiet = crater("run", "demo", "--out", out, "--force", "--quiet", *short)
        loud = crater("run", "demo", "--out", out, "--force", *short)
        self.assertIn("crater: info:", loud.stderr)
        warnings = [line for line in loud.stderr.splitlines() if "warning:" in line]
        self.assertTrue(warnings)
        self.assertEqual(quiet.stderr.splitlines(), warnings)

    def test_schema_plain_text_and_markdown(self):
        # Issue 28's trap: `schema` and `schema --markdown` printed the same.
        plain = crater("schema").stdout
        md = crater("schema", "--markdown").stdout
        self.assertNotEqual(plain, md)
        self.assertNotIn("| key |", plain)
        self.assertNotIn("`", plain)
        self.assertIn("| key |", md)
        # The same keys in both: every `name` of a Markdown row starts a plain line.
        md_keys = re.findall(r"^\| `([a-z0-9_]+)` \|", md, re.M)
        plain_keys = re.findall(r"^  ([a-z0-9_]+) ", plain, re.M)
        self.assertGreater(len(md_keys), 100)
        self.assertEqual(md_keys, plain_keys)
        self.assertEqual(md, (SOURCE_DIR / "docs" / "scenario-format.md").read_text())

    def test_make_run_builds_only_the_binary(self):
        # Issue 28: `make run` builds the binary, not the tests and benchmarks.
        import subprocess
        p = subprocess.run(["make", "-n", "-C", str(SOURCE_DIR), "run"], capture_output=True,
                           text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        builds = [line for line in p.stdout.splitlines() if "cmake --build" in line]
        self.assertEqual(len(builds), 1, p.stdout)
        self.assertIn("--target crater_cli", builds[0])

    def test_dem_part_without_grains_exits_2(self):
        # Fuzzing found it: a random packing whose first grain outweighs the region's solid
        # volume placed none, and the empty part failed in the cell grid (exit 1).
        scenario = scratch("cli_empty_dem") / "empty.toml"
        scenario.write_text(soil_box(random_packing=True, radius_max_m=1.0))
        p = crater("check", scenario, check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("key 'parts[soil].packing': no grain to place", p.stderr)
        # A lattice part whose every grain is carved away by another part's region.
        scenario.write_text(soil_box(random_packing=False, radius_max_m=0.004, carved=True))
        p = crater("check", scenario, check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("holds no grains", p.stderr)

    def test_run_directory_is_not_overwritten_without_force(self):
        out = scratch("cli_force")
        crater("run", "demo", "--out", out, "--quiet", "--set", "scenario.end_time_s=2e-6")
        before = (out / "summary.json").read_bytes()
        p = crater("run", "demo", "--out", out, "--quiet", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("--force", p.stderr)
        self.assertEqual((out / "summary.json").read_bytes(), before)
        crater("run", "demo", "--out", out, "--quiet", "--force", "--set",
               "scenario.end_time_s=2e-6")

    def test_particle_leaving_the_domain_exits_3_with_state(self):
        # The demo's charge in a domain barely larger than itself: products leave it.
        out = scratch("cli_unstable")
        p = crater("run", "demo", "--out", out, "--quiet", "--force",
                   "--set", "domain.min_m=[-0.12, -0.12]", "--set", "domain.max_m=[0.12, 0.12]",
                   check=False)
        self.assertEqual(p.returncode, 3, p.stderr)
        m = re.search(r"part 'charge', entity (\d+), t = ([0-9.e+-]+) s: particle left the domain",
                      p.stderr)
        self.assertIsNotNone(m, p.stderr)
        pts, arrays, _, t = read_vtu(out / "charge_failure.vtu")
        self.assertAlmostEqual(t, float(m.group(2)), delta=1e-12)
        self.assertIn(int(m.group(1)), arrays["id"].tolist())
        summary = json.loads((out / "summary.json").read_text())
        self.assertEqual(summary["status"], "failed")
        self.assertIn("left the domain", summary["message"])

    def test_fixed_step_that_becomes_unstable_exits_3(self):
        # Stable at t = 0 (so accepted), but the stable step falls as the products expand.
        out = scratch("cli_fixed_dt")
        p = crater("run", "demo", "--out", out, "--quiet", "--force",
                   "--set", "time.fixed_dt_s=4.7e-7", check=False)
        self.assertEqual(p.returncode, 3, p.stderr)
        self.assertRegex(p.stderr, r"numerical failure in part 'charge', entity \d+, t = "
                                   r"[0-9.e+-]+ s: the fixed time step 4.7e-07 s exceeds")
        self.assertTrue((out / "charge_failure.vtu").exists())


def soil_box(random_packing, radius_max_m, carved=False):
    """A 0.1 m box of sand grains ("soil", radii from 3 mm to radius_max_m), by random packing
    or on a lattice; with `carved`, a gas block ("block") covering it carves it away."""
    materials = [material(SAND, shear_modulus_pa=5e8, friction=0.5)]
    parts = [part("soil", "dem", "sand", 0.01, box([0.0, 0.0], [0.1, 0.1]),
                  carve=["block"] if carved else None,
                  dem={"radius_min_m": 0.003, "radius_max_m": radius_max_m},
                  packing={"method": "random", "porosity": 0.5} if random_packing else None)]
    if carved:
        materials.append(material(AIR, name="gas"))
        parts.append(part("block", "sph", "gas", 0.01, box([0.0, 0.0], [0.12, 0.12])))
    return scenario_text(compose_scenario("empty", 2, 1e-4, domain=domain([0.0, 0.0], [1.0, 1.0]),
                                          materials=materials, parts=parts))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
