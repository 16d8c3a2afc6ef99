#!/usr/bin/env python3
"""Bake each comparison scene with impulse (the extension's bake: read, simulate, write
keyframes) and with Blender's own rigid body solver (``ptcache.bake_all`` at Blender's
defaults), and time writing keyframes for many objects; prints a Markdown table
(docs/blender.md).

Needs a Python with ``bpy`` (Blender as a module, from PyPI) and ``impulse`` installed:

    python scripts/blender-compare.py [--frames 250] [--preset default] [--scenes stack30 ...]
    python scripts/blender-compare.py --render docs      # docs/blender-{dominoes,bowl}.png

E is the largest drift, sink or overlap at the last frame for the scenes meant to stay at
rest (stack30, pyramid20, heavy_on_light), the largest overlap for the others, measured from
the poses in the same way for both bakes (blender/tests/measure.py).
"""

import argparse
import pathlib
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "blender"), str(ROOT / "blender" / "tests")]

import bpy
import numpy as np
from impulse_bake import bake, keyframes, scene_reader
from measure import error_at_end, poses_at

import scenes


def measure(scene, info, static_scene):
    names = [b.object_name for b in info.bodies]
    positions, orientations = poses_at(scene, names, info.frame_end)
    return error_at_end(info, positions, orientations, static_scene)[0]


def impulse_bake(name, frames, preset, substeps=0, frame_steps=0):
    scene = scenes.SCENES[name](frames)
    start = time.perf_counter()
    baker = bake.bake_scene(scene, preset=preset, substeps=substeps, frame_steps=frame_steps)
    seconds = time.perf_counter() - start
    return seconds, measure(scene, baker.info, name in scenes.STATIC_SCENES), len(baker.info.bodies)


def blender_bake(name, frames):
    scene = scenes.SCENES[name](frames)
    info = scene_reader.read_scene(scene)
    start = time.perf_counter()
    with bpy.context.temp_override(scene=scene):
        bpy.ops.ptcache.bake_all(bake=True)
    seconds = time.perf_counter() - start
    return seconds, measure(scene, info, name in scenes.STATIC_SCENES)


def keyframe_timing(objects, frames):
    """Seconds to write location and quaternion keyframes of ``frames`` frames on ``objects``
    new objects (random poses; the write alone)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    created = []
    for i in range(objects):
        obj = bpy.data.objects.new(f"object{i:04d}", None)
        scene.collection.objects.link(obj)
        created.append(obj)
    generator = np.random.default_rng(0)
    locations = generator.normal(size=(frames, objects, 3)).astype(np.float32)
    quaternions = generator.normal(size=(frames, objects, 4)).astype(np.float32)
    quaternions /= np.linalg.norm(quaternions, axis=2, keepdims=True)
    frame_numbers = np.arange(1, frames + 1)
    start = time.perf_counter()
    for i, obj in enumerate(created):
        keyframes.write_fcurves(obj, frame_numbers, locations[:, i], quaternions[:, i])
    return time.perf_counter() - start


#: Scenes drawn by --render: (scene, frame, camera location, camera target).
RENDERS = (
    ("dominoes", 60, (9.5, -17.0, 7.0), (9.5, 0.0, 0.5)),
    ("bowl", 60, (0.0, -9.0, 9.0), (0.0, 0.0, 2.0)),
)


def render(directory, frames, preset):
    """Bake each scene of RENDERS with impulse and draw its frame with Cycles on the CPU into
    ``directory``/blender-<scene>.png."""
    import mathutils

    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    for name, frame, eye, target in RENDERS:
        scene = scenes.SCENES[name](frames)
        bake.bake_scene(scene, preset=preset)
        camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
        scene.collection.objects.link(camera)
        camera.location = eye
        direction = mathutils.Vector(target) - mathutils.Vector(eye)
        camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
        scene.camera = camera
        sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", type="SUN"))
        sun.rotation_euler = (0.6, 0.2, 0.8)
        sun.data.energy = 4.0
        scene.collection.objects.link(sun)
        if scene.world is None:
            scene.world = bpy.data.worlds.new("world")
        scene.world.color = (0.6, 0.65, 0.7)
        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = 32
        scene.render.resolution_x, scene.render.resolution_y = 640, 360
        scene.render.filepath = str(directory / f"blender-{name}.png")
        scene.frame_set(frame)
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(write_still=True)
        print(f"drew {scene.render.filepath} (frame {frame})")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=250)
    parser.add_argument("--preset", default="default", choices=bake.PRESETS)
    parser.add_argument("--scenes", nargs="*", default=list(scenes.SCENES), choices=list(scenes.SCENES))
    parser.add_argument("--keyframe-objects", type=int, default=1000)
    parser.add_argument("--keyframe-frames", type=int, default=250)
    parser.add_argument("--substeps", type=int, default=0, help="impulse substeps per step (0: the preset's)")
    parser.add_argument("--steps-per-frame", type=int, default=0, help="impulse steps per frame (0: within 1/60 s)")
    parser.add_argument("--impulse-only", action="store_true", help="skip Blender's bake")
    parser.add_argument("--repeat", type=int, default=3, help="bakes of each kind; the median time is shown")
    parser.add_argument("--render", metavar="DIR", help="only draw the frames of RENDERS into DIR")
    args = parser.parse_args()
    if args.render:
        render(args.render, args.frames, args.preset)
        return
    # Imported once before timing, as Blender keeps the package loaded between bakes.
    bake.import_impulse()

    print(
        f"Blender {bpy.app.version_string}, {args.frames} frames at 24 fps, impulse preset {args.preset}, "
        f"median of {args.repeat} bakes\n"
    )
    print(
        "| scene | bodies | impulse bake (s) | impulse E (mm) | Blender bake (s) | Blender E (mm) | time ratio | target met |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for name in args.scenes:
        impulse_runs = [
            impulse_bake(name, args.frames, args.preset, args.substeps, args.steps_per_frame)
            for _ in range(args.repeat)
        ]
        impulse_seconds = float(np.median([run[0] for run in impulse_runs]))
        impulse_error, bodies = impulse_runs[-1][1:]
        if args.impulse_only:
            print(f"| {name} | {bodies} | {impulse_seconds:.3f} | {1000 * impulse_error:.2f} | | | | |", flush=True)
            continue
        blender_runs = [blender_bake(name, args.frames) for _ in range(args.repeat)]
        blender_seconds = float(np.median([run[0] for run in blender_runs]))
        blender_error = blender_runs[-1][1]
        ratio = impulse_seconds / blender_seconds
        met = "yes" if ratio <= 0.5 and impulse_error <= blender_error else "no"
        print(
            f"| {name} | {bodies} | {impulse_seconds:.3f} | {1000 * impulse_error:.2f} | "
            f"{blender_seconds:.3f} | {1000 * blender_error:.2f} | {ratio:.2f} | {met} |",
            flush=True,
        )
    if args.keyframe_objects == 0:
        return
    seconds = float(
        np.median([keyframe_timing(args.keyframe_objects, args.keyframe_frames) for _ in range(args.repeat)])
    )
    print(
        f"\nKeyframes for {args.keyframe_objects} objects x {args.keyframe_frames} frames "
        f"(location and quaternion, 7 F-curves each; median of {args.repeat}): {seconds:.3f} s"
    )


if __name__ == "__main__":
    main()
