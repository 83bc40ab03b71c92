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

SCENARIO = """
[scenario]
name = "wall-safeguard"
description = "a grain fired into the floor at 3 km/s"
dimension = 2
end_time_s = 2e-5
[output]
interval_s = 1e-5
history_every = 1
[domain]
min_m = [-0.05, 0.0]
max_m = [0.05, 0.2]
[[materials]]
name = "sand"
model = "granular"
rho0_kg_m3 = 1920
shear_modulus_pa = 29e9
poisson_ratio = 0.2
friction = 0.84
restitution = 0.5
[[parts]]
name = "grain"
method = "dem"
material = "sand"
spacing_m = 0.01
region = { type = "box", min_m = [-0.02, 0.0], max_m = [0.02, 0.04] }
[parts.dem]
walls = ["bottom"]
wall_restitution = 0.5
[[parts.particles]]
center_m = [0.0, 0.0052]
radius_m = 0.005
velocity_m_s = [10.0, -3000.0]
"""


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
