#!/usr/bin/env python3
"""Writes scenes/mug.obj (a closed mug mesh as a modelling tool exports it: a revolved cup of
about 2,000 triangles and a half-torus handle), scenes/mugs500.json (500 of them poured into
a walled box, their orientations from a fixed seed; 2 s at 1/60 s) and scenes/mugs98.json (its
first 98 mugs, two layers, for 120 steps of 1/240 s: the benchmarks' mug pour). Rerun after changing the shapes here.

Usage: scripts/make-mug-scenes.py
"""
import json
import math
import os
import random

RADIUS, HEIGHT, WALL, SEGMENTS = 0.045, 0.1, 0.006, 216
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")


def signed_volume(vertices, triangles):
    total = 0.0
    for a, b, c in triangles:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = vertices[a], vertices[b], vertices[c]
        total += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    return total / 6.0


def outward(vertices, triangles):
    """The triangles wound outward (reversed when the signed volume is negative)."""
    if signed_volume(vertices, triangles) < 0:
        return [(a, c, b) for a, b, c in triangles]
    return triangles


def cup():
    """The cup: a profile from the axis back to the axis turned about y."""
    inner = RADIUS - WALL
    profile = [(0, 0), (RADIUS, 0), (RADIUS, HEIGHT), (inner, HEIGHT), (inner, WALL), (0, WALL)]
    vertices, rows = [], []
    for r, y in profile:
        if r == 0:
            rows.append([len(vertices)] * SEGMENTS)
            vertices.append((0.0, y, 0.0))
        else:
            row = []
            for s in range(SEGMENTS):
                angle = 2 * math.pi * s / SEGMENTS
                row.append(len(vertices))
                vertices.append((r * math.cos(angle), y, r * math.sin(angle)))
            rows.append(row)
    triangles = []
    for p in range(len(profile) - 1):
        for s in range(SEGMENTS):
            t = (s + 1) % SEGMENTS
            a, b, c, d = rows[p][s], rows[p][t], rows[p + 1][t], rows[p + 1][s]
            for tri in ((a, b, c), (a, c, d)):
                if len(set(tri)) == 3:
                    triangles.append(tri)
    return vertices, outward(vertices, triangles)


def handle():
    """Half a torus on the +x side, its capped ends sunk into the wall."""
    ring, tube, n, m = 0.3 * HEIGHT, 0.12 * HEIGHT, 12, 10
    cx, cy = RADIUS - 0.5 * WALL, 0.5 * HEIGHT
    vertices, triangles = [], []
    for i in range(n + 1):
        u = -math.pi / 2 + math.pi * i / n
        for j in range(m):
            w = 2 * math.pi * j / m
            r = ring + tube * math.cos(w)
            vertices.append((cx + r * math.cos(u), cy + r * math.sin(u), tube * math.sin(w)))
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, (i + 1) * m + j
            c, d = (i + 1) * m + (j + 1) % m, i * m + (j + 1) % m
            triangles += [(a, b, c), (a, c, d)]
    for end in (0, n):
        centre = len(vertices)
        u = -math.pi / 2 + math.pi * end / n
        vertices.append((cx + ring * math.cos(u), cy + ring * math.sin(u), 0.0))
        for j in range(m):
            a, b = end * m + j, end * m + (j + 1) % m
            triangles.append((centre, a, b) if end == 0 else (centre, b, a))
    return vertices, outward(vertices, triangles)


def mug():
    """The mug's vertices and triangles: the cup, then the handle."""
    cup_vertices, cup_triangles = cup()
    handle_vertices, handle_triangles = handle()
    offset = len(cup_vertices)
    vertices = cup_vertices + handle_vertices
    triangles = cup_triangles + [(a + offset, b + offset, c + offset) for a, b, c in handle_triangles]
    return vertices, triangles


def open_edges(triangles):
    """Edges not shared by exactly two triangles of opposite winding: 0 for a closed mesh."""
    count = {}
    for a, b, c in triangles:
        for edge in ((a, b), (b, c), (c, a)):
            count[edge] = count.get(edge, 0) + 1
    return sum(1 for (a, b), n in count.items() if n != 1 or count.get((b, a), 0) != 1)


def write_obj(path):
    vertices, triangles = mug()
    assert open_edges(triangles) == 0, "the mug mesh is not closed"
    with open(path, "w") as f:
        f.write(f"# A mug: {len(triangles)} triangles, closed, wound outward (scripts/make-mug-scenes.py)\n")
        for x, y, z in vertices:
            f.write(f"v {x:.6f} {y:.6f} {z:.6f}\n")
        for a, b, c in triangles:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")
    return len(triangles)


