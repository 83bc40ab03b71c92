"""A grain fired into a rigid wall faster than the Hertz law can stop it within its radius (a
blast does this): the DEM part puts it back in front of the wall with its normal velocity
reversed and scaled by the wall's restitution, counts it in `wall_reflections`, and books the
kinetic energy lost, so the run goes on and its energy balance still closes.

Closed form for the safeguard alone (no contact force acts once the centre is past the face):
the rebound speed is at most e v (the Hertz contact before and after the crossing takes more),
and the tangential velocity is kept. Reference for the Hertz stopping distance:
delta_max = (15 m v^2 / (16 E* sqrt(R)))^(2/5) (Johnson 1985, section 11.4) is 7-10 R at
3000 m/s for this grain (E* of a rigid or of a like wall), so without the safeguard its centre
would cross the floor and the run would stop (exit 3, "grain left the domain").
"""
import sys
import unittest

from crater_test import crater, read_vtu, run_scenario, scratch
from scenario_blocks import (SAND, box, compose_scenario, domain, output, part, particle,
                             scenario_text)

SCENARIO = scenario_text(compose_scenario(
    "wall-safeguard", 2, 2e-5, description="a grain fired into the floor at 3 km/s",
    output=output(1e-5, history_every=1), domain=domain([-0.05, 0.0], [0.05, 0.2]),
    materials=[SAND],
    parts=[part("grain", "dem", "sand", 0.01, box([-0.02, 0.0], [0.02, 0.04]),
                dem={"walls": ["bottom"], "wall_restitution": 0.5},
                particles=[particle([0.0, 0.0052], 0.005, [10.0, -3000.0])])]))


class WallSafeguard(unittest.TestCase):
    def test_grain_driven_through_the_floor_comes_back(self):
        work = scratch("dem_wall_safeguard")
        (work / "case.toml").write_text(SCENARIO)
        s = run_scenario(work / "case.toml", work / "out")
        x, a, _, _ = read_vtu(work / "out" / "grain_000002.vtu")
        v = a["velocity"][0]
        refl = s["parts"][0]["diagnostics"]["wall_reflections"]
        print(f"reflections {refl:.0f}; grain at y = {x[0][1] * 1e3:.2f} mm moving {v[:2]} m/s; "
              f"energy balance {s['energy']['balance_error']:.2e}")
        self.assertGreaterEqual(refl, 1)
        self.assertGreater(x[0][1], 0.0)
        self.assertGreater(v[1], 0.0)
        self.assertLessEqual(v[1], 0.5 * 3000.0 * 1.0001)
        self.assertLess(abs(s["energy"]["balance_error"]), 0.01)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
