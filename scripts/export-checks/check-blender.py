"""Imports a `.glb` or `.gltf` written by `impulse run --out` into Blender headless (the `bpy` wheel) and
checks it: one mesh object per body, named after it, whose world transform at each written
step equals the CSV trajectory of the same run (converted to Blender's z-up axes).

Usage: python check-blender.py ANIMATION.glb|ANIMATION.gltf TRAJECTORY.csv SCENE.json
"""

import math
import sys

import bpy
from mathutils import Matrix, Quaternion

from trajectory import Trajectory, body_names

TOLERANCE = 1e-5


def main(glb, csv_path, scene_path):
    trajectory = Trajectory(csv_path)
    names = body_names(scene_path)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    # The importer places keyframes at time × fps; with fps = 1/dt they land on step numbers.
    fps = round(1.0 / trajectory.dt())
    scene.render.fps = fps
    scene.render.fps_base = 1.0
    bpy.ops.import_scene.gltf(filepath=glb)
    meshes = {o.name: o for o in bpy.data.objects if o.type == "MESH"}
    problems = []
    if len(meshes) != trajectory.bodies:
        problems.append(f"{len(meshes)} mesh objects, {trajectory.bodies} bodies")
    # glTF is y up, Blender z up: the importer turns +90° about x.
    y_up_to_z_up = Matrix.Rotation(math.radians(90.0), 4, "X")
    compared = 0
    for step in trajectory.steps:
        frame = trajectory.times[step] * fps
        scene.frame_set(int(math.floor(frame)), subframe=frame - math.floor(frame))
        for index, (position, rotation) in enumerate(trajectory.frames[step]):
            obj = meshes.get(names[index])
            if obj is None:
                if step == trajectory.steps[0]:
                    problems.append(f"no object named {names[index]!r}")
                continue
            x, y, z, w = rotation
            expected = (
                y_up_to_z_up
                @ Matrix.Translation(position)
                @ Quaternion((w, x, y, z)).to_matrix().to_4x4()
                @ y_up_to_z_up.inverted()
            )
            got = obj.matrix_world
            if any(
                abs(got[r][c] - expected[r][c]) > TOLERANCE for r in range(4) for c in range(4)
            ):
                problems.append(
                    f"{obj.name} at step {step}: location {tuple(got.translation)}, "
                    f"expected {tuple(expected.translation)}"
                )
            compared += 1
    for problem in problems[:20]:
        print(f"  {problem}")
    print(
        f"{glb} in Blender {bpy.app.version_string}: {len(meshes)} mesh objects, "
        f"{compared} poses compared with the CSV, {len(problems)} problems"
    )
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
