#!/usr/bin/python3
"""The equivalent blast pressure of scenarios/paper-fem-only.toml, from a hybrid run.

    tools/equivalent_pressure.py HISTORY_CSV [WIDTH_M] [PLATE]

Reads history.csv of a paper-20cm run (demo level: `crater run paper-20cm --out DIR`) and
prints the `time_s` / `pressure_pa` arrays of the plate's pressure load:

    p_eq(t) = max(0, F_y(charge -> plate) + F_y(soil -> plate)) / W

the upward force the hybrid model's products and grains put on the plate (N per metre of
depth), spread over the strip of the plate's bottom face above the charge, W = 1.28 m (the
charge's diameter). Averaged over bins (20 us to 1 ms, 100 us after) so that the impulse of
each bin is kept; negative net forces (the soil above holding the plate back, which the FEM-only
model has as a part of its own) are set to zero.
"""
import csv
import sys
import textwrap

import numpy as np


def main():
    path = sys.argv[1]
    width = float(sys.argv[2]) if len(sys.argv) > 2 else 1.28
    plate = sys.argv[3] if len(sys.argv) > 3 else "plate"
    with open(path) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["time_s"]) for r in rows])
    force = np.zeros_like(t)
    for col in rows[0]:
        if col.startswith("force_") and col.endswith(f"-{plate}_y"):
            force += np.array([float(r[col]) for r in rows])
    edges = np.concatenate([np.arange(0, 1e-3, 2e-5), np.arange(1e-3, t[-1] + 1e-9, 1e-4)])
    times, pressures = [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        grid = np.linspace(lo, hi, 201)
        mean = np.trapz(np.interp(grid, t, force), grid) / (hi - lo)
        times.append(0.5 * (lo + hi))
        pressures.append(max(0.0, mean) / width)
    # Start from zero at t = 0 and end at zero at the last time.
    times = [0.0] + times + [float(edges[-1])]
    pressures = [0.0] + pressures + [0.0]
    impulse = np.trapz(np.maximum(force, 0), t)
    print(f"# from {path}: impulse of the positive net force {impulse:.4g} N s/m, "
          f"table impulse x W {np.trapz(pressures, times) * width:.4g} N s/m")
    for name, values in (("time_s", times), ("pressure_pa", pressures)):
        body = textwrap.fill(", ".join(f"{x:.4g}" for x in values), width=94,
                             initial_indent="  ", subsequent_indent="  ")
        print(f"{name} = [\n{body},\n]")


if __name__ == "__main__":
    main()
