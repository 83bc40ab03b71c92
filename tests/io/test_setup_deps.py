"""tools/setup-deps.sh never removes a package: apt-get runs with --no-remove, and with ParaView's
python3-paraview installed (it conflicts with python3-vtk9, so installing python3-vtk9 removed the
viewer the README recommends) python3-vtk9 is not requested: ParaView's VTK serves when the
Python imports it, and otherwise the script stops with what to do. Runs the script against stub
dpkg-query, apt-get, sudo, id and python that record their arguments (nothing is installed)."""
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from crater_test import SOURCE_DIR

SCRIPT = SOURCE_DIR / "tools" / "setup-deps.sh"

STUBS = {
    # Installed packages: the names in $FAKE_INSTALLED.
    "dpkg-query": """#!/bin/sh
echo "dpkg-query $*" >> "$FAKE_LOG"
for last; do :; done
for p in $FAKE_INSTALLED; do
  if [ "$p" = "$last" ]; then printf 'install ok installed'; exit 0; fi
done
echo "dpkg-query: no packages found matching $last" >&2
exit 1
""",
    "apt-get": """#!/bin/sh
echo "apt-get $*" >> "$FAKE_LOG"
case "$1" in install) exit "${FAKE_APT_INSTALL_RC:-0}";; esac
exit 0
""",
    "sudo": """#!/bin/sh
echo "sudo $*" >> "$FAKE_LOG"
exec "$@"
""",
    "id": """#!/bin/sh
echo "${FAKE_UID:-0}"
""",
    # The interpreter given as CRATER_PYTHON: imports VTK when $FAKE_VTK is 1.
    "python": """#!/bin/sh
echo "python $*" >> "$FAKE_LOG"
[ "${FAKE_VTK:-0}" = 1 ]
""",
}

ALL = ("g++ cmake ninja-build make pkg-config libeigen3-dev libtomlplusplus-dev libcli11-dev "
       "libfmt-dev libspdlog-dev libgtest-dev libgmock-dev libbenchmark-dev libopenmpi-dev "
       "openmpi-bin python3 "
       "python3-numpy python3-matplotlib clang-format universal-ctags")


class SetupDeps(unittest.TestCase):
    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="crater_setup_deps_"))
        self.addCleanup(shutil.rmtree, self.dir)
        bin_dir = self.dir / "bin"
        bin_dir.mkdir()
        for name, text in STUBS.items():
            path = bin_dir / name
            path.write_text(text)
            path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
        self.log = self.dir / "log"
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("FAKE_")}
        self.env.update(PATH=f"{bin_dir}:{os.environ.get('PATH', '/usr/bin:/bin')}",
                        FAKE_LOG=str(self.log), CRATER_PYTHON=str(bin_dir / "python"))

    def run_script(self, **fake):
        env = dict(self.env, **{f"FAKE_{k.upper()}": str(v) for k, v in fake.items()})
        proc = subprocess.run(["bash", str(SCRIPT)], env=env, capture_output=True, text=True,
                              timeout=60)
        calls = self.log.read_text().splitlines() if self.log.exists() else []
        installs = [c.split() for c in calls if c.startswith("apt-get install")]
        return proc, calls, installs

    def test_clean_machine_as_root(self):
        proc, calls, installs = self.run_script(installed="", uid=0)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("apt-get update -qq", calls)
        self.assertEqual(len(installs), 1, calls)
        self.assertIn("--no-remove", installs[0])
        for p in ("python3-vtk9", "g++", "python3-numpy"):
            self.assertIn(p, installs[0])
        self.assertFalse(any(c.startswith("sudo") for c in calls), calls)

    def test_not_root_uses_sudo_with_no_remove(self):
        proc, calls, installs = self.run_script(installed="", uid=1000)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        sudo_installs = [c.split() for c in calls if c.startswith("sudo apt-get install")]
        self.assertEqual(len(sudo_installs), 1, calls)
        self.assertIn("--no-remove", sudo_installs[0])

    def test_paraview_with_usable_vtk_keeps_paraview(self):
        proc, calls, installs = self.run_script(installed="python3-paraview", uid=0, vtk=1)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertEqual(len(installs), 1, calls)
        self.assertIn("--no-remove", installs[0])
        self.assertNotIn("python3-vtk9", installs[0])
        self.assertIn("python3-paraview", proc.stdout)
        self.assertTrue(any(c.startswith("python -c") and "vtkmodules" in c for c in calls), calls)

    def test_paraview_without_usable_vtk_stops_and_says_what_to_do(self):
        proc, calls, installs = self.run_script(installed="python3-paraview", uid=0, vtk=0)
        self.assertNotEqual(proc.returncode, 0)
        self.assertEqual(installs, [], calls)
        self.assertIn("python3-paraview", proc.stderr)
        self.assertIn("python3-vtk9", proc.stderr)

    def test_everything_installed_runs_no_apt(self):
        proc, calls, _ = self.run_script(installed=ALL + " python3-vtk9", uid=0)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertFalse(any(c.startswith("apt-get") for c in calls), calls)
        proc, calls, _ = self.run_script(installed=ALL + " python3-paraview", uid=0, vtk=1)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertFalse(any(c.startswith("apt-get") for c in calls), calls)

    def test_install_that_would_remove_fails_loudly(self):
        # apt-get --no-remove exits 100 when the install needs a removal.
        proc, calls, installs = self.run_script(installed="", uid=0, apt_install_rc=100)
        self.assertNotEqual(proc.returncode, 0)
        self.assertIn("--no-remove", installs[0])
        self.assertIn("without removing", proc.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
