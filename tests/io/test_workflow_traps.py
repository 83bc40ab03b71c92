# ctest-cost: 5
"""Issue 28's traps of the scenario format, each removed (the bad-input halves are in
tests/scenarios/bad/: jc_heating_without_*.toml, fem_initial_temperature_without_temperature.toml).

- One initial temperature: a Johnson-Cook part starts at its material's room_temperature_k
  (it used to start at parts.fem.initial_temperature_k's own default of 293.15 K, whatever the
  material said); a part that states another temperature gets a warning naming both.
- Hourglass coefficients by form: unset, 0.1 with the viscous form (LS-DYNA's default) and 0.05
  with the stiffness form (it used to be 0.1 for both, which stiffens large plastic flow in the
  stiffness form): a run without the key is bit for bit the run that states that value.
- [domain] is optional in an FEM-only scenario: the clamped plate without it runs bit for bit as
  with it (its domain bounded nothing). What needs the box (SPH and DEM parts, symmetry planes,
  a layer region) is refused without it: tests/scenarios/bad/domain_*.toml,
  layer_without_domain.toml.
- Grains placed by hand ([[parts.particles]]) need neither spacing_m nor region: a head-on
  collision of two grains without them runs bit for bit as with them (where they are now
  warned about as unused).
"""
import sys
import unittest
from pathlib import Path

import numpy as np

from crater_test import SOURCE_DIR, crater, read_vtu_cells, scratch
from scenario_blocks import (SAND, approaching_pair, box, compose_scenario, domain, material, part,
                             write_scenario)

PLATE = str(Path(SOURCE_DIR) / "tests" / "data" / "fem_plate_2d.toml")
# Copper's heating constants (Johnson & Cook 1983): the plate heats, so temperature is written.
COPPER_HEAT = ["materials.0.thermal_softening=true", "materials.0.melt_temperature_k=1356",
               "materials.0.specific_heat_j_kg_k=383", "scenario.end_time_s=1e-5"]


def sets(*xs):
    return [a for x in xs for a in ("--set", x)]


class InitialTemperature(unittest.TestCase):
    def first_frame_temperature(self, out):
        return read_vtu_cells(out / "plate_000000.vtu")["temperature"]

    def test_part_starts_at_its_materials_room_temperature(self):
        out = scratch("trap_t0_room")
        p = crater("run", PLATE, "--out", out, "--force", *sets(*COPPER_HEAT,
                   "materials.0.room_temperature_k=300"))
        t = self.first_frame_temperature(out)
        self.assertTrue(np.all(t == 300.0), t[:5])
        self.assertNotIn("room_temperature_k", p.stderr)

    def test_another_start_temperature_is_warned_about(self):
        out = scratch("trap_t0_own")
        p = crater("run", PLATE, "--out", out, "--force", *sets(*COPPER_HEAT,
                   "materials.0.room_temperature_k=300", "parts.0.fem.initial_temperature_k=350"))
        self.assertTrue(np.all(self.first_frame_temperature(out) == 350.0))
        self.assertIn("part 'plate' starts at 350 K, not at its material's "
                      "room_temperature_k = 300 K", p.stderr)


class HourglassDefaults(unittest.TestCase):
    def history(self, name, text):
        d = scratch(f"trap_hg_{name}")
        d.mkdir(parents=True, exist_ok=True)
        (d / "plate.toml").write_text(text)
        crater("run", d / "plate.toml", "--out", d / "out", "--force", "--quiet")
        return (d / "out" / "history.csv").read_bytes()

    def test_each_form_has_its_own_default(self):
        text = Path(PLATE).read_text()
        self.assertIn('hourglass = "stiffness"\nhourglass_coefficient = 0.05\n', text)
        for form, value in (("stiffness", "0.05"), ("viscous", "0.1")):
            with self.subTest(form=form):
                stated = text.replace('hourglass = "stiffness"\nhourglass_coefficient = 0.05\n',
                                      f'hourglass = "{form}"\nhourglass_coefficient = {value}\n')
                unset = text.replace('hourglass = "stiffness"\nhourglass_coefficient = 0.05\n',
                                     f'hourglass = "{form}"\n')
                other = text.replace('hourglass = "stiffness"\nhourglass_coefficient = 0.05\n',
                                     f'hourglass = "{form}"\nhourglass_coefficient = 0.2\n')
                self.assertEqual(self.history(f"{form}_unset", unset),
                                 self.history(f"{form}_stated", stated))
                # The coefficient matters in this run (the comparison can fail).
                self.assertNotEqual(self.history(f"{form}_unset", unset),
                                    self.history(f"{form}_other", other))


class DomainOptionalForFem(unittest.TestCase):
    def test_fem_only_without_domain(self):
        text = Path(PLATE).read_text()
        start, end = text.index("[domain]"), text.index("[[materials]]")
        self.assertIn("min_m", text[start:end])
        d = scratch("trap_no_domain")
        d.mkdir(parents=True, exist_ok=True)
        (d / "plate.toml").write_text(text[:start] + text[end:])
        histories = []
        for name, scene in (("without", d / "plate.toml"), ("with", PLATE)):
            crater("run", scene, "--out", d / name, "--force", "--quiet", "--set",
                   "probes.plate=plate")
            histories.append((d / name / "history.csv").read_bytes())
        self.assertEqual(histories[0], histories[1])


class HandPlacedGrains(unittest.TestCase):
    def test_no_spacing_nor_region(self):
        d = scratch("trap_hand_placed")
        d.mkdir(parents=True, exist_ok=True)

        def scene(**lattice):
            return compose_scenario(
                "two-grains", 2, 2e-4, domain=domain([-0.02, -0.02], [0.02, 0.02]),
                materials=[material(SAND)],
                parts=[part("grains", "dem", "sand",
                            particles=approaching_pair(2, 0.0026, 0.0025, 0.5), **lattice)])

        write_scenario(d / "bare.toml", scene())
        write_scenario(d / "lattice.toml", scene(spacing_m=0.005,
                                                 region=box([-0.01, -0.01], [0.01, 0.01])))
        runs = {}
        for name in ("bare", "lattice"):
            p = crater("run", d / f"{name}.toml", "--out", d / name, "--force")
            runs[name] = ((d / name / "history.csv").read_bytes(), p.stderr)
        self.assertEqual(runs["bare"][0], runs["lattice"][0])
        self.assertNotIn("is not used", runs["bare"][1])
        for k in ("spacing_m", "region"):
            self.assertIn(f"part 'grains': {k} is not used", runs["lattice"][1])


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
