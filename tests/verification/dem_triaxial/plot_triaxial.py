"""The figure of the triaxial test (docs/figures/dem_triaxial.png): mobilised friction angle,
stresses and volumetric strain against axial strain, one line per packing, with the peak and
residual marked. test_triaxial.py calls figure() after its runs; run alone, it reduces the
runs a previous test left in CRATER_TEST_TMP/triaxial:

    CRATER_TEST_TMP=build/release/tests/tmp /usr/bin/python3 \
        tests/verification/dem_triaxial/plot_triaxial.py

(with CRATER_WRITE_FIGURES=1 the PNG is copied to docs/figures/). matplotlib missing: the
figure is skipped, unless CRATER_WRITE_FIGURES=1 asked for it (sph_profiles.pyplot).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "lib"))
from sph_profiles import pyplot, save_figure  # noqa: E402
from triaxial_case import (PSI_WINDOW, RESIDUAL, SEEDS, SIGMA3_PA, angles,  # noqa: E402
                           reduce)


def figure(runs, found):
    plt = pyplot()
    if plt is None:
        return None
    fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(7, 9.5), sharex=True,
                                        gridspec_kw={"height_ratios": [3, 2, 2]})
    for seed, r in runs.items():
        a = found[seed]
        line, = ax1.plot(100 * r["e1"], r["phi"], lw=0.5, alpha=0.5)
        c, m = a["bins"]
        ax1.plot(100 * c, m, color=line.get_color(), lw=1.8,
                 label=f"seed {seed}: peak {a['phi_peak']:.1f}°, residual "
                       f"{a['phi_residual']:.1f}°, ψ {a['psi']:.1f}°")
        ax1.plot(100 * a["e1_peak"], a["phi_peak"], "o", color=line.get_color())
        ax2.plot(100 * r["e1"], r["s1"] / 1e3, color=line.get_color(), lw=1.0)
        ax2.plot(100 * r["e1"], r["s3"] / 1e3, color=line.get_color(), lw=1.0, ls="--")
        ax3.plot(100 * r["e1"], 100 * r["ev"], color=line.get_color(), lw=1.2)
    ax1.axvspan(100 * RESIDUAL[0], 100 * RESIDUAL[1], color="0.9", zorder=0)
    ax1.axhspan(35, 45, color="tab:green", alpha=0.12, zorder=0,
                label="dense dry sand, 35–45° (Bolton 1986)")
    ax1.axhspan(30, 40, facecolor="none", edgecolor="tab:red", hatch="//", lw=0, alpha=0.4,
                zorder=0, label="3D DEM, dense frictional spheres, 30–40° (test's band)")
    ax1.set_ylabel("mobilised friction angle φ [°]")
    ax1.set_ylim(0, 50)
    ax1.legend(fontsize=7, loc="lower right")
    ax1.set_title(f"Triaxial compression, paper's sand (μ = 0.84, spheres), σ₃ = "
                  f"{SIGMA3_PA / 1e3:.0f} kPa, ~1,100 spheres")
    ax2.set_ylabel("σ₁ (solid), σ₃ (dashed) [kPa]")
    ax3.axvspan(100 * PSI_WINDOW[0], 100 * PSI_WINDOW[1], color="0.9", zorder=0)
    ax3.set_xlabel("axial strain ε₁ [%]")
    ax3.set_ylabel("volumetric strain ε_v [%]\n(compression > 0)")
    for ax in (ax1, ax2, ax3):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, "dem_triaxial")


if __name__ == "__main__":
    import os
    work = Path(os.environ.get("CRATER_TEST_TMP", "/tmp")) / "triaxial"
    runs = {s: reduce(work / f"seed{s}" / "history.csv") for s in SEEDS}
    print(figure(runs, {s: angles(r) for s, r in runs.items()}))
