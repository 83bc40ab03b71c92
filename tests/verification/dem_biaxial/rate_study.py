"""Rate-dependent friction in the biaxial test (issue 24, paper section III-C): the same packing
sheared at two axial strain rates with rate_dependent_friction on (beta 0.05, reference rate
RATE0 below both) and off, to separate the law's friction rise from inertia. Prints the peak
(and the mean over eps_1 = 1-3 %) of the mobilised friction angle per run, the measured rises
and what the law gives at the nominal rates (docs/validation.md, "DEM: biaxial test").

    CRATER_BIN=build/release/bin/crater CRATER_TEST_TMP=/tmp/crater-rates \
        /usr/bin/python3 tests/verification/dem_biaxial/rate_study.py [seed]

About 2-3 minutes per seed on one core (two runs of 0.64 s and two of 0.064 s to 3 % strain);
writes CRATER_TEST_TMP/biaxial_rates_<seed>/rates.json.
"""
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from biaxial_case import angles, reduce, scenario  # noqa: E402
from crater_test import crater, scratch  # noqa: E402
from scenario_blocks import SAND, write_scenario  # noqa: E402

RATES = (0.05, 0.5)  # 1/s: I = 1e-4 and 1e-3
RATE0 = 0.01  # 1/s, friction_reference_strain_rate
BETA = 0.05
STRAIN = 0.03
RAMP_STRAIN = 0.0025


def law_angle(rate):
    """The contact friction angle the law gives at a contact strain rate [deg]."""
    phi_s = math.degrees(math.atan(SAND["friction"]))
    return phi_s * (1 + BETA * math.log10(max(rate / RATE0, 1.0)))


def main(seed=1):
    work = scratch(f"biaxial_rates_{seed}")
    found = {}
    for law in (False, True):
        for rate in RATES:
            name = f"{'law' if law else 'off'}_{rate:g}"
            dem = {"rate_dependent_friction": True, "friction_rate_beta": BETA,
                   "friction_reference_strain_rate": RATE0} if law else None
            # The top's speed ramped over the same strain at both rates (0.25 %, as the
            # biaxial test's 10 ms at 0.25 /s).
            write_scenario(work / f"{name}.toml",
                           scenario(seed, work / "cache", strain_rate=rate, axial_strain=STRAIN,
                                    dem=dem, ramp_s=RAMP_STRAIN / rate))
            crater("run", work / f"{name}.toml", "--out", work / name, "--force", "--quiet",
                   timeout=3600)
            r = reduce(work / name / "history.csv")
            a = angles(r)
            band = (r["e1"] >= 0.01) & (r["e1"] <= STRAIN)
            found[name] = {"phi_peak": a["phi_peak"], "e1_peak": a["e1_peak"],
                           "phi_1_3": float(r["phi"][band].mean()), "psi": a["psi"]}
    lo, hi = RATES
    rise = {k: {"law": found[f"law_{hi:g}"][k] - found[f"law_{lo:g}"][k],
                "off": found[f"off_{hi:g}"][k] - found[f"off_{lo:g}"][k]}
            for k in ("phi_peak", "phi_1_3")}
    predicted_contact = law_angle(hi) - law_angle(lo)
    # If the macroscopic angle scaled as the contact's: phi (1 + beta log10) at both rates.
    base = found[f"off_{lo:g}"]["phi_peak"]
    predicted_macro = base * (law_angle(hi) - law_angle(lo)) / math.degrees(
        math.atan(SAND["friction"]))
    out = {"seed": seed, "runs": found, "rise_deg": rise,
           "law_contact_angle_deg": {f"{r:g}": law_angle(r) for r in RATES},
           "law_contact_rise_deg": predicted_contact,
           "law_rise_if_macro_scales_deg": predicted_macro}
    (work / "rates.json").write_text(json.dumps(out, indent=1))
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1)
