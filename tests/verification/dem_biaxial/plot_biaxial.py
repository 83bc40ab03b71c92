"""The figure of the biaxial test (docs/figures/dem_biaxial.png): mobilised friction angle and
volumetric strain against axial strain, one line per packing, with the peak and residual
marked. test_biaxial_seeds_slow.py calls figure() after its runs; run alone, it reduces the
runs a previous test left in CRATER_TEST_TMP/biaxial:

    CRATER_TEST_TMP=build/release/tests/tmp /usr/bin/python3 \
        tests/verification/dem_biaxial/plot_biaxial.py

(with CRATER_WRITE_FIGURES=1 the PNG is copied to docs/figures/). matplotlib missing: the
figure is skipped, unless CRATER_WRITE_FIGURES=1 asked for it (sph_profiles.pyplot).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from biaxial_case import RESIDUAL, SEEDS, SIGMA3_PA, angles, reduce  # noqa: E402
from sph_profiles import pyplot, save_figure  # noqa: E402


def figure(runs, found):
    plt = pyplot()
    if plt is None:
        return None
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True)
    for seed, r in runs.items():
        a = found[seed]
        line, = ax1.plot(100 * r["e1"], r["phi"], lw=0.5, alpha=0.5)
        c, m = a["bins"]
        ax1.plot(100 * c, m, color=line.get_color(), lw=1.8,
                 label=f"seed {seed}: peak {a['phi_peak']:.1f}°, residual "
                       f"{a['phi_residual']:.1f}°, ψ {a['psi']:.1f}°")
        ax1.plot(100 * a["e1_peak"], a["phi_peak"], "o", color=line.get_color())
        ax2.plot(100 * r["e1"], 100 * r["ev"], color=line.get_color(), lw=1.2)
    ax1.axvspan(100 * RESIDUAL[0], 100 * RESIDUAL[1], color="0.9", zorder=0)
    ax1.axhspan(35, 45, color="tab:green", alpha=0.12, zorder=0,
                label="dense dry sand, 35–45° (Bolton 1986)")
    ax1.set_ylabel("mobilised friction angle φ [°]")
    ax1.set_ylim(0, 50)
    ax1.legend(fontsize=7, loc="upper right")
    ax1.set_title(f"Plane-strain biaxial test, paper's sand (μ = 0.84), σ₃ = "
                  f"{SIGMA3_PA / 1e3:.0f} kPa, ~400 disks")
    ax2.set_xlabel("axial strain ε₁ [%]")
    ax2.set_ylabel("volumetric strain ε_v [%] (compression > 0)")
    ax2.grid(alpha=0.3)
    ax1.grid(alpha=0.3)
    return save_figure(fig, "dem_biaxial")


if __name__ == "__main__":
    import os
    work = Path(os.environ.get("CRATER_TEST_TMP", "/tmp")) / "biaxial"
    runs = {s: reduce(work / f"seed{s}" / "history.csv") for s in SEEDS}
    print(figure(runs, {s: angles(r) for s, r in runs.items()}))
