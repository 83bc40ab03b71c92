"""Building blocks of the scenario files the Python tests write, so that a test states only
what its case changes.

A scenario is nested Python dicts in the shape of the TOML file (docs/scenario-format.md): a
dict is a [table], a list of dicts an [[array of tables]], None leaves a key out. `compose_scenario()` assembles
the top-level tables, `part()`, `particle()`, `box()`, `vec()` ... the pieces, and the material
blocks (TNT, SAND, STEEL, ...) carry the values the tests share; `material(BLOCK, key=value)`
is a block with some values changed. `scenario_text()` / `write_scenario()` turn the dicts into
TOML text:

    write_scenario(d / "case.toml", compose_scenario(
        "two-grains", 2, 1e-3, domain=domain([-0.02, -0.02], [0.02, 0.02]),
        materials=[material(SAND, restitution=0.9)],
        parts=[part("grains", "dem", "sand", 0.005, box([-0.01, -0.01], [0.01, 0.01]),
                    particles=approaching_pair(2, 0.0026, 0.0025, 0.5))]))

Floats are written with repr(), which reads back as the same double.
"""
from pathlib import Path

import numpy as np

# ---------------------------------------------------------------------------------------------
# TOML text
# ---------------------------------------------------------------------------------------------

# Keys whose table value is written inline (`region = { type = "box", ... }`).
_INLINE_TABLES = {"region", "initial", "damage"}


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, Path):
        v = str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()
                                if x is not None) + " }"
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"no TOML form for {v!r}")


def _is_table_array(v):
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def _emit(lines, prefix, table):
    # Plain keys first, then sub-tables, then arrays of tables (TOML attaches a [a.b] header
    # to the last element of the enclosing [[a]]).
    subtables, arrays = [], []
    for k, v in table.items():
        if v is None:
            continue
        if isinstance(v, dict) and k not in _INLINE_TABLES:
            subtables.append((k, v))
        elif _is_table_array(v):
            arrays.append((k, v))
        else:
            lines.append(f"{k} = {_toml_value(v)}")
    for k, v in subtables:
        name = f"{prefix}.{k}" if prefix else k
        lines += ["", f"[{name}]"]
        _emit(lines, name, v)
    for k, items in arrays:
        name = f"{prefix}.{k}" if prefix else k
        for item in items:
            lines += ["", f"[[{name}]]"]
            _emit(lines, name, item)


def scenario_text(scenario, comment=""):
    """TOML text of a scenario given as nested dicts: dict values become [tables], lists of
    dicts [[arrays of tables]], `region`, `initial` and `damage` inline tables; None values
    are left out. `comment` (lines) opens the file."""
    lines = [f"# {c}" for c in comment.splitlines()] if comment else []
    _emit(lines, "", scenario)
    return "\n".join(lines).lstrip("\n") + "\n"


