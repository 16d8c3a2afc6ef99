#!/usr/bin/env python3
"""Writes scenes/mug.obj (a closed mug mesh as a modelling tool exports it: a revolved cup of
about 2,000 triangles and a half-torus handle) and scenes/mugs500.json (500 of them poured into
a walled box, their orientations from a fixed seed). Rerun after changing the shapes here.

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
            triangles.append((centre, b, a) if end == 0 else (centre, a, b))
    return vertices, outward(vertices, triangles)


def write_obj(path):
    cup_vertices, cup_triangles = cup()
    handle_vertices, handle_triangles = handle()
    offset = len(cup_vertices)
    vertices = cup_vertices + handle_vertices
    triangles = cup_triangles + [(a + offset, b + offset, c + offset) for a, b, c in handle_triangles]
    with open(path, "w") as f:
        f.write(f"# A mug: {len(triangles)} triangles, closed, wound outward (scripts/make-mug-scenes.py)\n")
        for x, y, z in vertices:
            f.write(f"v {x:.6f} {y:.6f} {z:.6f}\n")
        for a, b, c in triangles:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")
    return len(triangles)


def write_scene(path, count=500):
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
    spacing, per_row = 0.17, 7
    for k in range(count):
        layer, cell = divmod(k, per_row * per_row)
        row, column = divmod(cell, per_row)
        position = [
            (column - (per_row - 1) / 2) * spacing,
            0.15 + layer * spacing,
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
        bodies.append({"kind": "dynamic", "shape": {"type": "trimesh", "file": "mug.obj"},
                       "position": [round(x, 4) for x in position], "orientation": [round(x, 6) for x in q]})
    scene = {"name": f"{count} mugs poured into a box", "steps": 300, "bodies": bodies}
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    triangles = write_obj(os.path.join(ROOT, "mug.obj"))
    write_scene(os.path.join(ROOT, "mugs500.json"))
    print(f"wrote scenes/mug.obj ({triangles} triangles) and scenes/mugs500.json")
