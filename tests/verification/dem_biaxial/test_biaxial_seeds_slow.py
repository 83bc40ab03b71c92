# ctest-labels: slow
# ctest-timeout: 1800
# ctest-cost: 145
"""The plane-strain biaxial test of the paper's sand over three packings (seeds 1-3; issue 24's
calibration: the friction angle with its scatter over three packings, docs/validation.md).
Every check of test_biaxial.py (which runs seed 1 in `make test`) for each seed; the three
seeds' peak, residual and dilatancy angles with their mean and standard deviation are printed
and written to CRATER_TEST_TMP/biaxial/angles.json; the figure (plot_biaxial.py) goes to
CRATER_TEST_TMP/figures/dem_biaxial.png, and to docs/figures/ with CRATER_WRITE_FIGURES=1.
About 6.6 minutes beside other jobs.
"""
import json
import sys
import unittest

import numpy as np

import test_biaxial as quick
from biaxial_case import SEEDS


class BiaxialSeeds(quick.Biaxial):
    SEEDS = SEEDS

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        table = {s: {k: v for k, v in a.items() if k != "bins"} for s, a in cls.angles.items()}
        for k in ("phi_peak", "phi_residual", "psi"):
            vals = np.array([table[s][k] for s in cls.SEEDS])
            table[f"{k}_mean"] = float(vals.mean())
            table[f"{k}_std"] = float(vals.std(ddof=1))
        (cls.work / "angles.json").write_text(json.dumps(table, indent=1))
        print(json.dumps(table, indent=1), file=sys.stderr)
        try:
            from plot_biaxial import figure
            figure(cls.runs, cls.angles)
        except ImportError:  # no matplotlib: the figure is skipped (plot_biaxial.py says so)
            pass


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
