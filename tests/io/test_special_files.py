"""A scenario or mesh path that is not a regular file (a directory, a character device such as
/dev/zero, a FIFO, a socket) is an input error (exit 2) that says what it is, found from its
status alone: /dev/zero was called 'a directory', and a FIFO must not block the loader."""
import os
import shutil
import socket
import sys
import tempfile
import unittest
from pathlib import Path

from crater_test import SOURCE_DIR, TMP, crater
from scenario_blocks import STEEL, compose_scenario, domain, part, scenario_text

DEMO = (SOURCE_DIR / "scenarios" / "demo.toml").read_text()
TIMEOUT = 60  # a read of /dev/zero or of a FIFO without a writer would not end


def mesh_scenario(mesh_path):
    """A 2D FEM plate read from mesh_path."""
    return scenario_text(compose_scenario(
        "mesh-special", 2, 1e-5, description="an FEM plate from a mesh file",
        domain=domain([0, 0], [0.2, 0.02]), materials=[STEEL],
        parts=[part("plate", "fem", "steel", fem={"mesh_file": mesh_path})]))


class SpecialFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # A fresh directory (scratch() empties only files and directories, not a FIFO).
        TMP.mkdir(parents=True, exist_ok=True)
        cls.work = Path(tempfile.mkdtemp(prefix="special_files_", dir=TMP))
        cls.fifo = cls.work / "scenario.fifo"
        os.mkfifo(cls.fifo)
        cls.sock_path = cls.work / "scenario.sock"
        cls.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        cls.sock.bind(str(cls.sock_path))

    @classmethod
    def tearDownClass(cls):
        cls.sock.close()
        shutil.rmtree(cls.work)

    def cases(self):
        yield "/dev/zero", "is a character device"
        yield self.fifo, "is a FIFO (named pipe)"
        yield self.work, "is a directory"
        yield self.sock_path, "is a socket"

    def test_scenario_path(self):
        for path, what in self.cases():
            for command in ("check", "run"):
                with self.subTest(path=str(path), command=command):
                    extra = ["--out", self.work / "run"] if command == "run" else []
                    p = crater(command, path, *extra, check=False, timeout=TIMEOUT)
                    self.assertEqual(p.returncode, 2, p.stderr)
                    self.assertIn(f"'{path}' {what}", p.stderr)
                    self.assertNotIn("got a directory", p.stderr)

    def test_mesh_path(self):
        for path, what in self.cases():
            with self.subTest(path=str(path)):
                scenario = self.work / "mesh.toml"
                scenario.write_text(mesh_scenario(path))
                p = crater("check", scenario, check=False, timeout=TIMEOUT)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertIn("parts[0].fem.mesh_file", p.stderr)
                self.assertIn(f"'{path}' {what}", p.stderr)

    def test_regular_file_still_loads(self):
        scenario = self.work / "demo.toml"
        scenario.write_text(DEMO)
        self.assertTrue(crater("check", scenario, timeout=TIMEOUT).stdout.rstrip().endswith("ok"))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
