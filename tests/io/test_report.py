# ctest-cost: 36
"""`crater report DIR`: figures and report.md for a run directory (tools/report/crater_report.py,
embedded in the binary). A small charge + plate + grains scene and the demo are run and
reported; every figure report.md links must exist and be a real picture (a PNG over 200 px
each way that is not one flat colour); the optional figures appear when history.csv and
surface_profile.csv hold their columns; a failed run is reported with its state at failure;
bad input exits 2 with one line and no Python traceback; a missing interpreter or module
exits 1 naming the Debian packages."""
import csv
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import unittest

import numpy as np

from crater_test import BIN, SOURCE_DIR, crater, run_scenario, scratch
from scenario_blocks import (SAND, STEEL_JC, STEEL_JC_DAMAGE, TNT, box, compose_scenario, contact,
                             disk, domain, material, output, part, scenario_text)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def linked_pngs(report_md):
    """The PNG files report.md links, in order."""
    return re.findall(r"!\[[^\]]*\]\(([^)\s]+\.png)\)", report_md.read_text())


def png_size(path):
    """(width, height) from the IHDR chunk, which follows the signature."""
    data = path.read_bytes()[:24]
    if data[:8] != PNG_SIGNATURE or data[12:16] != b"IHDR":
        raise AssertionError(f"{path} is not a PNG file")
    return struct.unpack(">II", data[16:24])


