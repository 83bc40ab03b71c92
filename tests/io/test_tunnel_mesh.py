# ctest-labels: slow
"""The committed meshes of paper-tunnel are tools/mesh/tunnel.py's output: the script (Debian's
python3-gmsh, which `make test` does not install: this test is `slow`, run with
`ctest -L slow` after `sudo apt-get install python3-gmsh`) writes scenarios/meshes/
paper-tunnel-demo.msh and -medium.msh byte for byte, all hexahedra, with the physical groups
the scenario names."""
import os
import subprocess
import sys
import unittest
from pathlib import Path

from crater_test import scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
GROUPS = ("lining", "soil", "lining_inner", "lining_outer", "soil_inner", "sym_x", "sym_y",
          "soil_side", "soil_bottom", "ground", "far_end")


class TunnelMesh(unittest.TestCase):
    def test_script_writes_the_committed_meshes(self):
        work = scratch("tunnel_mesh")
        for level in ("demo", "medium"):
            with self.subTest(level=level):
                out = work / f"{level}.msh"
                p = subprocess.run(["/usr/bin/python3", SOURCE / "tools" / "mesh" / "tunnel.py",
                                    "--level", level, "--out", out],
                                   capture_output=True, text=True, timeout=600)
                self.assertEqual(p.returncode, 0, p.stderr)
                committed = SOURCE / "scenarios" / "meshes" / f"paper-tunnel-{level}.msh"
                self.assertEqual(out.read_bytes(), committed.read_bytes())
                text = out.read_text()
                for g in GROUPS:
                    self.assertIn(f'"{g}"', text)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
