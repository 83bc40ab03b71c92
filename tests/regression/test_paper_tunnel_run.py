# ctest-labels: slow
# ctest-processors: 2
# ctest-timeout: 3600
"""The paper-tunnel draft's whole demo run (issue 27's acceptance: "1-vs-2-thread bit
identity"; scenarios/drafts/paper-tunnel.toml): 20 ms on 1 and on 2 threads write
bit-identical frames, history, crown line and summary (tests/regression/test_paper_tunnel.py
checks the first 50 us in `make test`; this run has the products on the lining from 0.77 ms,
the lining's damage and the charge-lining and lining-soil contacts all the way).

Also, on the 1-thread run, what docs/validation.md ("paper-tunnel") quotes:
- the energy balance within the issue's 2 %;
- the crown's outward displacement over the run against the reference's 6.40 cm: reported,
  not asserted (the model's soil and concrete are assumed, see the scenario's header; the
  figure is the issue's open question, not a regression bound), with the soil's on the crown
  line.

Slow: 482 s on one thread and 313 s on two, alone on the machine (13 minutes in all;
`ctest -L slow -R paper_tunnel_run`; 2026-11-27, 24e62f8).
"""
import json
import os
import sys
import unittest
from pathlib import Path

from crater_test import assert_bit_identical_runs, scratch

SOURCE = Path(os.environ.get("CRATER_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SCENARIO = SOURCE / "scenarios" / "drafts" / "paper-tunnel.toml"
REFERENCE_CROWN_M = 0.064  # Dolatshahi & Nouri Qarahasanlou 2023, via the paper's section IV-D


class PaperTunnelRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = scratch("paper_tunnel_run")
        cls.names = assert_bit_identical_runs(SCENARIO, cls.work, sets=["output.interval_s=1e-3"])
        cls.summary = json.loads((Path(cls.work) / "threads1" / "summary.json").read_text())

    def test_outputs_compared(self):
        for name in ("history.csv", "crown_line.csv", "summary.json", "lining.pvd"):
            self.assertIn(name, self.names)

    def test_energy_balance(self):
        self.assertLess(abs(self.summary["energy"]["balance_error"]), 0.02)

    def test_crown(self):
        m = self.summary["metrics"]
        crown = m["lining_crown_displacement_max_m"]
        print(f"crown {crown * 100:.2f} cm against {REFERENCE_CROWN_M * 100:.2f} cm "
              f"({crown / REFERENCE_CROWN_M - 1:+.1%}); soil at the interface "
              f"{m['soil_crown_line_interface_displacement_max_m'] * 100:.2f} cm, at the ground "
              f"{m['soil_crown_line_surface_displacement_max_m'] * 100:.2f} cm")
        self.assertGreater(crown, 0)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
