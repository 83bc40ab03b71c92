#!/usr/bin/python3
"""Writes the hexahedral meshes of scenarios/paper-tunnel.toml (the paper's section IV-D: a
circular tunnel, inner diameter 6.8 m, concrete lining 0.35 m, in soil) with Gmsh's Python API
(Debian: python3-gmsh).

The model is a quarter: x >= 0 (the vertical plane through the tunnel's axis) and y >= 0 (the
cross-section through the charge) are planes of symmetry. The axis runs along y at x = z = 0; z
is up, the ground surface at z = top_m.

The cross-section (x-z) is meshed in quadrangles and extruded along y in layers, so every
element is an 8-node hexahedron: the lining's half ring structured (`--thickness` elements
through the wall, about `--size` around it), the soil around it unstructured and growing from
the lining's size at the ring to `--far` at the model's corners (Gmsh's frontal-Delaunay
triangles recombined into quadrangles; the script stops if any triangle is left). Along y the layers grow geometrically from `--size`
at the charge's section to at most `--far`.

Physical groups (names used by the scenario):
  volumes:  lining, soil
  surfaces: lining_inner (the tunnel's wall, r = 3.4 m), lining_outer, soil_inner (the two
            faces of the lining-soil interface: coincident nodes, two parts), sym_x (x = 0),
            sym_y (y = 0), soil_side (x = width), soil_bottom, ground (z = top), far_end
            (y = length, lining and soil)

Usage: tools/mesh/tunnel.py --level demo   (writes scenarios/meshes/paper-tunnel-demo.msh)
"""
import argparse
import math
import sys
from pathlib import Path

import gmsh

LEVELS = {
    # lining element size around the ring, elements through its thickness, far size [m]
    "demo": dict(size=0.30, thickness=3, far=2.0),
    "medium": dict(size=0.15, thickness=5, far=1.2),
}
R_IN, T = 3.4, 0.35  # the paper's: inner diameter 6.8 m, lining 0.35 m
R_OUT = R_IN + T


def layers(length, first, far, ratio=1.15):
    """Layer thicknesses along y: first, growing by `ratio` up to far, summing to length."""
    out, h = [], first
    while sum(out) + h < length:
        out.append(h)
        h = min(h * ratio, far)
    out[-1] += length - sum(out)
    return out


def build(size, thickness, far, width, top, bottom, length):
    occ = gmsh.model.occ
    # The half ring (x >= 0) and the soil's rectangle less the ring's outer disk, in x-z (y = 0).
    outer = occ.addDisk(0, 0, 0, R_OUT, R_OUT)
    inner = occ.addDisk(0, 0, 0, R_IN, R_IN)
    half = occ.addRectangle(0, -R_OUT - 1, 0, R_OUT + 1, 2 * R_OUT + 2)
    ring, _ = occ.cut([(2, outer)], [(2, inner)], removeTool=True, removeObject=False)
    lining, _ = occ.intersect(ring, [(2, half)])
    box = occ.addRectangle(0, -bottom, 0, width, top + bottom)
    soil, _ = occ.cut([(2, box)], [(2, outer)])
    occ.fragment(lining, soil)
    occ.rotate(occ.getEntities(2), 0, 0, 0, 1, 0, 0, math.pi / 2)  # x-y plane -> x-z plane
    occ.synchronize()

    surfaces = [t for _, t in gmsh.model.getEntities(2)]
    def is_lining(s):
        x, y, z = occ.getCenterOfMass(2, s)
        return math.hypot(x, z) < R_OUT
    lining_s = [s for s in surfaces if is_lining(s)]
    soil_s = [s for s in surfaces if not is_lining(s)]

    # The ring: structured, `thickness` elements through the wall.
    # The arcs may come in pieces (a circle's seam): each piece gets its share of the
    # elements around, the same on the inner and the outer arc (by angle).
    for _, c in gmsh.model.getBoundary([(2, s) for s in lining_s], oriented=False):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(1, c)
        if abs(x1 - x0) < 1e-6:  # a segment on x = 0, through the wall
            gmsh.model.mesh.setTransfiniteCurve(c, thickness + 1)
            continue
        radius = max(abs(x1), abs(z0), abs(z1))
        angle = occ.getMass(1, c) / radius
        gmsh.model.mesh.setTransfiniteCurve(c, max(2, round(angle * (R_IN + T / 2) / size)) + 1)
    corners = []
    for _, p in gmsh.model.getEntities(0):
        x, y, z = gmsh.model.getValue(0, p, [])
        if abs(x) < 1e-6 and (abs(abs(z) - R_IN) < 1e-6 or abs(abs(z) - R_OUT) < 1e-6):
            corners.append(p)
    for s in lining_s:
        gmsh.model.mesh.setTransfiniteSurface(s, cornerTags=corners)
        gmsh.model.mesh.setRecombine(2, s)
    # The soil: the ring's size at the ring, `far` at the model's corners, Gmsh's
    # interpolation between.
    for _, p in gmsh.model.getEntities(0):
        x, y, z = gmsh.model.getValue(0, p, [])
        gmsh.model.mesh.setSize([(0, p)], size if math.hypot(x, z) < R_OUT + 1e-6 else far)
    for s in soil_s:
        gmsh.model.mesh.setRecombine(2, s)
    gmsh.option.setNumber("Mesh.Algorithm", 6)  # frontal-Delaunay
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)

    # Extrude the section along y in layers.
    hs = layers(length, size, far)
    total = sum(hs)
    heights, acc = [], 0.0
    for h in hs:
        acc += h
        heights.append(acc / total)
    out = occ.extrude([(2, s) for s in surfaces], 0, length, 0, [1] * len(hs), heights,
                      recombine=True)
    occ.synchronize()
    vols = [t for d, t in out if d == 3]
    lining_v = [v for v in vols if math.hypot(*(occ.getCenterOfMass(3, v)[i] for i in (0, 2))) < R_OUT]
    soil_v = [v for v in vols if v not in lining_v]
    return lining_v, soil_v, width, top, bottom, length


