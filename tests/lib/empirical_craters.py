"""Empirical apparent-crater relations for explosive charges on or in dry soil/sand.

For comparing crater's 3D run (1814 kg TNT sphere, radius 0.64 m, centre d = 1.2 m deep, dry
sand; a quarter model with symmetry planes, which does not matter here) with published
cratering relations. Numpy only; runs under Debian's /usr/bin/python3.

Units: charge mass W in kg of TNT, depth of burial d in m to the charge *centre*, results in m.
Scaled depth lambda = d / W^(1/3) in m/kg^(1/3) (1 m/kg^(1/3) = 2.520 ft/lb^(1/3)).

Every relation carries a `status`, because most coefficients in this field circulate by
quotation and could not be checked against the original here (docs/empirical-craters.md):

  "verified"    coefficient read in the cited source itself;
  "secondary"   coefficient read only as quoted by others, not in the cited original;
  "unverified"  coefficient neither read in the original nor in a citable quotation.

`band()` uses "verified" and "secondary" relations unless told otherwise. As of this file no
relation is "verified": the sources that hold them (TM 5-855-1, Cooper 1996, Kinney & Graham
1985, Ambrosini et al. 2002, Luccioni et al. 2009, ...) could not be read from here.

All radii are *apparent* (measured at the original ground level, fallback included); none of
the relations knows about the steel plate buried above the charge.
"""
import numpy as np

M_PER_FT = 0.3048
KG_PER_LB = 0.45359237
# 1 m/kg^(1/3) expressed in ft/lb^(1/3)
FT_LB_PER_M_KG = (1.0 / M_PER_FT) * KG_PER_LB ** (1.0 / 3.0)

# The project's case
W_CASE_KG = 1814.0
D_CASE_M = 1.2


def scaled_depth(W, d):
    """Cube-root scaled depth of burial lambda = d / W^(1/3) [m/kg^(1/3)] (d to the charge centre)."""
    W = np.asarray(W, dtype=float)
    return np.asarray(d, dtype=float) / np.cbrt(W)


def scaled_depth_ft_lb(W, d):
    """The same scaled depth in the US units of TM 5-855-1 / Cooper, ft/lb^(1/3)."""
    return scaled_depth(W, d) * FT_LB_PER_M_KG


def scale_dimension(L_ref, W_ref, W, m=3.0):
    """A crater dimension L_ref [m] measured for charge W_ref [kg] scaled to charge W [kg] at the
    same scaled geometry: L = L_ref (W / W_ref)^(1/m).

    m = 3 is cube-root (Hopkinson-Cranz) scaling. Larger exponents m (e.g. 3.4) were used for
    craters from larger charges: the crater-prediction chapter (ch. 4, "Prediction of craters") of
    a 1950s Operation CASTLE crater-survey report, scanned at rminucleardocs.icaad.ngo (entity
    fqcud6nrv7p, scan pages 44 and 57), writes the radius as R = (W E)^(1/m) f(lambda), finds the
    most probable m = 3.4 for TNT craters in Nevada soil, tabulates other m per soil (the dry-sand
    entry is illegible in the scan), and puts the uncertainty of a radius for a given soil, charge
    size and scaled depth at no less than +-10 %.
    """
    return np.asarray(L_ref, dtype=float) * (np.asarray(W, dtype=float) / W_ref) ** (1.0 / m)


# --- relations -------------------------------------------------------------------------------

def kinney_graham_surface(W, d=0.0):
    """Apparent crater of a charge on the ground surface: diameter D = 0.8 W^(1/3)
    (D [m], W [kg TNT]), so radius R = 0.4 W^(1/3); depth not given.

    Source: G. F. Kinney and K. J. Graham, "Explosive Shocks in Air", 2nd ed., Springer, 1985
    (the crater relation for surface bursts; page not checked here). STATUS "secondary": the
    original was not readable from here; the coefficient 0.8 (diameter, m and kg) was seen
    only as a quotation of this book in third-party public code, not in a citable text.
    Validity: charge resting on the surface (lambda ~ 0); soil in general, not dry sand
    specifically; apparent crater. Scatter: not stated in anything read here; the CASTLE-era
    analysis (scale_dimension) puts any single radius at +-10 % or more.
    `d` is accepted for a common signature and ignored: this is not a buried-charge relation.
    Returns (R [m], depth [m] or None).
    """
    return 0.4 * np.cbrt(np.asarray(W, dtype=float)), None


