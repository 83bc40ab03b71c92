# ctest-timeout: 120
"""The size check (issue 23, second acceptance item): tools/check_sizes.py holds src/ to the
limits of docs/architecture.md (lines per file, per function). The repository passes; a copy
with a file over the limit, a function over the limit, or a `known-...` line that no longer
matches anything fails, naming the file (and line and function)."""
import os
import shutil
import subprocess
import sys
import unittest
from pathlib import Path

from crater_test import scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / "tools" / "check_sizes.py"


def check(root):
    return subprocess.run(["/usr/bin/python3", SCRIPT, "--root", root], capture_output=True,
                          text=True, timeout=60)


class Sizes(unittest.TestCase):
    def copy(self, name):
        d = scratch("sizes") / name
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(SOURCE / "src", d / "src")
        (d / "docs").mkdir()
        shutil.copy(SOURCE / "docs" / "architecture.md", d / "docs")
        return d

    def test_the_repository_passes(self):
        proc = check(SOURCE)
        self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)

    def test_long_file_fails(self):
        root = self.copy("long_file")
        path = root / "src" / "core" / "types.hpp"
        n = len(path.read_text().splitlines())
        path.write_text(path.read_text() + "// filler\n" * (801 - n))
        proc = check(root)
        self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
        self.assertIn("src/core/types.hpp: 801 lines, over 800", proc.stdout)

    def test_long_function_fails(self):
        root = self.copy("long_function")
        body = "".join(f"  x += {k};\n" for k in range(119))
        # 1 line for the head, 119 of body, 1 for the return, 1 for the brace: 122 lines.
        code = f"inline int long_one(int x) {{\n{body}  return x;\n}}\n"
        path = root / "src" / "core" / "types.hpp"
        path.write_text(path.read_text() + code)
        proc = check(root)
        self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
        self.assertIn("function long_one is 122 lines, over 120", proc.stdout)
        # Two lines shorter, at the limit (120 lines), it passes.
        path.write_text(path.read_text().replace("  x += 117;\n  x += 118;\n", ""))
        self.assertEqual(check(root).returncode, 0)

    def test_stale_known_line_fails(self):
        root = self.copy("stale")
        doc = root / "docs" / "architecture.md"
        doc.write_text(doc.read_text().replace(
            "function-lines 120\n", "function-lines 120\nknown-file src/core/types.hpp\n"))
        proc = check(root)
        self.assertEqual(proc.returncode, 1, proc.stdout + proc.stderr)
        self.assertIn("'known-file src/core/types.hpp' in docs/architecture.md no longer "
                      "applies", proc.stdout)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
