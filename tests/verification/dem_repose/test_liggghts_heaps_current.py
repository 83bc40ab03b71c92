# ctest-processors: 2
# ctest-labels: slow
# ctest-timeout: 1800
"""LIGGGHTS' drained heaps checked in for test_drained_heap_vs_liggghts.py
(tests/data/liggghts_drained_heap.json) are still what the deck gives: where `liggghts` is
installed, bench/peers/liggghts_drained_heap/run.py runs the three seeds again (2-6 minutes on two
cores) and each heap must come out the same: spheres left equal, flank angles and apex equal
to the JSON's rounding (1e-3 degree, 1e-6 m). LIGGGHTS on one process is deterministic, so any
difference means the deck, the runner, the lattice or the angle measurement changed without the
JSON being regenerated.
"""
import json
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

from crater_test import SOURCE_DIR
from drained_heap import LIGGGHTS_HEAPS

RUNNER = SOURCE_DIR / "bench" / "peers" / "liggghts_drained_heap" / "run.py"


@unittest.skipUnless(shutil.which("liggghts") or shutil.which("lmp_auto"), "LIGGGHTS not installed")
class LiggghtsHeapsCurrent(unittest.TestCase):
    def test_rerun_matches(self):
        with tempfile.TemporaryDirectory() as d:
            out = Path(d) / "heaps.json"
            subprocess.run(["/usr/bin/python3", str(RUNNER), str(out)], check=True)
            now = json.loads(out.read_text())
        ref = json.loads(LIGGGHTS_HEAPS.read_text())
        self.assertEqual(now["variables"], ref["variables"])
        for a, b in zip(now["runs"], ref["runs"], strict=True):
            for sa, sb in zip(a["stages"], b["stages"], strict=True):
                with self.subTest(seed=a["seed"]):
                    print(f"seed {a['seed']}: {sa} / checked in {sb}", file=sys.stderr)
                    self.assertEqual(sa["spheres"], sb["spheres"])
                    for x, y in zip(sa["flanks_deg"], sb["flanks_deg"], strict=True):
                        self.assertAlmostEqual(x, y, delta=1e-3)
                    self.assertAlmostEqual(sa["apex_m"], sb["apex_m"], delta=1e-6)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