def bounding_sphere(vertices):
    """Centre (the bounding box's) and radius of a sphere holding every vertex."""
    centre = [0.5 * (min(v[i] for v in vertices) + max(v[i] for v in vertices)) for i in range(3)]
    radius = max(math.dist(v, centre) for v in vertices)
    return centre, radius


def rotate(q, v):
    """The vector v turned by the unit quaternion q = [x, y, z, w]."""
    x, y, z, w = q
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return [v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)]


def write_scene(path, count=500, steps=120, dt=1 / 60, gap=0.01):
    """Mugs in layers of a 7 x 7 grid above a walled box, each turned at random about its
    bounding sphere's centre, the spheres `gap` apart: no mug starts touching another, the
    floor or a wall. The draws go mug by mug, so the first k mugs are the same for any
    count >= k."""
    rng = random.Random(62)
    half, wall_height = 0.7, 0.6
    bodies = [
        {"name": "floor", "kind": "static", "shape": {"type": "cuboid", "half_extents": [1.0, 0.1, 1.0]},
         "position": [0, -0.1, 0]},
    ]
    for name, position, extents in [
        ("wall -x", [-half - 0.05, wall_height / 2, 0], [0.05, wall_height / 2, half + 0.1]),
        ("wall +x", [half + 0.05, wall_height / 2, 0], [0.05, wall_height / 2, half + 0.1]),
        ("wall -z", [0, wall_height / 2, -half - 0.05], [half + 0.1, wall_height / 2, 0.05]),
        ("wall +z", [0, wall_height / 2, half + 0.05], [half + 0.1, wall_height / 2, 0.05]),
    ]:
        bodies.append({"name": name, "kind": "static", "shape": {"type": "cuboid", "half_extents": extents},
                       "position": position})
    centre, radius = bounding_sphere(mug()[0])
    spacing, per_row = 2 * radius + gap, 7
    assert (per_row - 1) / 2 * spacing + radius < half, "the grid does not fit inside the walls"
    spheres = []
    for k in range(count):
        layer, cell = divmod(k, per_row * per_row)
        row, column = divmod(cell, per_row)
        sphere = [
            (column - (per_row - 1) / 2) * spacing,
            radius + gap + layer * spacing,
            (row - (per_row - 1) / 2) * spacing,
        ]
        # A uniformly random orientation (Shoemake's method).
        u1, u2, u3 = rng.random(), rng.random(), rng.random()
        q = [
            math.sqrt(1 - u1) * math.sin(2 * math.pi * u2),
            math.sqrt(1 - u1) * math.cos(2 * math.pi * u2),
            math.sqrt(u1) * math.sin(2 * math.pi * u3),
            math.sqrt(u1) * math.cos(2 * math.pi * u3),
        ]
        q = [round(x, 6) for x in q]
        # The origin placed so that the turned bounding sphere's centre is the grid point (the
        # engine normalises the rounded quaternion).
        norm = math.sqrt(sum(x * x for x in q))
        turned = rotate([x / norm for x in q], centre)
        position = [round(sphere[i] - turned[i], 6) for i in range(3)]
        spheres.append([position[i] + turned[i] for i in range(3)])
        bodies.append({"kind": "dynamic", "shape": {"type": "trimesh", "file": "mug.obj"},
                       "position": position, "orientation": q})
    # No mug touches another or the floor at the start: bounding spheres apart.
    for i, a in enumerate(spheres):
        assert a[1] - radius > 0, f"mug {i} starts in the floor"
        for b in spheres[i + 1:i + per_row * per_row + per_row + 2]:
            assert math.dist(a, b) > 2 * radius, "two mugs start overlapping"
    # 2 s at the default 1/60 s: the steps in which the 6 mm walls' parts would turn into each
    # other are taken in collision steps, each finding contacts again (docs/testing.md, "The
    # 500-mug pour"). The benchmarks' 98 mugs keep steps of 1/240 s, as measured against peers.
    scene = {"name": f"{count} mugs poured into a box", "dt": dt, "steps": steps, "bodies": bodies}
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    triangles = write_obj(os.path.join(ROOT, "mug.obj"))
    write_scene(os.path.join(ROOT, "mugs500.json"))
    write_scene(os.path.join(ROOT, "mugs98.json"), count=98, steps=120, dt=1 / 240)
    print(f"wrote scenes/mug.obj ({triangles} triangles), scenes/mugs500.json and scenes/mugs98.json")