def brief_surface_087(W, d=0.0):
    """Apparent crater diameter D = 0.87 W^(1/3) (m, kg TNT) for charges on the surface, as the
    crater project's brief attributes to Ambrosini, Luccioni et al. (e.g. D. Ambrosini,
    B. Luccioni, R. Danesi, J. Riera, M. Rocha, "Size of craters produced by explosive charges
    on or above the ground surface", Shock Waves 12 (2002) 69-78).

    STATUS "unverified": neither the paper nor a quotation of this coefficient could be read
    here. Kept only so that the number is visible next to the others; `band()` leaves it out
    unless asked. Validity as kinney_graham_surface. Returns (R [m], None).
    """
    return 0.435 * np.cbrt(np.asarray(W, dtype=float)), None


RELATIONS = {
    "kinney_graham_1985_surface": {
        "function": kinney_graham_surface,
        "status": "secondary",
        "kind": "surface charge (lambda ~ 0), apparent crater",
        "source": "Kinney & Graham (1985), Explosive Shocks in Air, 2nd ed.: D = 0.8 W^(1/3) m",
    },
    "brief_0.87_surface": {
        "function": brief_surface_087,
        "status": "unverified",
        "kind": "surface charge (lambda ~ 0), apparent crater",
        "source": "D = 0.87 W^(1/3) m as attributed in the brief to Ambrosini/Luccioni et al.",
    },
}


def band(W=W_CASE_KG, d=D_CASE_M, statuses=("verified", "secondary")):
    """Each relation's apparent radius and depth for (W [kg], d [m]) and the min-max band over
    the relations whose status is in `statuses`.

    Returns a dict: lambda_m_kg (m/kg^(1/3)), lambda_ft_lb (ft/lb^(1/3)), relations (name ->
    {radius_m, depth_m, status, kind, source, in_band}), radius_min_m/radius_max_m and
    depth_min_m/depth_max_m over the relations in the band (None where no relation gives one).
    """
    out = {
        "W_kg": float(W),
        "d_m": float(d),
        "lambda_m_kg": float(scaled_depth(W, d)),
        "lambda_ft_lb": float(scaled_depth_ft_lb(W, d)),
        "relations": {},
    }
    radii, depths = [], []
    for name, rel in RELATIONS.items():
        R, D = rel["function"](W, d)
        in_band = rel["status"] in statuses
        out["relations"][name] = {
            "radius_m": float(R),
            "depth_m": None if D is None else float(D),
            "status": rel["status"],
            "kind": rel["kind"],
            "source": rel["source"],
            "in_band": in_band,
        }
        if in_band:
            radii.append(float(R))
            if D is not None:
                depths.append(float(D))
    out["radius_min_m"] = min(radii) if radii else None
    out["radius_max_m"] = max(radii) if radii else None
    out["depth_min_m"] = min(depths) if depths else None
    out["depth_max_m"] = max(depths) if depths else None
    return out


if __name__ == "__main__":
    b = band(statuses=("verified", "secondary", "unverified"))
    print(f"W = {b['W_kg']:.0f} kg TNT, d = {b['d_m']:.2f} m: lambda = {b['lambda_m_kg']:.4f} m/kg^(1/3)"
          f" = {b['lambda_ft_lb']:.3f} ft/lb^(1/3)")
    for name, r in b["relations"].items():
        depth = "-" if r["depth_m"] is None else f"{r['depth_m']:.2f}"
        print(f"  {name:28s} R_a = {r['radius_m']:.2f} m  depth = {depth}  [{r['status']}]")
    print(f"  band (all statuses): R_a {b['radius_min_m']:.2f}-{b['radius_max_m']:.2f} m")
