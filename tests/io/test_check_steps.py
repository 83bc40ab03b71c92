"""`crater check`'s table of stable steps: each row shows its stable step and the step it allows
(a part's stability limit times the safety factor; the contacts' accuracy bound as it is), the
contacts' row names the contact that sets it (no 'entity -1'), and the global step line names the
row that allows the smallest step and quotes that step."""
import re
import sys
import unittest

from crater_test import crater

NUMBER = r"[-+]?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|inf)"
ROW = re.compile(rf"^(\S+)\s+(\S+)\s+(\d+)\s+(\S+)\s+({NUMBER})\s+({NUMBER})\s+(.*)$")


def check_table(*args):
    """Runs `crater check`; returns ({row name: (stable, allowed, limited by)}, global line)."""
    out = crater("check", *args).stdout.splitlines()
    head = next(i for i, line in enumerate(out) if line.startswith("part "))
    assert "allowed dt [s]" in out[head], out[head]
    rows = {}
    for line in out[head + 1:]:
        m = ROW.match(line)
        if not m:
            break
        rows[m.group(1)] = (float(m.group(5)), float(m.group(6)), m.group(7))
    glob = next(line for line in out if line.startswith("global step:"))
    return rows, glob


def global_step(line):
    return float(re.match(rf"global step: ({NUMBER}) s", line).group(1))


class CheckSteps(unittest.TestCase):
    def assert_global_is_smallest(self, rows, glob):
        name, (_, allowed, _) = min(rows.items(), key=lambda kv: kv[1][1])
        self.assertEqual(global_step(glob), allowed, glob)
        who = "contacts:" if name == "contacts" else f"part '{name}'"
        self.assertIn(who, glob)
        return name

    def test_contact_limits(self):
        # paper-20cm at a safety factor of 0.9: the charge-plate penalty spring's bound (not
        # scaled) is below 0.9 x every part's stable step.
        rows, glob = check_table("paper-20cm", "--set", "time.safety_factor=0.9")
        self.assertIn("contacts", rows)
        stable, allowed, by = rows["contacts"]
        self.assertEqual(stable, allowed)  # an accuracy bound: not scaled
        self.assertNotIn("entity -1", by)
        self.assertRegex(by, r"^contact '[^']+-[^']+'")  # the pair, e.g. 'charge-plate'
        for name, (s, a, _) in rows.items():
            if name != "contacts":
                self.assertAlmostEqual(a, 0.9 * s, delta=1e-4 * a)
        self.assertEqual(self.assert_global_is_smallest(rows, glob), "contacts")
        self.assertIn(by.split(";")[0], glob)  # the same contact named in both

    def test_part_limits_though_contact_stable_step_is_smaller(self):
        # At the file's 0.2 the soil rules (its smallest grains, 8 mm): 0.2 x its step is below
        # the contacts' bound, though the contacts' stable step is below the soil's.
        rows, glob = check_table("paper-20cm")
        self.assertLess(rows["contacts"][0], rows["soil"][0])
        self.assertNotIn("entity -1", rows["contacts"][2])
        self.assertEqual(self.assert_global_is_smallest(rows, glob), "soil")
        self.assertIn("0.2 x", glob)

    def test_without_contacts(self):
        rows, glob = check_table("demo")
        self.assertEqual(list(rows), ["charge"])
        self.assertEqual(self.assert_global_is_smallest(rows, glob), "charge")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
