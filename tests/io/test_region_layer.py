# ctest-cost: 4
"""The "layer" region (issue 28: a plate's thickness and depth as single keys, for `crater
sweep`): `{ type = "layer", bottom_m = B, thickness_m = T }` is the box across the whole domain
from B to B + T along the vertical axis (y in 2D, z in 3D). Checked against the box it stands
for: the same run bit for bit in 2D (the clamped plate of tests/data), the same element count and
mass from `crater check` in 3D; the bundled paper scenes state their plates as layers, and their
wide level no longer has to restate the plate's box."""
import re
import sys
import unittest
from pathlib import Path

from crater_test import SOURCE_DIR, crater, scratch

PLATE = Path(SOURCE_DIR) / "tests" / "data" / "fem_plate_2d.toml"
BOX_2D = 'region = { type = "box", min_m = [-0.1, -0.01], max_m = [0.1, 0.01] }\n'


def write(name, text):
    d = scratch(f"layer_{name}")
    d.mkdir(parents=True, exist_ok=True)
    (d / "s.toml").write_text(text)
    return d


class LayerRegion(unittest.TestCase):
    def test_2d_layer_is_the_box_across_the_domain(self):
        text = PLATE.read_text()
        self.assertEqual(text.count(BOX_2D), 1)
        layer = text.replace(BOX_2D, 'region = { type = "layer", bottom_m = -0.01, '
                             'thickness_m = 0.02 }\n', 1)
        runs = []
        for name, t in (("box", text), ("layer", layer)):
            d = write(name, t)
            crater("run", d / "s.toml", "--out", d / "out", "--force", "--quiet")
            runs.append((d / "out" / "history.csv").read_bytes())
        self.assertEqual(runs[0], runs[1])

    def test_3d_layer_spans_x_and_y(self):
        def scene(region):
            return f"""[scenario]
name = "layer3d"
dimension = 3
end_time_s = 1e-5
[domain]
min_m = [0.0, 0.0, -1.0]
max_m = [0.4, 0.2, 1.0]
[[materials]]
name = "steel"
model = "elastic"
rho0_kg_m3 = 7850
youngs_modulus_pa = 200e9
poisson_ratio = 0.3
[[parts]]
name = "plate"
method = "fem"
material = "steel"
spacing_m = 0.05
region = {region}
"""
        outs = []
        for name, region in (
                ("box3", '{ type = "box", min_m = [0.0, 0.0, -0.3], max_m = [0.4, 0.2, -0.2] }'),
                ("layer3", '{ type = "layer", bottom_m = -0.3, thickness_m = 0.1 }')):
            d = write(name, scene(region))
            p = crater("check", d / "s.toml")
            row = re.search(r"^plate\s+fem\s+(\d+)\s+([\d.e+-]+)", p.stdout, re.M)
            self.assertIsNotNone(row, p.stdout)
            outs.append(row.groups())
        self.assertEqual(outs[0], outs[1])
        self.assertEqual(outs[0][0], str(8 * 4 * 2))  # 0.4/0.05 x 0.2/0.05 x 0.1/0.05 elements

    def test_thickness_must_be_positive(self):
        text = PLATE.read_text().replace(
            BOX_2D, 'region = { type = "layer", bottom_m = -0.01, thickness_m = 0.0 }\n', 1)
        d = write("bad", text)
        p = crater("check", d / "s.toml", check=False)
        self.assertEqual(p.returncode, 2)
        self.assertIn("parts[0].region.thickness_m", p.stderr)

    def test_paper_scenes_state_their_plates_as_layers(self):
        for name, thickness, elements in (("paper-20cm", "0.2", 4000), ("paper-40cm", "0.4", 8000)):
            text = (Path(SOURCE_DIR) / "scenarios" / f"{name}.toml").read_text()
            self.assertIn('region = { type = "layer", bottom_m = -0.5, thickness_m = '
                          f'{thickness} }}', text)
            p = crater("check", name, "--level", "wide")
            # The wide level's 8 m at 0.02 m: 400 elements across, thickness / 0.02 m through.
            self.assertRegex(p.stdout, rf"(?m)^plate\s+fem\s+{elements}\s")


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)
