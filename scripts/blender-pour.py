#!/usr/bin/env python3
"""Pour 2,000 ico-spheres into a box, built as the interface builds it, and bake it with
Blender's own rigid body solver (``ptcache.bake_all`` at Blender's defaults) and with impulse
(the extension's whole bake: read, simulate, write keyframes); prints both bakes' times (wall
and this process's CPU time: Blender's solver runs on one thread, impulse's on all cores) and
whether anything went through the floor or out of the box (docs/blender.md).

The scene: the factory startup file without its cube; a passive ground slab (a scaled cube,
top at z = 0) and four passive walls (scaled cubes) around a 3 × 3 m floor, 2 m high; one ico
sphere of radius 0.1 m added with the Add menu, duplicated into a jittered grid of 12 × 12 ×
14 spheres (0.24 m apart, from 0.4 m above the walls' top), and made rigid bodies together with
Physics › Rigid Body › Add Active on the selection (default shape Convex Hull, 1 kg).

Needs a Python with ``bpy`` (Blender as a module, from PyPI) and ``impulse`` installed:

    python scripts/blender-pour.py [--frames 250] [--count 2000] [--impulse-only]
"""

import argparse
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "blender"), str(ROOT / "blender" / "tests")]

import bpy
import numpy as np
from impulse_bake import bake

import field

#: Sphere radius, the box's inner half-width and its walls' height and thickness (m).
RADIUS = 0.1
HALF_WIDTH = 1.5
WALL_HEIGHT = 2.0
WALL_THICKNESS = 0.2
#: Grid of the spheres' start: per layer, spacing (m), first layer's height (m).
PER_ROW = 12
SPACING = 0.24
FIRST_LAYER = WALL_HEIGHT + 0.4


def build(frames, count):
    """The pour scene; returns the scene and its spheres."""
    scene = field.startup(frames)
    field.ground(size=20.0, top=0.0)
    for name, location, scale in (
        ("Wall+X", (HALF_WIDTH + WALL_THICKNESS / 2, 0.0), (WALL_THICKNESS, 2 * HALF_WIDTH + 2 * WALL_THICKNESS)),
        ("Wall-X", (-HALF_WIDTH - WALL_THICKNESS / 2, 0.0), (WALL_THICKNESS, 2 * HALF_WIDTH + 2 * WALL_THICKNESS)),
        ("Wall+Y", (0.0, HALF_WIDTH + WALL_THICKNESS / 2), (2 * HALF_WIDTH, WALL_THICKNESS)),
        ("Wall-Y", (0.0, -HALF_WIDTH - WALL_THICKNESS / 2), (2 * HALF_WIDTH, WALL_THICKNESS)),
    ):
        wall = field.add("cube", name, size=1.0, location=(*location, WALL_HEIGHT / 2))
        wall.scale = (*scale, WALL_HEIGHT)
        bpy.context.view_layer.update()
        field.rigid(wall, "PASSIVE")
    first = field.add("ico_sphere", "Ball", radius=RADIUS, location=(0.0, 0.0, 0.0))
    generator = np.random.default_rng(0)
    spheres = [first]
    offset = (PER_ROW - 1) / 2 * SPACING
    for i in range(count):
        layer, cell = divmod(i, PER_ROW * PER_ROW)
        row, column = divmod(cell, PER_ROW)
        jitter = generator.uniform(-0.015, 0.015, size=2)
        location = (
            column * SPACING - offset + jitter[0],
            row * SPACING - offset + jitter[1],
            FIRST_LAYER + layer * SPACING,
        )
        if i == 0:
            first.location = location
            continue
        copy = first.copy()  # Shift+D without a new mesh: Alt+D, a linked duplicate
        copy.name = f"Ball.{i:04d}"
        copy.location = location
        scene.collection.objects.link(copy)
        spheres.append(copy)
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    for sphere in spheres:
        sphere.select_set(True)
    bpy.context.view_layer.objects.active = first
    bpy.ops.rigidbody.objects_add(type="ACTIVE")
    cache = scene.rigidbody_world.point_cache
    cache.frame_start, cache.frame_end = scene.frame_start, scene.frame_end
    return scene, spheres


def outcome(scene, spheres, frame):
    """(lowest vertex of any sphere (m; the floor's top is 0), spheres with a vertex more than
    1 cm below the floor's top, spheres whose centre is outside the walls) at ``frame``."""
    scene.frame_set(frame)
    mesh = spheres[0].data
    vertices = np.array([v.co[:] for v in mesh.vertices])
    matrices = np.array([np.array(s.matrix_world) for s in spheres])
    heights = np.einsum("sj,vj->sv", matrices[:, 2, :3], vertices) + matrices[:, 2, 3][:, None]
    bottoms = heights.min(axis=1)
    centres = matrices[:, :3, 3]
    through = int(np.sum(bottoms < -0.01))
    outside = int(np.sum(np.max(np.abs(centres[:, :2]), axis=1) > HALF_WIDTH + 0.01))
    return float(bottoms.min()), through, outside


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=250)
    parser.add_argument("--count", type=int, default=2000)
    parser.add_argument("--impulse-only", action="store_true", help="skip Blender's bake")
    args = parser.parse_args()
    bake.import_impulse()
    print(f"Blender {bpy.app.version_string}, {args.count} ico-spheres, {args.frames} frames at 24 fps", flush=True)
    results = []
    if not args.impulse_only:
        start = time.perf_counter()
        scene, spheres = build(args.frames, args.count)
        built = time.perf_counter() - start
        start, cpu = time.perf_counter(), time.process_time()
        with bpy.context.temp_override(scene=scene):
            bpy.ops.ptcache.bake_all(bake=True)
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        results.append(("Blender", seconds, cpu, *outcome(scene, spheres, args.frames)))
        print(f"built in {built:.1f} s; Blender's bake {seconds:.1f} s ({cpu:.1f} s CPU)", flush=True)
    scene, spheres = build(args.frames, args.count)
    start, cpu = time.perf_counter(), time.process_time()
    bake.bake_scene(scene)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    results.append(("impulse (default preset)", seconds, cpu, *outcome(scene, spheres, args.frames)))
    print("\n| bake | whole bake (s) | CPU (s) | lowest vertex (mm) | through the floor | out of the box |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, seconds, cpu, lowest, through, outside in results:
        print(f"| {name} | {seconds:.1f} | {cpu:.1f} | {1000 * lowest:.1f} | {through} | {outside} |")
    if len(results) == 2:
        ratio = results[1][1] / results[0][1]
        print(f"\nimpulse / Blender: {ratio:.3f} (target <= 0.15: {'met' if ratio <= 0.15 else 'not met'})")


if __name__ == "__main__":
    main()