def write_scenario(path, scenario, comment=""):
    """Writes scenario_text(scenario, comment) to path (making its directory); returns path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(scenario_text(scenario, comment))
    return path


# ---------------------------------------------------------------------------------------------
# The tables of a scenario
# ---------------------------------------------------------------------------------------------

def compose_scenario(name, dimension, end_time_s, *, domain, materials, parts, description=None,
             time=None, output=None, contacts=None, **tables):
    """A whole scenario: [scenario] (name, description, dimension, end_time_s), [time],
    [output], [domain], [[materials]], [[parts]], [[contacts]] and any further `tables`
    (e.g. probes=...). Tables given as None (or empty) are left out."""
    return {
        "scenario": {"name": name, "description": description, "dimension": dimension,
                     "end_time_s": end_time_s},
        "time": time, "output": output, "domain": domain,
        "materials": list(materials), "parts": list(parts), "contacts": contacts or None,
        **tables,
    }


def output(interval_s, history_every=None):
    """[output]: a frame every interval_s; a history.csv row every history_every steps."""
    return {"interval_s": interval_s, "history_every": history_every}


def domain(min_m, max_m, gravity=None, outflow=None):
    """[domain]: the box [min_m, max_m], gravity [m/s^2] and what happens to what leaves it
    (outflow "stop" or "remove"; None: crater's default)."""
    return {"min_m": min_m, "max_m": max_m, "gravity_m_s2": gravity, "outflow": outflow}


def part(name, method, material, spacing_m=None, region=None, **keys):
    """One [[parts]] entry: its name, method ("sph", "dem", "fem"), material, lattice spacing
    and region, then any further keys (initial=..., dem={...}, fem={...}, particles=[...],
    carve=[...], ...)."""
    return {"name": name, "method": method, "material": material, "spacing_m": spacing_m,
            "region": region, **keys}


def contact(a, b, **keys):
    """One [[contacts]] entry between parts a and b (friction=..., penalty_scale=...)."""
    return {"parts": [a, b], **keys}


# ---------------------------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------------------------

def vec(dim, x, y, z=0.0):
    """[x, y] in 2D, [x, y, z] in 3D."""
    return [x, y] if dim == 2 else [x, y, z]


def box(lo, hi):
    """A box region from its lower and upper corners."""
    return {"type": "box", "min_m": [float(x) for x in lo], "max_m": [float(x) for x in hi]}


def disk(center, radius):
    """A disk (2D) or ball (3D) region."""
    return {"type": "disk", "center_m": [float(x) for x in center], "radius_m": float(radius)}


# ---------------------------------------------------------------------------------------------
# DEM grains and FEM boundaries
# ---------------------------------------------------------------------------------------------

def particle(center_m, radius_m, velocity_m_s=None):
    """One [[parts.particles]] entry: a grain placed by hand."""
    return {"center_m": center_m, "radius_m": radius_m, "velocity_m_s": velocity_m_s}


def approaching_pair(dim, x, radius_m, speed):
    """Two grains on the x axis at -x and +x moving towards each other at `speed` each
    (apart for speed < 0): the head-on collision of the DEM contact tests."""
    return [particle(vec(dim, -x, 0.0), radius_m, vec(dim, speed, 0.0)),
            particle(vec(dim, x, 0.0), radius_m, vec(dim, -speed, 0.0))]


def boundary(type_, face=None, **keys):
    """One [[parts.fem.boundary]] entry (type "fixed", "symmetry", "velocity",
    "non_reflecting") on a face of the part's box, or on a mesh group (group=...)."""
    return {"type": type_, "face": face, **keys}


def symmetry(*faces):
    """Symmetry (roller) conditions on the given faces."""
    return [boundary("symmetry", f) for f in faces]


# ---------------------------------------------------------------------------------------------
# Materials
# ---------------------------------------------------------------------------------------------

def material(block, **changes):
    """A copy of a material block with some values changed (None removes a key)."""
    return {**block, **changes}


# Standard TNT JWL (Dobratz & Crawford 1985, LLNL Explosives Handbook; as scenarios/demo.toml).
TNT = {
    "name": "tnt", "model": "jwl", "rho0_kg_m3": 1630.0, "a_pa": 373.8e9, "b_pa": 3.747e9,
    "r1": 4.15, "r2": 0.90, "omega": 0.35, "e0_j_m3": 6.0e9, "d_cj_m_s": 6930.0,
}

# Air as an ideal gas at 1 kg/m^3 (the SPH gas tests; pressure set per part).
AIR = {"name": "air", "model": "ideal_gas", "rho0_kg_m3": 1.0, "gamma": 1.4}

# The paper's sand grains (scenarios/paper-20cm.toml): Hertz-Mindlin with the given friction
# and restitution.
SAND = {
    "name": "sand", "model": "granular", "rho0_kg_m3": 1920.0, "shear_modulus_pa": 29.0e9,
    "poisson_ratio": 0.2, "friction": 0.84, "restitution": 0.5,
}

# Glass-like beads, soft enough for linear-spring chains and heaps.
BEADS = {
    "name": "beads", "model": "granular", "rho0_kg_m3": 2500.0, "shear_modulus_pa": 1.0e9,
    "poisson_ratio": 0.25, "friction": 0.5, "restitution": 0.5,
}

# Rock grains (quartz density) of a bonded assembly.
ROCK = {
    "name": "rock", "model": "granular", "rho0_kg_m3": 2650.0, "shear_modulus_pa": 1.0e9,
    "poisson_ratio": 0.2, "friction": 0.5, "restitution": 0.5,
}

# Linear elastic steel.
STEEL = {
    "name": "steel", "model": "elastic", "rho0_kg_m3": 7850.0, "youngs_modulus_pa": 200e9,
    "poisson_ratio": 0.3,
}

# The paper's steel plate, Johnson-Cook strength (the paper's Table 3; scenarios/paper-20cm.toml),
# without damage: add damage=STEEL_JC_DAMAGE (or other constants) for failure.
STEEL_JC = {
    **STEEL, "model": "johnson_cook", "a_pa": 50.103e6, "b_pa": 176.091e6, "n": 0.5176,
    "c": 0.095, "m": 0.6622,
}

# The paper's Johnson-Cook failure constants D1-D5 (Table 3).
STEEL_JC_DAMAGE = {"d1": 0.05, "d2": 3.44, "d3": -2.12, "d4": 0.002, "d5": 0.61}
