# ctest-fixtures: bundled_bed
"""The memory estimate (src/solver/memory_estimate.cpp): `crater check` prints it for every
bundled scenario; it is within 30 % of the peak resident set size of the bundled demo-level
runs (setup and the first 50 steps, which reach 87-97 % of the whole runs' peak:
docs/performance.md "Memory estimate"); a scenario far too big for the machine is refused
with exit 2, naming the part's key, before anything large is allocated; an allocation that
fails anyway in setup is "out of memory", exit 2."""
import os
import re
import resource
import subprocess
import unittest

from crater_test import BIN, crater, scratch

MEMORY_LINE = re.compile(r"^memory: about ([\d.]+) (kB|MB|GB) estimated \((.*)\), "
                         r"([\d.]+) (kB|MB|GB) available", re.M)
UNIT = {"kB": 1e3, "MB": 1e6, "GB": 1e9}
ONE_GB = 1e9


def estimate_bytes(stdout):
    m = MEMORY_LINE.search(stdout)
    if m is None:
        raise AssertionError(f"no memory line in:\n{stdout}")
    return float(m.group(1)) * UNIT[m.group(2)]


def run_peak_rss(*args, address_space=None):
    """Runs crater; returns (exit code, stderr, peak resident set size of that process [B]).
    address_space [B]: a limit on the child's virtual memory (RLIMIT_AS)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    proc = subprocess.Popen([BIN, *map(str, args)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=limit if address_space else None)
    err = proc.stderr.read()
    proc.stderr.close()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, err, usage.ru_maxrss * 1024  # Linux: kB


class MemoryEstimate(unittest.TestCase):
    def test_check_prints_the_estimate_for_every_bundled_scenario(self):
        names = [line.split()[0] for line in crater("list").stdout.splitlines()
                 if line.strip() and not line[0].isspace()]
        self.assertIn("demo", names)
        for name in names:
            with self.subTest(scenario=name):
                p = crater("check", name)
                self.assertGreater(estimate_bytes(p.stdout), 1e6)

    def test_estimate_within_30_percent_of_peak_rss(self):
        for name, extra in (("demo", ()), ("paper-20cm", ("--level", "demo"))):
            with self.subTest(scenario=name):
                estimate = estimate_bytes(crater("check", name, *extra).stdout)
                out = scratch(f"memory_{name}")
                code, err, peak = run_peak_rss("run", name, *extra, "--out", out, "--force",
                                               "--quiet", "--set", "time.max_steps=50")
                self.assertEqual(code, 0, err)
                self.assertLess(abs(estimate - peak), 0.3 * peak,
                                f"estimate {estimate / 1e6:.1f} MB, peak {peak / 1e6:.1f} MB")

    def test_too_big_scenario_is_refused_before_allocating(self):
        # About 1.9e8 particles, 1.6e8 grains (the dense bed's 0.82 of the 5.9 m^2 left by the
        # carved charge and plate, in disks of 0.1 mm) or 1.9e8 elements: just under the
        # load-time limit of 2e8.
        grains = ("parts.soil.dem.radius_min_m=1e-4", "parts.soil.dem.radius_max_m=1e-4")
        cases = (
            ("demo", ("parts.charge.spacing_m=1.286e-5",), "parts.charge.spacing_m",
             r"1\.9\d*e\+08 particles"),
            ("paper-20cm", grains, "parts.soil.dem.radius_min_m", r"1\.6\d*e\+08 grains"),
            ("paper-20cm", ("parts.plate.spacing_m=6.49e-5",), "parts.plate.spacing_m",
             r"1\.9\d*e\+08 elements"),
        )
        for name, overrides, key, count in cases:
            for command in ("check", "run"):
                with self.subTest(scenario=name, key=key, command=command):
                    args = [command, name]
                    for o in overrides:
                        args += ["--set", o]
                    if command == "run":
                        args += ["--out", scratch("memory_refused"), "--force", "--quiet"]
                    code, err, peak = run_peak_rss(*args)
                    self.assertEqual(code, 2, err)
                    self.assertIn(f"key '{key}'", err)
                    self.assertRegex(err, "about " + count)
                    self.assertIn("output.memory_limit_fraction", err)
                    self.assertLess(peak, ONE_GB)

    def test_allocation_failure_in_setup_exits_2(self):
        # Within the machine's memory (2.4 GB estimated), but the process may map only 400 MB:
        # building the charge fails (std::bad_alloc), reported as out of memory, exit 2.
        for command in ("check", "run"):
            with self.subTest(command=command):
                args = [command, "demo", "--set", "parts.charge.spacing_m=0.0002"]
                if command == "run":
                    args += ["--out", scratch("memory_bad_alloc"), "--force", "--quiet"]
                code, err, _ = run_peak_rss(*args, address_space=400 * 2**20)
                self.assertEqual(code, 2, err)
                self.assertIn("error: out of memory while setting up", err)

    def test_memory_limit_fraction_is_settable(self):
        # The demo needs about 11 MB: a limit of a millionth of the available memory (some
        # tens of kB on any machine that runs the suite) refuses it, naming the charge.
        p = crater("check", "demo", "--set", "output.memory_limit_fraction=1e-6", check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("key 'parts.charge.spacing_m'", p.stderr)
        p = crater("check", "demo", "--set", "output.memory_limit_fraction=2", check=False)
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("output.memory_limit_fraction", p.stderr)


if __name__ == "__main__":
    unittest.main()
