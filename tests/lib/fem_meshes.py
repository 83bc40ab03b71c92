"""Meshes for crater's FEM tests, written as Gmsh MSH 4.1 ASCII files (the format crater reads
with fem.mesh_file). Independent of crater's own structured generator."""
import math

import numpy as np


def quarter_cylinder_hex(radius, length, core_cells, ring_cells, layers):
    """Hexahedra filling the quarter cylinder x >= 0, z >= 0, 0 <= y <= length (axis y) as an
    O-grid ("butterfly"): a square core [0, a]^2 (a = radius / 2) of core_cells^2 cells and two
    blocks of core_cells x ring_cells cells between the core and the arc. Returns (nodes Nx3,
    hexes Mx8 zero-based, VTK/Gmsh order with positive volume)."""
    a = 0.5 * radius
    n, m = core_cells, ring_cells
    section = {}  # (block, i, j) -> 2D point; shared points merged by coordinates below
    pts2d, index = [], {}

    def add(p):
        key = (round(p[0] / radius * 1e9), round(p[1] / radius * 1e9))
        if key not in index:
            index[key] = len(pts2d)
            pts2d.append(p)
        return index[key]

    quads = []
    # Core.
    core = [[add((a * i / n, a * j / n)) for j in range(n + 1)] for i in range(n + 1)]
    for i in range(n):
        for j in range(n):
            quads.append((core[i][j], core[i + 1][j], core[i + 1][j + 1], core[i][j + 1]))
    # Ring blocks: k = 0 along the core's edge x = a, k = 1 along its edge z = a.
    for block in range(2):
        grid = []
        for i in range(n + 1):
            t = i / n
            if block == 0:
                inner = np.array((a, a * t))
                theta = t * math.pi / 4
            else:
                inner = np.array((a * t, a))
                theta = math.pi / 2 - t * math.pi / 4
            outer = radius * np.array((math.cos(theta), math.sin(theta)))
            grid.append([add(tuple(inner + (outer - inner) * r / m)) for r in range(m + 1)])
        for i in range(n):
            for r in range(m):
                quads.append((grid[i][r], grid[i + 1][r], grid[i + 1][r + 1], grid[i][r + 1]))
    pts2d = np.array(pts2d)
    ns = len(pts2d)
    nodes = []
    for layer in range(layers + 1):
        y = length * layer / layers
        for x, z in pts2d:
            nodes.append((x, y, z))
    nodes = np.array(nodes)
    hexes = []
    for layer in range(layers):
        lo, hi = layer * ns, (layer + 1) * ns
        for q in quads:
            h = [lo + q[0], lo + q[1], lo + q[2], lo + q[3], hi + q[0], hi + q[1], hi + q[2], hi + q[3]]
            if hex_volume(nodes[h]) < 0:
                h = [h[0], h[3], h[2], h[1], h[4], h[7], h[6], h[5]]
            hexes.append(h)
    return nodes, np.array(hexes)


def hex_volume(x):
    """Signed volume of a hexahedron (VTK order) as the sum of five tetrahedra."""
    tets = ((0, 1, 3, 4), (1, 2, 3, 6), (1, 3, 4, 6), (3, 4, 6, 7), (1, 4, 5, 6))
    v = 0.0
    for t in tets:
        p = x[list(t)]
        v += np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0])) / 6.0
    return v


def rectangle_quads(lo, hi, cells, clockwise=False):
    """A structured quadrilateral mesh of the rectangle lo..hi (2D, z = 0) with cells = (nx, ny),
    nodes row by row from the lower-left corner. Returns (nodes Nx3, quads Mx4 zero-based,
    counter-clockwise unless `clockwise`, {face name: [2-node lines]} for the four sides)."""
    nx, ny = cells
    xs = np.linspace(lo[0], hi[0], nx + 1)
    ys = np.linspace(lo[1], hi[1], ny + 1)
    nodes = np.array([(x, y, 0.0) for y in ys for x in xs])
    idx = lambda i, j: j * (nx + 1) + i
    quads = []
    for j in range(ny):
        for i in range(nx):
            q = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
            quads.append(q[::-1] if clockwise else q)
    sides = {
        "left": [(idx(0, j), idx(0, j + 1)) for j in range(ny)],
        "right": [(idx(nx, j), idx(nx, j + 1)) for j in range(ny)],
        "bottom": [(idx(i, 0), idx(i + 1, 0)) for i in range(nx)],
        "top": [(idx(i, ny), idx(i + 1, ny)) for i in range(nx)],
    }
    return nodes, np.array(quads), sides


def write_msh41(path, nodes, blocks):
    """Writes a Gmsh MSH 4.1 ASCII file. `blocks` = [(dim, gmsh element type, physical name,
    elements as rows of zero-based node indices)]; each block is one geometric entity of its
    dimension in its own physical group (types: 1 line, 2 triangle, 3 quadrangle, 5 hexahedron).
    All nodes are written in one block of the highest dimension's first entity."""
    top = max(b[0] for b in blocks)
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    box = " ".join(f"{v:.17g}" for v in (*lo, *hi))
    entity_tag, counts, names = [], [0, 0, 0, 0], []
    for k, (dim, _, name, _) in enumerate(blocks):
        counts[dim] += 1
        entity_tag.append(counts[dim])
        names.append((dim, k + 1, name))
    with open(path, "w") as f:
        f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        f.write(f"$PhysicalNames\n{len(names)}\n")
        f.write("".join(f'{d} {t} "{n}"\n' for d, t, n in names))
        f.write("$EndPhysicalNames\n$Entities\n" + " ".join(map(str, counts)) + "\n")
        for dim in range(4):
            for k, b in enumerate(blocks):
                if b[0] != dim:
                    continue
                if dim == 0:
                    f.write(f"{entity_tag[k]} {lo[0]:.17g} {lo[1]:.17g} {lo[2]:.17g} 1 {k + 1}\n")
                else:
                    f.write(f"{entity_tag[k]} {box} 1 {k + 1} 0\n")
        f.write("$EndEntities\n")
        n = len(nodes)
        first = entity_tag[next(k for k, b in enumerate(blocks) if b[0] == top)]
        f.write(f"$Nodes\n1 {n} 1 {n}\n{top} {first} 0 {n}\n")
        f.write("".join(f"{i + 1}\n" for i in range(n)))
        f.write("".join(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in nodes))
        f.write("$EndNodes\n")
        total = sum(len(b[3]) for b in blocks)
        f.write(f"$Elements\n{len(blocks)} {total} 1 {total}\n")
        tag = 1
        for k, (dim, etype, _, elements) in enumerate(blocks):
            f.write(f"{dim} {entity_tag[k]} {etype} {len(elements)}\n")
            for el in elements:
                f.write(f"{tag} " + " ".join(str(int(v) + 1) for v in el) + "\n")
                tag += 1
        f.write("$EndElements\n")
