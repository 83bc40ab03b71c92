# ctest-cost: 1
"""`crater verify`'s measures (tools/verify/crater_verify.py: measure, judge), each reduction
on a hand-written history.csv / gauges.csv whose answers are worked out by hand below, and
validate()'s refusals. (test_verify.py runs the cases themselves from an installed crater.)
"""
import importlib.util
import json
import math
import sys
import unittest

from crater_test import SOURCE_DIR, scratch

spec = importlib.util.spec_from_file_location(
    "crater_verify", SOURCE_DIR / "tools" / "verify" / "crater_verify.py")
cv = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cv)

# t = 0, 1, 2, 3, 4 s; a.x rises and falls, two gauge columns to average.
GAUGES = """step,time_s,g.node3.f_x,g.node4.f_x,h.node1.v
0,0,1,3,-2
1,1,3,5,-1
2,2,5,7,4
3,3,2,4,3
4,4,0,2,1
"""
HISTORY = """step,time_s,kinetic_j
0,0,4
1,2,2
2,4,1
"""


class Measures(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = scratch("verify_measures")
        cls.d.mkdir(parents=True, exist_ok=True)
        (cls.d / "gauges.csv").write_text(GAUGES)
        (cls.d / "history.csv").write_text(HISTORY)
        (cls.d / "summary.json").write_text(json.dumps({"energy": {"balance_error": 1.5e-3}}))

    def m(self, **check):
        return cv.measure(self.d, check)

    def test_reductions(self):
        g = {"file": "gauges.csv", "column": "g.*.f_x"}  # mean of the two: 2, 4, 6, 3, 1
        self.assertEqual(self.m(**g, reduce="final"), 1)
        self.assertEqual(self.m(**g, reduce="first"), 2)
        self.assertEqual(self.m(**g, reduce="max"), 6)
        self.assertEqual(self.m(**g, reduce="min"), 1)
        self.assertEqual(self.m(**g, reduce="mean"), 16 / 5)
        self.assertEqual(self.m(**g, reduce="mean", from_s=1, to_s=3), 13 / 3)
        self.assertEqual(self.m(**g, reduce="at_time", time_s=2.5), 4.5)
        self.assertEqual(self.m(**g, reduce="at_time", time_s=2), 6)
        self.assertEqual(self.m(**g, reduce="span_above", threshold=2.5), 2)  # t = 1 .. 3
        self.assertEqual(self.m(**g, reduce="span_below", threshold=2.5), 4)  # t = 0 .. 4
        self.assertEqual(self.m(**g, reduce="first_time_above", threshold=5), 2)
        self.assertEqual(self.m(**g, reduce="final_over_first"), 0.5)
        self.assertEqual(self.m(**g, reduce="max", scale=2, offset=1), 13)
        h = {"file": "gauges.csv", "column": "h.node1.v"}  # -2, -1, 4, 3, 1
        self.assertEqual(self.m(**h, reduce="min", abs=True), 1)
        self.assertEqual(self.m(file="history.csv", column="kinetic_j", reduce="final_over_first",
                                power=0.5), 0.5)
        self.assertEqual(self.m(file="summary.json", key="energy.balance_error"), 1.5e-3)

    def test_judge(self):
        self.assertTrue(cv.judge({"reference": 2.0, "tolerance_rel": 0.05}, 2.09)[2])
        self.assertFalse(cv.judge({"reference": 2.0, "tolerance_rel": 0.05}, 2.11)[2])
        self.assertTrue(cv.judge({"reference": 0.0, "tolerance_abs": 1e-3}, -9e-4)[2])
        self.assertFalse(cv.judge({"reference": 0.0, "tolerance_abs": 1e-3}, 1.1e-3)[2])

    def test_what_cannot_be_measured_says_why(self):
        cases = [
            ({"file": "gauges.csv", "column": "nope.*", "reduce": "final"}, "no column matching"),
            ({"file": "gauges.csv", "column": "g.*.f_x", "reduce": "span_above",
              "threshold": 99}, "never above 99"),
            ({"file": "gauges.csv", "column": "g.*.f_x", "reduce": "at_time", "time_s": 9},
             "outside the rows"),
            ({"file": "gauges.csv", "column": "h.node1.v", "reduce": "min", "power": 0.5},
             "cannot be raised"),
            ({"file": "summary.json", "key": "energy.nope"}, "has no energy.nope"),
            ({"file": "missing.csv", "column": "x", "reduce": "final"}, "cannot read"),
        ]
        for check, text in cases:
            with self.subTest(check=check):
                with self.assertRaises(cv.MeasureError) as e:
                    cv.measure(self.d, check)
                self.assertIn(text, str(e.exception))

    def test_validate_refuses_bad_cases(self):
        good = {"name": "c", "scenario": "c.toml", "check": [
            {"quantity": "q", "file": "gauges.csv", "column": "x", "reduce": "final",
             "reference": 1.0, "tolerance_rel": 0.1}]}
        cv.validate("cases.toml", {"case": [good]})
        bad = [
            ({"reduce": "median"}, "`reduce` must be one of"),
            ({"tolerance_abs": 0.1}, "exactly one of tolerance_rel, tolerance_abs"),
            ({"reference": math.inf}, "finite number"),
            ({"from_s": 1.0}, "from_s and to_s go with reduce"),
            ({"file": "frames.vtu"}, "`file` must be"),
            ({"extra": 1}, "unknown key"),
        ]
        for change, text in bad:
            with self.subTest(change=change):
                check = dict(good["check"][0], **change)
                with self.assertRaises(cv.InputError) as e:
                    cv.validate("cases.toml", {"case": [dict(good, check=[check])]})
                self.assertIn(text, str(e.exception))
        with self.assertRaises(cv.InputError):
            cv.validate("cases.toml", {"case": [good, good]})  # the same name twice


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
