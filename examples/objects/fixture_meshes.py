#!/usr/bin/python3
"""Writes the meshes of examples/fixture_two_pins.yaml and examples/stack_in_tray.yaml (inches):
two_pin_base.off, two_hole_part.off, wall.off and tray.stl (binary STL, no face names). Each is a
rectilinear solid, a union of filled cells of a grid, written as the boundary quads between
filled and empty cells (outward, counter-clockwise), each named by the part of the solid it
bounds. Run it in examples/objects/: /usr/bin/python3 fixture_meshes.py"""
import itertools
import struct

def solid_off(xs, ys, zs, filled, name_of, header):
    nx, ny, nz = len(xs) - 1, len(ys) - 1, len(zs) - 1
    full = lambda i, j, k: 0 <= i < nx and 0 <= j < ny and 0 <= k < nz and filled(i, j, k)
    vertices, index, polys = [], {}, []
    def vid(p):
        if p not in index:
            index[p] = len(vertices); vertices.append(p)
        return index[p]
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        if not full(i, j, k): continue
        for axis in range(3):
            for side in (0, 1):
                n = [i, j, k]; n[axis] += 1 if side else -1
                if full(*n): continue
                lo = [xs[i], ys[j], zs[k]]; hi = [xs[i+1], ys[j+1], zs[k+1]]
                a, b = [(axis + 1) % 3, (axis + 2) % 3]
                plane = hi[axis] if side else lo[axis]
                corners = []
                for (ua, ub) in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0, 0, 0]; p[axis] = plane
                    p[a] = hi[a] if ua else lo[a]; p[b] = hi[b] if ub else lo[b]
                    corners.append(tuple(p))
                if not side: corners.reverse()
                direction = ("+" if side else "-") + "xyz"[axis]
                polys.append(([vid(c) for c in corners], name_of(i, j, k, direction)))
    out = ["OFF"] + ["# " + line for line in header.splitlines()]
    out.append(f"{len(vertices)} {len(polys)} 0")
    out += [" ".join(f"{c:g}" for c in v) for v in vertices]
    out += [f"4 {' '.join(map(str, p))} # {name}" for p, name in polys]
    return "\n".join(out) + "\n"


# Base plate 6 x 3 x 0.5 with two pins 0.4 x 0.4 x 1 near its +x end.
xs = [-3, 1.8, 2.2, 3]; ys = [-1.5, -1.0, -0.6, 0.6, 1.0, 1.5]; zs = [0, 0.5, 1.5]
def base_filled(i, j, k): return k == 0 or (i == 1 and j in (1, 3))
def base_name(i, j, k, d):
    if k == 1: return ("pin_a " if j == 1 else "pin_b ") + d
    return "plate " + d
open('two_pin_base.off', 'w').write(solid_off(xs, ys, zs, base_filled, base_name,
  "two_pin_base: a plate 6 x 3 x 0.5 in with two square pins 0.4 x 0.4 x 1 in at x = 2,\ny = +-0.8; origin at the centre of the bottom; inches.\nWritten by examples/objects/fixture_meshes.py."))

# Part: 3.25 x 4.5 x 1 with two square holes 0.5 x 0.5 through at x = 0.675, y = +-0.8.
xs = [-1.625, 0.425, 0.925, 1.625]; ys = [-2.25, -1.05, -0.55, 0.55, 1.05, 2.25]; zs = [0, 1]
holes = {(1, 1), (1, 3)}
def part_filled(i, j, k): return (i, j) not in holes
def part_name(i, j, k, d):
    step = {"+x": (1, 0), "-x": (-1, 0), "+y": (0, 1), "-y": (0, -1)}.get(d)
    if step and (i + step[0], j + step[1]) in holes: return "hole wall"
    return "part " + d
open('two_hole_part.off', 'w').write(solid_off(xs, ys, zs, part_filled, part_name,
  "two_hole_part: a plate 3.25 x 4.5 x 1 in with two square holes 0.5 x 0.5 in through at\nx = 0.675, y = +-0.8; origin at the centre of the bottom; inches.\nWritten by examples/objects/fixture_meshes.py."))

# Wall: 0.5 x 8 x 5.
open('wall.off', 'w').write(solid_off([0, 0.5], [-4, 4], [0, 5], lambda i, j, k: True,
  lambda i, j, k, d: "wall " + d, "wall: a box 0.5 x 8 x 5 in, origin at a bottom corner edge; inches.\nWritten by examples/objects/fixture_meshes.py."))

# Tray: 6 x 5 x 1 with a pocket 3.7 x 3.2 x 0.5 on top; as a binary STL (no face names).
xs = [-3, -1.85, 1.85, 3]; ys = [-2.5, -1.6, 1.6, 2.5]; zs = [0, 0.5, 1]
text = solid_off(xs, ys, zs, lambda i, j, k: k == 0 or (i, j) != (1, 1),
                 lambda i, j, k, d: "tray", "")
lines = [l for l in text.splitlines() if l and not l.startswith('#')]
nv, nf, _ = map(int, lines[1].split())
verts = [tuple(map(float, l.split())) for l in lines[2:2 + nv]]
tris = []
for l in lines[2 + nv:2 + nv + nf]:
    idx = list(map(int, l.split('#')[0].split()[1:]))
    tris += [(idx[0], idx[1], idx[2]), (idx[0], idx[2], idx[3])]
with open('tray.stl', 'wb') as f:
    f.write(b'tray: 6 x 5 x 1 in, pocket 3.7 x 3.2 x 0.5 in; inches; fixture_meshes.py'.ljust(80, b' '))
    f.write(struct.pack('<I', len(tris)))
    for t in tris:
        f.write(struct.pack('<3f', 0, 0, 0))
        for v in t: f.write(struct.pack('<3f', *verts[v]))
        f.write(struct.pack('<H', 0))
