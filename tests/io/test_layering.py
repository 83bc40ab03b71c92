# ctest-timeout: 120
"""The layering check (issue 23, first acceptance item): tools/check_layers.py holds src/ to the
rules of docs/architecture.md. The repository passes; a copy with a deliberate violation of each
kind fails, naming the file and line: a method including another method, a method including
io/, contact/ including a method, io/ including a method's part code (it may include only the
methods' settings headers), a new include cycle, and a `known` line that no longer matches
anything (the list of today's violations can only shrink)."""
import os
import shutil
import subprocess
import sys
import unittest
from pathlib import Path

from crater_test import scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / "tools" / "check_layers.py"


def check(root):
    return subprocess.run(["/usr/bin/python3", SCRIPT, "--root", root], capture_output=True,
                          text=True, timeout=60)


class Layering(unittest.TestCase):
    def copy(self, name):
        d = scratch("layering") / name
        shutil.copytree(SOURCE / "src", d / "src")
        (d / "docs").mkdir()
        shutil.copy(SOURCE / "docs" / "architecture.md", d / "docs")
        return d

    def add_include(self, root, file, include):
        path = root / file
        path.write_text(f'#include "{include}"\n' + path.read_text())

    def test_the_repository_passes(self):
        proc = check(SOURCE)
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)

    def test_deliberate_violations_fail(self):
        cases = [
            ("src/sph/kernels.hpp", "dem/laws/hertz_mindlin.hpp", "src/sph/kernels.hpp:1:",
             "'sph' must not include 'dem'"),
            ("src/fem/hourglass.hpp", "io/scenario/config.hpp", "src/fem/hourglass.hpp:1:",
             "'fem' must not include 'io'"),
            ("src/contact/coupling.cpp", "sph/kernels.hpp", "src/contact/coupling.cpp:1:",
             "'contact' must not include 'sph'"),
            # The reader may include a method's settings header (allow lines), nothing else.
            ("src/io/scenario/load.cpp", "sph/sph_part.hpp", "src/io/scenario/load.cpp:1:",
             "'io' must not include 'sph'"),
            ("src/core/types.hpp", "parallel/parallel.hpp", "include cycle joins src/core, "
             "src/parallel", "cycles none"),
        ]
        for n, (file, include, where, rule) in enumerate(cases):
            with self.subTest(file=file, include=include):
                root = self.copy(f"case{n}")
                self.add_include(root, file, include)
                proc = check(root)
                self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
                self.assertIn(where, proc.stdout)
                self.assertIn(rule, proc.stdout)

    def test_stale_known_line_fails(self):
        root = self.copy("stale")
        doc = root / "docs" / "architecture.md"
        doc.write_text(doc.read_text().replace("cycles none\n",
                                               "cycles none\nknown src/sph/kernels.hpp io\n"))
        proc = check(root)
        self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
        self.assertIn("'known src/sph/kernels.hpp io'", proc.stdout)
        self.assertIn("no longer happens", proc.stdout)

    def test_bad_rule_is_refused(self):
        root = self.copy("bad_rule")
        doc = root / "docs" / "architecture.md"
        doc.write_text(doc.read_text().replace("cycles none\n", "cycles none\nsph io\n"))
        proc = check(root)
        self.assertEqual(proc.returncode, 2, proc.stdout + proc.stderr)
        self.assertIn("not understood", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
