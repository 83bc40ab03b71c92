# ctest-timeout: 1200
# ctest-cost: 180
"""Rate-dependent friction in a run (issue 24's acceptance: "a shear/biaxial test at two strain
rates shows the friction rise the law predicts (within 10 %)"; paper section III-C; the case,
its parameters and the method: rate_study.py; docs/validation.md, "DEM: biaxial test").

Per packing (seeds 1, 2, 3), the biaxial test of slippery disks (mu 0.1, the law with beta 1,
reference rate 0.01 /s) sheared at 0.1 and 1 /s to eps_1 = 1.5 %. Measured rise: the law-on
run's mobilised friction angle (mean over eps_1 = 0.25-1 %) at 1 /s minus at 0.1 /s. Predicted
rise: the same from law-off runs of the same packing at the constant mu_dyn the law gives at
the nominal rate (contact angle 5.71 deg x 2 and x 3: mu 0.202 at 0.1 /s, 0.308 at 1 /s).

Asserted:
- the mean over the three packings of the measured rise is within 10 % of the mean of the
  predicted rise (the issue's tolerance). Measured (2026-12-01, the walls' loads as
  reproducible sums): 3.04 against 3.12 deg, ratio 0.974 (per packing 1.19 / 1.05 / 0.80;
  2026-11-26: 2.87 against 3.04, 0.946). The comparison is a difference of differences of a
  400-grain sample's angle, and the law-off runs at another mu follow other trajectories: over
  twelve packings (rate_study.py 1 ... 12) the per-packing ratio spans 0.59-1.86, the mean
  rises are 2.87 against 3.11 deg (0.922), and the standard error of the paired difference is
  9 % of the rise (12 % for three packings; bootstrap 95 %: 0.78-1.12). So the 10 % is met by
  the mean, here and over twelve packings, but three packings resolve it only to about +-12 %;
  no per-packing ratio is asserted;
- per packing, the law raises the friction well beyond what the rate alone does: the measured
  rise exceeds 1.5 deg, where the law-off sample at mu 0.1 rises by 0.20-0.88 deg from 0.1 to
  1 /s (rate_study.py's static runs, twelve packings) and the law-on by 2.11-4.09 deg.
Runs are deterministic (the same binary gives the same numbers), so the test does not flake; a
change of the DEM's arithmetic redraws the trajectories, and a failure just outside 10 % should
be judged on the twelve-packing study, not by widening the tolerance.
The runs stop at eps_1 = 1.15 % (STRAIN_TEST), not the study's 1.5 %: the angle is the mean
over eps_1 <= 1 % (the top reaches it 0.125 % of strain late, after its ramp), an explicit run
does not look ahead, and the frames stay at the study's times (rate_study.run), so every angle
is the study's bit for bit (checked: seed 1, 0.1 /s, 24.867758 deg either way) at 20 % less
cost. Wall time: 3.1 minutes alone on one core (twelve runs).
Writes CRATER_TEST_TMP/biaxial_rate_friction_test/rates.json.
"""
import json
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from biaxial_case import SEEDS  # noqa: E402
from crater_test import scratch  # noqa: E402
from rate_study import study_seed, summarise  # noqa: E402

TOLERANCE = 0.10
STRAIN_TEST = 0.0115  # past PHI_BAND's end (eps_1 = 1 %) with the ramp's lag


class RateDependentFriction(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        work = scratch("biaxial_rate_friction_test")
        cls.seeds = [study_seed(work, seed, static=False, strain=STRAIN_TEST) for seed in SEEDS]
        cls.summary = summarise(cls.seeds)
        out = {"seeds": cls.seeds, "summary": cls.summary}
        (work / "rates.json").write_text(json.dumps(out, indent=1))
        print(json.dumps(out, indent=1), file=sys.stderr)

    def test_mean_rise_within_ten_percent_of_prediction(self):
        self.assertLess(abs(self.summary["ratio_of_means"] - 1), TOLERANCE)

    def test_every_packing_shows_the_rise(self):
        for s in self.seeds:
            with self.subTest(seed=s["seed"]):
                self.assertGreater(s["rise_measured"], 1.5)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