def report(*args, env=None):
    """Runs `crater report`; returns the CompletedProcess (no check: callers test the code)."""
    return subprocess.run([BIN, "report", *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=env)


class Report(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("report")
        scenario = cls.work / "scene.toml"
        scenario.write_text(SCENE)
        cls.scene = cls.work / "scene"
        cls.scene_summary = run_scenario(scenario, cls.scene)
        cls.demo = cls.work / "demo"
        run_scenario("demo", cls.demo)

    def assert_valid_report(self, out_dir, expected):
        """report.md links exactly the PNGs written, each of them a sensible picture, and the
        expected ones among them. Returns report.md's text."""
        md = out_dir / "report.md"
        self.assertTrue(md.is_file(), f"no {md}")
        links = linked_pngs(md)
        self.assertTrue(set(expected) <= set(links), f"{expected} not all in {links}")
        self.assertEqual(sorted(links), sorted(p.name for p in out_dir.glob("*.png")),
                         "report.md links every PNG written, and only those")
        import matplotlib.image
        for name in links:
            with self.subTest(png=name):
                path = out_dir / name
                self.assertTrue(path.is_file(), f"{path} linked but missing")
                w, h = png_size(path)
                self.assertGreater(w, 200)
                self.assertGreater(h, 200)
                self.assertLess(path.stat().st_size, 600_000, "PNGs stay small")
                pixels = matplotlib.image.imread(str(path))
                self.assertGreater(float(np.std(pixels)), 0.0, "not a single flat colour")
        return md.read_text()

    def test_multi_part_run(self):
        p = report(self.scene)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        text = self.assert_valid_report(self.scene / "report", [
            "snapshots_parts.png", "snapshots_velocity.png", "snapshots_pressure.png",
            "snapshots_von_mises.png", "energy.png"])
        self.assertIn("report-small", text)
        self.assertIn("completed", text)
        for p in self.scene_summary["parts"]:
            self.assertRegex(text, rf"\| {p['name']} \| {p['method']} \| {p['count']} \|")
        # where the time went: the loop and each part's stage as summary.json has them; no
        # table of ranks on one rank
        run = self.scene_summary["run"]
        self.assertIn(f"The time loop took {run['loop_time_s']:.4g} s", text)
        for name, t in run["time_by_part_s"]["parts"].items():
            self.assertIn(f"| part `{name}` | {t:.3g} |", text)
        self.assertNotIn("Each rank's stages", text)
        # default snapshots: four output times spread over the run, the first and last included
        self.assertIn("Snapshots at 0 ms, 0.05 ms, 0.15 ms, 0.2 ms;", text)
        # a 2D run gets none of the 3D maps: its file list is what it was before them, with the
        # damage snapshots of its plate (Johnson-Cook damage)
        self.assertEqual(sorted(p.name for p in (self.scene / "report").iterdir()), [
            "energy.png", "report.md", "snapshots_damage.png", "snapshots_parts.png",
            "snapshots_pressure.png", "snapshots_velocity.png", "snapshots_von_mises.png"])

    def test_times_and_out(self):
        out = self.work / "elsewhere"
        p = report(self.scene, "--out", out, "--times", "0.00011,1")
        self.assertEqual(p.returncode, 0, p.stderr)
        text = self.assert_valid_report(out, ["snapshots_velocity.png"])
        self.assertIn("Snapshots at 0.1 ms, 0.2 ms;", text)  # the frames nearest

    def test_sph_only_demo(self):
        p = report(self.demo)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assert_valid_report(self.demo / "report", [
            "snapshots_velocity.png", "snapshots_pressure.png", "energy.png"])
        self.assertFalse((self.demo / "report" / "snapshots_von_mises.png").exists(),
                         "no FEM part, no von Mises figure")

    def test_optional_histories_and_metrics(self):
        # The plate's peak stress per history row, the ground surface at the end and metrics
        # in summary.json: added to a copy of the scene's run.
        run = self.work / "with_profiles"
        if run.exists():
            shutil.rmtree(run)
        shutil.copytree(self.scene, run, ignore=shutil.ignore_patterns("report"))
        with open(self.scene / "history.csv") as f:
            rows = list(csv.reader(f))
        # and a tunnel lining's gauges (probes.lining, lining_soil) with its crown line
        rows[0] += ["plate_max_von_mises_pa", "lining_crown_radial_m",
                    "lining_springline_radial_m", "soil_crown_line_interface_up_m"]
        for i, row in enumerate(rows[1:]):
            row += [str(1e6 * i), str(1e-3 * i), str(1.2e-3 * i), str(0.8e-3 * i)]
        with open(run / "history.csv", "w", newline="") as f:
            csv.writer(f).writerows(rows)
        with open(run / "crown_line.csv", "w") as f:
            f.write("node,z_m,depth_m,above_crown_m,up_displacement_max_m,"
                    "up_displacement_min_m,up_displacement_m\n")
            for k, h in enumerate((0.35, 1.0, 3.0, 10.35)):
                f.write(f"{k},{3.4 + h},{10.35 - h},{h},{0.02 / (1 + h)},0,{0.01 / (1 + h)}\n")
        x = np.linspace(0.0, 1.0, 41)
        with open(run / "surface_profile.csv", "w") as f:
            f.write("x_m,vertical_displacement_m\n")
            for xi in x:
                f.write(f"{xi},{-0.01 * np.exp(-((xi - 0.35) / 0.2) ** 2)}\n")
        summary = json.loads((run / "summary.json").read_text())
        summary["metrics"] = {"plate_peak_von_mises_pa": 2.5e8, "crater_depth_m": 0.12,
                              "plate_eroded_elements": 3, "plate_perforated": False}
        (run / "summary.json").write_text(json.dumps(summary))
        p = report(run)
        self.assertEqual(p.returncode, 0, p.stderr)
        text = self.assert_valid_report(run / "report", [
            "von_mises_history.png", "surface_profile.png", "lining.png"])
        self.assertRegex(text, r"\| `plate_peak_von_mises_pa` \| 2\.5e\+08 .*\| Pa \|")
        self.assertRegex(text, r"\| `crater_depth_m` \| 0\.12 \| m \|")
        self.assertRegex(text, r"\| `plate_perforated` \| no \|")

    def test_failed_run(self):
        # The demo's charge in a domain barely larger than itself: a particle leaves (exit 3).
        run = self.work / "failed"
        p = crater("run", "demo", "--out", run, "--quiet", "--force",
                   "--set", "domain.min_m=[-0.12, -0.12]", "--set", "domain.max_m=[0.12, 0.12]",
                   check=False)
        self.assertEqual(p.returncode, 3, p.stderr)
        p = report(run)
        self.assertEqual(p.returncode, 0, p.stderr)
        text = self.assert_valid_report(run / "report", ["snapshots_velocity.png"])
        self.assertIn("**failed**", text)
        self.assertIn("left the domain", text)
        self.assertIn("charge_failure.vtu", text)

    def test_bad_input_exits_2_without_traceback(self):
        empty = scratch("report_empty")
        no_frames = scratch("report_no_frames")
        (no_frames / "summary.json").write_text('{"status": "completed", "parts": []}')
        bad_json = scratch("report_bad_json")
        (bad_json / "summary.json").write_text("{ not json")
        cases = [
            ([self.work / "no-such-dir"], "no such run directory"),
            ([self.scene / "summary.json"], "not a directory"),
            ([empty], "no summary.json"),
            ([no_frames], "no <part>.pvd"),
            ([bad_json], "not readable as JSON"),
            ([self.scene, "--times", "0.1,soon"], "--times"),
        ]
        for args, message in cases:
            with self.subTest(args=args):
                p = report(*args)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertNotIn("Traceback", p.stderr)
                self.assertIn(message, p.stderr)
                self.assertEqual(len(p.stderr.strip().splitlines()), 1, p.stderr)
        p = crater("report", check=False)  # no DIR: the command line is wrong
        self.assertEqual(p.returncode, 2)

    def test_missing_python_or_modules_exits_1(self):
        env = dict(os.environ, CRATER_PYTHON=str(self.work / "no-python"))
        p = report(self.demo, env=env)
        self.assertEqual(p.returncode, 1)
        self.assertIn("python3-vtk9 python3-matplotlib python3-numpy", p.stderr)
        # An interpreter without Debian's site packages (-S) lacks numpy, VTK and matplotlib.
        bare = self.work / "bare-python"
        bare.write_text(f'#!/bin/sh\nexec {sys.executable} -S "$@"\n')
        bare.chmod(0o755)
        p = report(self.demo, env=dict(os.environ, CRATER_PYTHON=str(bare)))
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        self.assertIn("python3-vtk9", p.stderr)


class Report3D(unittest.TestCase):
    """A quarter model (symmetry planes x = 0 and y = 0) of a small charge under a plate in a
    box of grains: the 3D maps, the plate from below and the crater, mirrored to the whole
    model."""

    @classmethod
    def setUpClass(cls):
        cls.work = scratch("report_3d")
        scenario = cls.work / "scene3d.toml"
        scenario.write_text(SCENE_3D)
        cls.run_dir = cls.work / "scene3d"
        run_scenario(scenario, cls.run_dir, threads=1)
        cls.proc = report(cls.run_dir)

    def test_maps_written(self):
        p = self.proc
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        self.assertNotIn("warning", p.stderr)
        text = Report.assert_valid_report(self, self.run_dir / "report", [
            "plate_from_below.png", "crater_map.png", "snapshots_von_mises.png",
            "surface_profile.png"])
        self.assertIn("mirrored through the scenario's symmetry planes", text)
        # The sizes the figures are laid out at (100 dpi): the plate at two frames (the last,
        # and the one nearest probes.stress_time_s) side by side, 2 x 7.6 x 7.4 in for a
        # square plate; the crater map 8.1 x 7.5 in for a square domain.
        self.assertEqual(png_size(self.run_dir / "report" / "plate_from_below.png"), (1520, 740))
        self.assertEqual(png_size(self.run_dir / "report" / "crater_map.png"), (810, 750))

    def test_without_the_scenario_file(self):
        # The scenario moved away: the maps are still drawn (not mirrored), no error.
        run = self.work / "moved"
        if run.exists():
            shutil.rmtree(run)
        shutil.copytree(self.run_dir, run, ignore=shutil.ignore_patterns("report"))
        cmd = run / "crater-command.toml"
        cmd.write_text(re.sub(r"(?m)^(scenario(_file)?) = .*$", r"\1 = 'gone.toml'",
                              cmd.read_text()))
        summary = json.loads((run / "summary.json").read_text())
        summary["scenario"]["file"] = "gone.toml"
        (run / "summary.json").write_text(json.dumps(summary))
        p = report(run)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        Report.assert_valid_report(self, run / "report", ["plate_from_below.png",
                                                          "crater_map.png"])


# A small charge under a plate in a box of grains: the paper's scene
# (scenarios/paper-20cm.toml) at a fifth of its size; runs in about a second.
SCENE = scenario_text(compose_scenario(
    "report-small", 2, 2.0e-4,
    description="a small charge under a plate in a box of grains (crater report test)",
    time={"safety_factor": 0.45}, output=output(5.0e-5, history_every=10),
    domain=domain([0.0, -0.6], [1.0, 1.0], gravity=[0.0, -9.81]),
    materials=[TNT, material(STEEL_JC, damage=STEEL_JC_DAMAGE), SAND],
    parts=[part("charge", "sph", "tnt", 0.02, disk([0.35, -0.38], 0.1),
                sph={"walls": ["left", "right", "bottom"]},
                detonation=[{"point_m": [0.35, -0.38]}]),
           part("plate", "fem", "steel", 0.025, box([0.0, -0.2], [1.0, -0.15]),
                fem={"erode_inverted": True, "erosion_plastic_strain": 2.0}),
           part("soil", "dem", "sand", 0.03, box([0.0, -0.6], [1.0, 0.0]),
                carve=["charge", "plate"],
                dem={"radius_min_m": 0.011, "radius_max_m": 0.014,
                     "hertz_2d": "row_of_spheres", "walls": ["left", "right", "bottom"]})],
    contacts=[contact("charge", "plate"), contact("soil", "plate", friction=0.4),
              contact("charge", "soil")]))


# SCENE in 3D as a quarter model: a charge of some 230 SPH particles (the whole sphere given,
# centred on the symmetry planes' corner), a plate of 13 x 13 hexahedra and some 350 grains;
# a few steps.
SCENE_3D = scenario_text(compose_scenario(
    "report-small-3d", 3, 6.0e-5,
    description="a quarter model of a small charge under a plate in grains (crater report test)",
    time={"safety_factor": 0.45}, output=output(2.0e-5, history_every=5),
    domain={**domain([0.0, 0.0, -0.3], [0.4, 0.4, 0.3], gravity=[0.0, 0.0, -9.81]),
            "symmetry_planes": ["left", "bottom"]},
    materials=[TNT, material(STEEL_JC, damage=STEEL_JC_DAMAGE), SAND],
    parts=[part("charge", "sph", "tnt", 0.01,
                {"type": "sphere", "center_m": [0.0, 0.0, -0.15], "radius_m": 0.06},
                sph={"walls": ["right", "top", "back"]},
                detonation=[{"point_m": [0.0, 0.0, -0.15]}]),
           part("plate", "fem", "steel", 0.02, box([0.0, 0.0, -0.08], [0.26, 0.26, -0.06]),
                fem={"erode_inverted": True, "erosion_plastic_strain": 0.3}),
           part("soil", "dem", "sand", 0.05, box([0.0, 0.0, -0.3], [0.4, 0.4, 0.0]),
                carve=["charge", "plate"],
                dem={"radius_min_m": 0.022, "radius_max_m": 0.025,
                     "walls": ["right", "top", "back"]})],
    contacts=[contact("charge", "plate"), contact("soil", "plate", friction=0.4),
              contact("charge", "soil")],
    probes={"plate": "plate", "soil": "soil", "stress_time_s": 3.0e-5}))


class ReportTraps(unittest.TestCase):
    """Issue 28's traps in the report: the per-part energy panel, what left the domain, the
    framing of the snapshots, and the flags."""

    @classmethod
    def setUpClass(cls):
        cls.work = scratch("report_traps")
        data = SOURCE_DIR / "tests" / "data"
        cls.outflow = cls.work / "outflow"
        cls.outflow_summary = run_scenario(data / "outflow_2d.toml", cls.outflow)
        # The clamped plate's middle thrown at 600 m/s out of its own box (the domain, which
        # does not hold FEM nodes).
        cls.plate = cls.work / "plate"
        run_scenario(data / "fem_plate_2d.toml", cls.plate)

    def test_parts_hold_what_the_totals_say(self):
        # kinetic_<part>_j and internal_<part>_j add up to history.csv's kinetic_j, internal_j.
        with open(self.outflow / "history.csv") as f:
            rows = list(csv.DictReader(f))
        parts = [p["name"] for p in self.outflow_summary["parts"]]
        for r in rows[:: max(1, len(rows) // 20)]:
            for term in ("kinetic", "internal"):
                total = sum(float(r[f"{term}_{p}_j"]) for p in parts)
                self.assertAlmostEqual(total, float(r[f"{term}_j"]),
                                       delta=1e-12 * max(1.0, abs(float(r[f"{term}_j"]))))

    def test_parts_table_shows_what_left_the_domain(self):
        out = self.work / "outflow_report"
        p = report(self.outflow, "--out", out, "--times", "0")  # one snapshot: report.md is read
        self.assertEqual(p.returncode, 0, p.stderr)
        md = (out / "report.md").read_text()
        self.assertIn("| part | method | count | mass | left the domain | eroded | notes |", md)
        for part in self.outflow_summary["parts"]:
            left = part["diagnostics"].get("left_domain_mass_kg")
            if left:
                row = next(l for l in md.splitlines() if l.startswith(f"| {part['name']} |"))
                self.assertEqual(float(row.split("|")[5]), float(f"{left:.6g}"), row)

    def test_snapshots_say_what_the_view_leaves_out(self):
        out = self.work / "plate_report"
        p = report(self.plate, "--out", out, "--times", "1e-4")  # the end: the middle flown off
        self.assertEqual(p.returncode, 0, p.stderr)
        md = (out / "report.md").read_text()
        self.assertRegex(md, r"particles and elements outside it are not drawn: \d+ at ")

    def test_crater_at_the_bottom_is_flagged(self):
        # The flag reads summary.json: the crater depth against the bed's depth.
        for depth, flagged in ((1.995, True), (1.95, False)):
            with self.subTest(depth=depth):
                d = self.work / f"flag_{depth}"
                if d.exists():
                    shutil.rmtree(d)
                shutil.copytree(self.outflow, d)
                s = json.loads((d / "summary.json").read_text())
                s["metrics"]["crater_depth_m"] = depth
                s["parts"][1]["diagnostics"]["packing_bed_height_m"] = 2.0
                (d / "summary.json").write_text(json.dumps(s))
                p = report(d, "--times", "0")
                self.assertEqual(p.returncode, 0, p.stderr)
                md = (d / "report" / "report.md").read_text()
                self.assertEqual("The crater reached the bottom of the box" in md, flagged)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
