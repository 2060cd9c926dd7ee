#!/usr/bin/env python3
"""Writes the CalculiX test models of jprom and runs CalculiX (`ccx`) on them.

Three small steel solids (mm, tonne, s: E = 2.0e5 MPa, nu = 0.3, rho = 7.8e-9 t/mm^3), none
of them jprom's built-in blade, each clamped at its root by *BOUNDARY:

  block   a straight cantilever block, 16 x 4 x 2 linear hexahedra (C3D8), everything in the
          .inp; node sets with and without GENERATE.
  plate   a cambered plate twisted by 45 degrees, 8 x 3 x 1 quadratic hexahedra (C3D20), the
          mesh and the sets in plate.msh, pulled in by *INCLUDE.
  arc     a 60-degree ring sector, 8 x 2 x 1 hexahedra each split into two quadratic wedges
          (C3D15); node ids start at 1001 and have gaps (only the nodes the elements use are
          written), the elements and sets are in arc_sets.msh (*INCLUDE).

Each model has the node sets TIP (contact candidates at the free end), LOAD (one node), OUT
(a few nodes) and ROOT (the clamped nodes).

For each model two decks are written into tests/data/calculix/<model>/:

  <model>_freq.inp   *FREQUENCY (10 modes, default solver): the eigenvalues go to
                     <model>_freq.dat ("E I G E N V A L U E   O U T P U T").
  <model>.inp        *FREQUENCY, SOLVER=MATRIXSTORAGE: ccx writes the stiffness matrix to
                     <model>.sti, the mass matrix to <model>.mas and the row -> node.direction
                     map to <model>.dof, then stops.

Usage:  python3 make_models.py           write the decks and run ccx (needs `ccx` on PATH)
        python3 make_models.py --no-run  only write the decks

Outputs kept (the tests read them): <model>.sti, .mas, .dof, <model>_freq.dat. Everything
else ccx writes (.frd, .cvg, .sta, spooles.out, ...) is deleted.
"""

import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
N_MODES = 10

MATERIAL = """*MATERIAL, NAME=STEEL
*ELASTIC
2.0e5, 0.3
*DENSITY
7.8e-9
*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL
"""


def fmt_node(nid, x):
    return "%d, %.12e, %.12e, %.12e\n" % (nid, x[0], x[1], x[2])


def id_lines(ids, per_line=8):
    ids = list(ids)
    out = []
    for k in range(0, len(ids), per_line):
        out.append(", ".join(str(i) for i in ids[k:k + per_line]) + ",\n")
    return "".join(out)


def signed_volume(p):
    """6 x the signed volume of the tetrahedron (p0, p1, p2, p3): > 0 for a right-handed corner."""
    a = [p[1][i] - p[0][i] for i in range(3)]
    b = [p[2][i] - p[0][i] for i in range(3)]
    c = [p[3][i] - p[0][i] for i in range(3)]
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


class Grid:
    """A structured grid of points (i, j, k), 0 <= i <= ni etc., mapped by `geom(u, v, w)`
    with u = i / ni ... in [0, 1]; node ids are handed out on first use, in the order asked."""

    def __init__(self, ni, nj, nk, geom, first_id=1, ids=None):
        self.n = (ni, nj, nk)
        self.geom = geom
        self.ids = {}
        self.next_id = first_id
        self.fixed_ids = ids  # optional function (i, j, k) -> id

    def node(self, i, j, k):
        key = (i, j, k)
        if key not in self.ids:
            if self.fixed_ids is not None:
                self.ids[key] = self.fixed_ids(i, j, k)
            else:
                self.ids[key] = self.next_id
                self.next_id += 1
        return self.ids[key]

    def coord(self, key):
        i, j, k = key
        return self.geom(i / self.n[0], j / self.n[1], k / self.n[2])

    def nodes_text(self):
        items = sorted(self.ids.items(), key=lambda kv: kv[1])
        return "".join(fmt_node(nid, self.coord(key)) for key, nid in items)

    def select(self, pred):
        return sorted(nid for key, nid in self.ids.items() if pred(*key))


# ---------------------------------------------------------------------------------------
# block: C3D8 cantilever, 100 x 20 x 10 mm, 16 x 4 x 2 elements, all in one .inp
# ---------------------------------------------------------------------------------------

