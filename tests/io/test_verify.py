# ctest-cost: 25
"""`crater verify` from an installed crater (issue 28): `cmake --install` of this build into a
fresh prefix, then only PREFIX/bin/crater and PREFIX/share/crater/verify are used, from a working
directory outside the source and build trees.

1. `crater verify --quick` passes: exit 0, every quick case of cases.toml run from the installed
   directory (verify.json says where the cases came from), each check's measured value within
   its tolerance of its reference, at least one case per method (DEM, FEM, SPH), the table on
   stdout.
2. A reference perturbed in the installed cases.toml (the bar's 2L/c, 3.96e-5 s, set to 3.0e-5 s,
   outside its 3 % tolerance): exit 1, the case named as FAILED on stderr and in verify.json, its
   row FAIL in the table; the measured value is the same as in the passing run (the run did not
   change, only the reference).
3. Bad input exits 2 and runs nothing: an unknown --case, a cases.toml with an unknown
   reduction, a check with two tolerances. A case whose run fails (a scenario crater rejects)
   fails the verification with exit 1, its crater exit code in verify.json.
"""
import json
import shutil
import subprocess
import sys
import tomllib
import unittest
from pathlib import Path

from crater_test import BIN, scratch

BUILD_DIR = Path(BIN).resolve().parent.parent


def install(prefix):
    if prefix.exists():
        shutil.rmtree(prefix)
    subprocess.run(["cmake", "--install", str(BUILD_DIR), "--prefix", str(prefix)], check=True,
                   capture_output=True, text=True, timeout=300)
    return prefix / "bin" / "crater", prefix / "share" / "crater" / "verify"


def verify(binary, cwd, *args):
    return subprocess.run([str(binary), "verify", *map(str, args)], capture_output=True,
                          text=True, timeout=900, cwd=cwd)


class VerifyInstalled(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("verify")
        if cls.work.exists():
            shutil.rmtree(cls.work)
        cls.work.mkdir(parents=True)
        cls.binary, cls.cases_dir = install(cls.work / "prefix")
        cls.cases = tomllib.loads((cls.cases_dir / "cases.toml").read_text())["case"]
        cls.quick = verify(cls.binary, cls.work, "--quick", "--threads", "1", "--out", "quick",
                         "--json", cls.work / "quick.json")
        print(cls.quick.stdout, cls.quick.stderr, file=sys.stderr)
        cls.doc = json.loads((cls.work / "quick.json").read_text())

    def test_quick_passes_from_the_install(self):
        self.assertEqual(self.quick.returncode, 0, self.quick.stderr)
        self.assertTrue(self.doc["passed"])
        self.assertEqual(Path(self.doc["cases_dir"]), self.cases_dir.resolve())
        quick = [c["name"] for c in self.cases if c.get("quick")]
        self.assertEqual([c["name"] for c in self.doc["cases"]], quick)
        self.assertEqual({c["method"] for c in self.doc["cases"]}, {"DEM", "FEM", "SPH"})
        for case in self.doc["cases"]:
            self.assertTrue(case["scenario"].startswith(str(self.cases_dir.resolve())))
            self.assertEqual(case["exit_code"], 0)
            for chk in case["checks"]:
                err = (chk["measured"] / chk["reference"] - 1 if chk["tolerance_kind"] == "rel"
                       else chk["measured"] - chk["reference"])
                self.assertLessEqual(abs(err), chk["tolerance"], (case["name"], chk))
                self.assertTrue(chk["passed"])
        rows = [ln for ln in self.quick.stdout.splitlines() if ln.endswith("PASS")]
        self.assertEqual(len(rows), sum(len(c["checks"]) for c in self.doc["cases"]))
        # The runs are ordinary run directories under --out.
        self.assertTrue((self.work / "quick" / "sph-sod" / "summary.json").exists())

    def test_a_perturbed_reference_fails_naming_the_case(self):
        perturbed = self.work / "perturbed"
        shutil.copytree(self.work / "prefix", perturbed, symlinks=True)
        cases_file = perturbed / "share" / "crater" / "verify" / "cases.toml"
        text = cases_file.read_text()
        self.assertEqual(text.count("reference = 3.96232e-05"), 1)
        cases_file.write_text(text.replace("reference = 3.96232e-05", "reference = 3.0e-05"))
        run = verify(perturbed / "bin" / "crater", self.work, "--quick", "--case",
                     "fem-bar-on-wall", "--threads", "1", "--out", "perturbed-out")
        self.assertEqual(run.returncode, 1, run.stderr)
        self.assertIn("FAILED fem-bar-on-wall", run.stderr)
        self.assertIn("time on the wall", run.stderr)
        row = next(ln for ln in run.stdout.splitlines() if "time on the wall" in ln)
        self.assertTrue(row.startswith("fem-bar-on-wall") and row.endswith("FAIL"), row)
        doc = json.loads((self.work / "perturbed-out" / "verify.json").read_text())
        self.assertFalse(doc["passed"])
        self.assertEqual(doc["failed"], ["fem-bar-on-wall"])
        bad = doc["cases"][0]["checks"][0]
        good = next(c for c in self.doc["cases"] if c["name"] == "fem-bar-on-wall")["checks"][0]
        self.assertEqual(bad["measured"], good["measured"])
        self.assertFalse(bad["passed"])
        # The other checks of the case still pass: only the perturbed one is reported.
        self.assertTrue(all(c["passed"] for c in doc["cases"][0]["checks"][1:]))

    def bad_cases_dir(self, name, edit):
        d = self.work / name
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(self.cases_dir, d)
        f = d / "cases.toml"
        f.write_text(edit(f.read_text()))
        return d

    def test_bad_input_exits_2(self):
        run = verify(self.binary, self.work, "--case", "no-such-case")
        self.assertEqual(run.returncode, 2)
        self.assertIn("no-such-case", run.stderr)
        self.assertIn("dem-hertz-impact", run.stderr)  # the cases it knows
        d = self.bad_cases_dir("bad-reduce", lambda t: t.replace(
            'reduce = "span_above"', 'reduce = "longest"', 1))
        run = verify(self.binary, self.work, "--cases", d, "--out", "bad-out")
        self.assertEqual(run.returncode, 2)
        self.assertIn("dem-hertz-impact", run.stderr)
        self.assertIn("longest", run.stderr)
        self.assertFalse((self.work / "bad-out").exists(), "nothing may run")
        d = self.bad_cases_dir("two-tolerances", lambda t: t.replace(
            "tolerance_rel = 0.03 ", "tolerance_rel = 0.03\ntolerance_abs = 1e-6 ", 1))
        run = verify(self.binary, self.work, "--cases", d, "--out", "bad-out")
        self.assertEqual(run.returncode, 2)
        self.assertIn("exactly one of tolerance_rel, tolerance_abs", run.stderr)

    def test_a_run_that_fails_fails_the_case(self):
        d = self.bad_cases_dir("run-fails", lambda t: t)
        scenario = d / "dem-restitution.toml"
        scenario.write_text(scenario.read_text().replace("restitution = 0.5", "restitution = 7"))
        run = verify(self.binary, self.work, "--cases", d, "--case", "dem-restitution",
                     "--out", "fails-out")
        self.assertEqual(run.returncode, 1)
        self.assertIn("FAILED dem-restitution: crater run exited with 2", run.stderr)
        doc = json.loads((self.work / "fails-out" / "verify.json").read_text())
        self.assertEqual(doc["cases"][0]["exit_code"], 2)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