def groups(lining_v, soil_v, width, top, bottom, length):
    eps = 1e-6
    def faces(vols):
        return [t for _, t in gmsh.model.getBoundary([(3, v) for v in vols], oriented=False)]
    named = {}
    def add(name, tag):
        named.setdefault(name, []).append(tag)
    for owner, vols in (("lining", lining_v), ("soil", soil_v)):
        for s in faces(vols):
            x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, s)
            x, y, z = gmsh.model.occ.getCenterOfMass(2, s)
            r = math.hypot(x0 if abs(x1 - x0) < eps else x, z)
            if x1 < eps:
                add("sym_x", s)
            elif y1 < eps:
                add("sym_y", s)
            elif y0 > length - eps:
                add("far_end", s)
            elif owner == "soil" and x0 > width - eps:
                add("soil_side", s)
            elif owner == "soil" and z1 < -bottom + eps:
                add("soil_bottom", s)
            elif owner == "soil" and z0 > top - eps:
                add("ground", s)
            else:
                # A curved face: the ring's inner or outer wall.
                radius = max(abs(x1), abs(z1), abs(z0))
                if owner == "lining":
                    add("lining_inner" if radius < R_IN + T / 2 else "lining_outer", s)
                else:
                    add("soil_inner", s)
    def physical(dim, tags, name):
        gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
    physical(3, lining_v, "lining")
    physical(3, soil_v, "soil")
    for name, tags in named.items():
        physical(2, sorted(set(tags)), name)
    return named


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", choices=sorted(LEVELS), default="demo")
    ap.add_argument("--width", type=float, default=20.0, help="x extent from the axis [m]")
    ap.add_argument("--top", type=float, default=13.75, help="ground surface above the axis [m]")
    ap.add_argument("--bottom", type=float, default=20.0, help="model's base below the axis [m]")
    ap.add_argument("--length", type=float, default=15.0, help="half length along the axis [m]")
    ap.add_argument("--out", type=Path, help="output .msh (default scenarios/meshes/)")
    a = ap.parse_args()
    out = a.out or Path(__file__).resolve().parents[2] / "scenarios" / "meshes" / f"paper-tunnel-{a.level}.msh"
    gmsh.initialize(["-nt", "1"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("paper-tunnel")
    lv, sv, *dims = build(**LEVELS[a.level], width=a.width, top=a.top, bottom=a.bottom,
                          length=a.length)
    named = groups(lv, sv, *dims)
    gmsh.model.mesh.generate(3)
    types, tags, _ = gmsh.model.mesh.getElements(3)
    if list(types) != [5]:
        sys.exit(f"tunnel.py: expected only hexahedra, got element types {list(types)}")
    # OpenCASCADE leaves the planes' nodes some 1e-13 m off them: put them on.
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    for tag, x in zip(node_tags, coords.reshape(-1, 3)):
        snapped = [0.0 if abs(v) < 1e-9 else v for v in x]
        if any(a != b for a, b in zip(snapped, x)):
            gmsh.model.mesh.setNode(int(tag), snapped, [])
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    out.parent.mkdir(parents=True, exist_ok=True)
    gmsh.write(str(out))
    print(f"{out}: {len(tags[0])} hexahedra; groups {', '.join(sorted(named))}")
    gmsh.finalize()


if __name__ == "__main__":
    main()