def block():
    ne = (16, 4, 2)
    size = (100.0, 20.0, 10.0)
    n1 = (ne[0] + 1, ne[1] + 1, ne[2] + 1)
    # ids numbered x fastest, so that lines of nodes are GENERATE ranges
    grid = Grid(*ne, geom=lambda u, v, w: (size[0] * u, size[1] * v, size[2] * w),
                ids=lambda i, j, k: 1 + i + n1[0] * (j + n1[1] * k))
    for k in range(n1[2]):
        for j in range(n1[1]):
            for i in range(n1[0]):
                grid.node(i, j, k)
    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    elems = []
    for k in range(ne[2]):
        for j in range(ne[1]):
            for i in range(ne[0]):
                conn = [grid.node(i + a, j + b, k + c) for a, b, c in corners]
                elems.append(conn)
    check_orientation(grid, elems, [0, 1, 3, 4])
    nx = ne[0]
    tip = grid.select(lambda i, j, k: i == nx)
    root = grid.select(lambda i, j, k: i == 0)
    load = grid.node(nx, ne[1], ne[2])
    out = [grid.node(nx // 2, ne[1], ne[2]), grid.node(nx, 0, ne[2]), load]
    # the tip face: ids 17, 34, ..., step 17 (one GENERATE line per layer k)
    tip_gen = "".join("%d, %d, %d\n" % (grid.node(nx, 0, k), grid.node(nx, ne[1], k), n1[0]) for k in range(n1[2]))
    assert sorted(sum((list(range(grid.node(nx, 0, k), grid.node(nx, ne[1], k) + 1, n1[0])) for k in range(n1[2])), [])) == tip
    mesh = "*NODE, NSET=NALL\n" + grid.nodes_text()
    mesh += "*ELEMENT, TYPE=C3D8, ELSET=EALL\n"
    mesh += "".join("%d, %s\n" % (e + 1, ", ".join(map(str, c))) for e, c in enumerate(elems))
    mesh += "*NSET, NSET=ROOT\n" + id_lines(root)
    mesh += "*NSET, NSET=TIP, GENERATE\n" + tip_gen
    mesh += "*NSET, NSET=LOAD\n%d\n" % load
    mesh += "*NSET, NSET=OUT\n" + id_lines(out)
    # the bottom edge y = 0, z = 0: ids 1..17
    mesh += "*NSET, NSET=EDGE, GENERATE\n1, %d\n" % n1[0]
    return None, mesh, None


# ---------------------------------------------------------------------------------------
# plate: C3D20, 120 x 30 x 3 mm twisted by 45 degrees and cambered, 8 x 3 x 1 elements,
# mesh in plate.msh
# ---------------------------------------------------------------------------------------

C3D20 = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2),
         (1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0), (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
         (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]


def plate():
    ne = (8, 3, 1)
    L, W, T = 120.0, 30.0, 3.0
    twist = math.radians(45.0)
    camber = 6.0

    def geom(u, v, w):
        y0, z0 = W * (v - 0.5), T * (w - 0.5)
        phi = twist * u
        c, s = math.cos(phi), math.sin(phi)
        x = L * u
        y = c * y0 - s * z0
        z = s * y0 + c * z0 + camber * math.sin(math.pi * v) * (0.5 + 0.5 * u)
        return (x, y, z)

    grid = Grid(2 * ne[0], 2 * ne[1], 2 * ne[2], geom)
    elems = []
    for i in range(ne[0]):
        for j in range(ne[1]):
            for k in range(ne[2]):
                elems.append([grid.node(2 * i + a, 2 * j + b, 2 * k + c) for a, b, c in C3D20])
    check_orientation(grid, elems, [0, 1, 3, 4])
    nx, ny, nz = 2 * ne[0], 2 * ne[1], 2 * ne[2]
    tip = grid.select(lambda i, j, k: i == nx and k == nz)  # tip edge, top face
    root = grid.select(lambda i, j, k: i == 0)
    load = grid.node(nx, ny, nz)
    out = [grid.node(nx, 0, nz), grid.node(nx // 2, ny // 2, nz), load]
    mesh = "** plate.msh: written by make_models.py\n*NODE, NSET=NALL\n" + grid.nodes_text()
    mesh += "*ELEMENT, TYPE=C3D20, ELSET=EALL\n"
    for e, c in enumerate(elems):
        # 20 nodes: 16 on the element line, 4 on a continuation line (lines end with ',')
        mesh += "%d, %s,\n%s\n" % (e + 1, ", ".join(map(str, c[:15])), ", ".join(map(str, c[15:])))
    mesh += "*NSET, NSET=ROOT\n" + id_lines(root)
    mesh += "*NSET, NSET=TIP\n" + id_lines(tip)
    mesh += "*NSET, NSET=LOAD\n%d\n" % load
    mesh += "*NSET, NSET=OUT\n" + id_lines(out)
    # a set made of sets
    mesh += "*NSET, NSET=WATCH\nLOAD, OUT\n"
    return None, mesh, "plate.msh"


# ---------------------------------------------------------------------------------------
# arc: C3D15 wedges, a 60-degree ring sector, r 50..70 mm, 8 mm thick; node ids from 1001
# ---------------------------------------------------------------------------------------

C3D15_A = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2),
           (1, 0, 0), (2, 1, 0), (1, 1, 0), (1, 0, 2), (2, 1, 2), (1, 1, 2),
           (0, 0, 1), (2, 0, 1), (2, 2, 1)]
C3D15_B = [(0, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 2, 2), (0, 2, 2),
           (1, 1, 0), (1, 2, 0), (0, 1, 0), (1, 1, 2), (1, 2, 2), (0, 1, 2),
           (0, 0, 1), (2, 2, 1), (0, 2, 1)]


def arc():
    ne = (2, 8, 1)  # radial, along the arc, through the thickness
    ri, ro, T = 50.0, 70.0, 8.0
    theta = math.radians(60.0)

    def geom(u, v, w):
        r = ri + (ro - ri) * u
        a = theta * v
        return (r * math.cos(a), r * math.sin(a), T * w)

    nx, ny, nz = 2 * ne[0], 2 * ne[1], 2 * ne[2]
    grid = Grid(nx, ny, nz, geom,
                ids=lambda i, j, k: 1001 + i + (nx + 1) * (j + (ny + 1) * k))
    elems = []
    for j in range(ne[1]):
        for i in range(ne[0]):
            for k in range(ne[2]):
                for pattern in (C3D15_A, C3D15_B):
                    elems.append([grid.node(2 * i + a, 2 * j + b, 2 * k + c) for a, b, c in pattern])
    check_orientation(grid, elems, [0, 1, 2, 3])
    tip = grid.select(lambda i, j, k: j == ny)
    root = grid.select(lambda i, j, k: j == 0)
    load = grid.node(nx, ny, nz)
    out = [grid.node(0, ny, nz), grid.node(nx, ny // 2, nz), load]
    nodes = "*NODE, NSET=NALL\n" + grid.nodes_text()
    mesh = "** arc_sets.msh: written by make_models.py\n"
    mesh += "*ELEMENT, TYPE=C3D15, ELSET=EALL\n"
    for e, c in enumerate(elems):
        mesh += "%d, %s\n" % (e + 1, ", ".join(map(str, c)))
    mesh += "*NSET, NSET=ROOT\n" + id_lines(root)
    mesh += "*NSET, NSET=TIP\n" + id_lines(tip)
    mesh += "*NSET,NSET=load\n%d\n" % load  # lower case: CalculiX names are case-insensitive
    mesh += "*NSET, NSET=OUT\n" + id_lines(out)
    return nodes, mesh, "arc_sets.msh"


def check_orientation(grid, elems, corner):
    """Every element's first corner must be right-handed (positive Jacobian)."""
    for e in elems:
        inv = {nid: key for key, nid in grid.ids.items()}
        p = [grid.coord(inv[e[c]]) for c in corner]
        assert signed_volume(p) > 0, "left-handed element %s" % e


def deck(name, inline, mesh, include, step):
    """The .inp text: mesh inline or *INCLUDE'd, material, clamp, one step."""
    text = "** %s: written by tests/data/calculix/make_models.py\n*HEADING\njprom CalculiX test model %s\n" % (name, name)
    if inline:
        text += inline
    if include:
        text += "*INCLUDE, INPUT=%s\n" % include
    else:
        text += mesh
    text += MATERIAL
    text += "*BOUNDARY\nROOT, 1, 3\n"
    text += step
    return text


FREQ_STEP = "*STEP\n*FREQUENCY\n%d\n*END STEP\n" % N_MODES
# no data line: with SOLVER=MATRIXSTORAGE ccx reads none (frequencys.f), it would warn
MATRIX_STEP = "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n"

KEEP = {".sti", ".mas", ".dof"}


def write_model(name, build, run):
    d = os.path.join(HERE, name)
    os.makedirs(d, exist_ok=True)
    inline, mesh, include = build()
    if include:
        with open(os.path.join(d, include), "w") as f:
            f.write(mesh)
    for job, step in ((name + "_freq", FREQ_STEP), (name, MATRIX_STEP)):
        with open(os.path.join(d, job + ".inp"), "w") as f:
            f.write(deck(name, inline, mesh, include, step))
    if not run:
        return
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1", CCX_NPROC_EQUATION_SOLVER="1")
    for job in (name + "_freq", name):
        with open(os.path.join(d, job + ".log"), "w") as log:
            subprocess.run(["ccx", "-i", job], cwd=d, env=env, stdout=log, stderr=subprocess.STDOUT, check=True)
    keep = {name + ext for ext in KEEP} | {name + "_freq.dat", name + ".inp", name + "_freq.inp"}
    if include:
        keep.add(include)
    for f in os.listdir(d):
        if f not in keep and "--keep-all" not in sys.argv[1:]:
            os.remove(os.path.join(d, f))


def main():
    run = "--no-run" not in sys.argv[1:]
    if run and shutil.which("ccx") is None:
        sys.exit("ccx not found (apt-get install calculix-ccx), or use --no-run")
    for name, build in (("block", block), ("plate", plate), ("arc", arc)):
        write_model(name, build, run)
        print("wrote", name)


if __name__ == "__main__":
    main()
