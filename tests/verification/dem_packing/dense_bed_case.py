"""The dense bed at rest of issue 24, shared by test_dense_bed.py (its grains stay at rest) and
test_bed_stress.py (its stress): 2D disks of sand, radii 4-10 mm (the paper's coarse range,
2.5:1), filling a 0.6 m x 0.3 m box (top at y = 0) with rigid walls left, right and bottom,
relaxed under gravity to an unbalanced force of 1e-3 of its weight, then run for 10 ms from the
cached packing (contacts' springs included), a frame every 1 ms."""
from scenario_blocks import SAND, box, compose_scenario, domain, output, part

BOX = ([0.0, -0.3], [0.6, 0.0])  # the bed's region [m]
GRAVITY = 9.81  # [m/s^2], along -y


def bed_alone(work):
    """The scenario, its packing cached in work/cache."""
    return compose_scenario(
        "dense-bed-at-rest", 2, 1e-2, domain=domain([0.0, -0.3], [0.6, 0.3], [0.0, -GRAVITY]),
        output=output(1e-3), materials=[SAND],
        parts=[part("soil", "dem", "sand", 0.02, box(*BOX),
                    dem={"radius_min_m": 0.004, "radius_max_m": 0.01,
                         "walls": ["left", "right", "bottom"]},
                    packing={"method": "dense", "settle": True,
                             "cache_dir": str(work / "cache")})])
