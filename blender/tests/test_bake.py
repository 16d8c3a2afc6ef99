"""Baking the comparison scenes with impulse through the extension's logic, headless."""

import math

import bpy
import mathutils
import numpy as np
import pytest
from impulse_bake import axes, bake, keyframes, scene_reader
from measure import error_at_end, poses_at

import scenes

#: Frames per scene in the default run (the full 250-frame comparison is
#: scripts/blender-compare.py).
FRAMES = 24


def keyed(obj):
    """The object's baked location (F, 2, 3) and rotation (F, 2, 4) quaternion or (F, 2, 3)
    Euler keyframe points (the object's rotation mode), each point (frame, value)."""
    fcurves = keyframes._fcurve_collection(obj, create=False)

    def points(path, count):
        columns = []
        for index in range(count):
            fcurve = fcurves.find(path, index=index)
            co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
            fcurve.keyframe_points.foreach_get("co", co)
            columns.append(co.reshape(-1, 2))
        return np.stack(columns, axis=-1)

    if obj.rotation_mode == "QUATERNION":
        return points("location", 3), points("rotation_quaternion", 4)
    return points("location", 3), points("rotation_euler", 3)


@pytest.mark.parametrize("name", list(scenes.SCENES))
def test_keyframes_equal_the_library_trajectory(name):
    scene = scenes.SCENES[name](FRAMES)
    # In the quaternion rotation mode the bake keys impulse's quaternions as they are.
    for obj in scene.rigidbody_world.collection.all_objects:
        obj.rotation_mode = "QUATERNION"
    info = scene_reader.read_scene(scene)
    world, frame_steps = bake.make_world(info.scene)
    assert frame_steps == 3  # 24 fps
    trajectory = world.simulate(info.steps * frame_steps, every=frame_steps)
    dynamic = [i for i, b in enumerate(info.bodies) if b.kind == "dynamic"]
    expected_locations = axes.positions_to_blender(trajectory.positions[:, dynamic])
    expected_quaternions = axes.orientations_to_blender(trajectory.orientations[:, dynamic])
    # The start frame is keyed with the object's own values (the engine normalises quaternions).
    expected_quaternions[0] = [info.bodies[i].start["rotation_quaternion"] for i in dynamic]

    for _ in range(2):  # the second bake replaces the first and gives the same keyframes
        baker = bake.bake_scene(scene)
        assert baker.frames_done == FRAMES
        assert not scene.rigidbody_world.enabled
        for column, index in enumerate(dynamic):
            locations, quaternions = keyed(scene.objects[info.bodies[index].object_name])
            assert locations.shape == (FRAMES, 2, 3)
            np.testing.assert_array_equal(locations[:, 0, 0], np.arange(1, FRAMES + 1))
            np.testing.assert_array_equal(locations[:, 1], expected_locations[:, column])
            # Signs are made continuous between frames: q and −q are the same rotation.
            sign = np.sign(np.sum(quaternions[:, 1] * expected_quaternions[:, column], axis=1))
            assert np.all(sign != 0)
            np.testing.assert_array_equal(quaternions[:, 1], sign[:, None] * expected_quaternions[:, column])


def test_euler_keys_are_the_quaternions_rotations_without_jumps():
    rng = np.random.default_rng(7)
    # A tumbling body's orientations: a random axis turning 40° a frame, 50 frames.
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angles = np.radians(40.0) * np.arange(50)
    quaternions = np.column_stack([np.cos(angles / 2), np.outer(np.sin(angles / 2), axis)])
    obj = bpy.data.objects.new("tumbler", None)
    assert obj.rotation_mode == "XYZ"
    path, eulers = keyframes.rotation_channel(obj, quaternions)
    assert path == "rotation_euler"
    for q, e in zip(quaternions, eulers, strict=True):
        expected = mathutils.Quaternion(q).to_matrix()
        got = mathutils.Euler(e, "XYZ").to_matrix()
        assert max(abs(a - b) for row_a, row_b in zip(expected, got, strict=True) for a, b in zip(row_a, row_b, strict=True)) < 1e-5
    assert np.max(np.abs(np.diff(eulers, axis=0))) < math.pi


def test_kinematic_paddle_follows_its_animation_and_pushes_boxes():
    scene = scenes.paddle(FRAMES)
    info = scene_reader.read_scene(scene)
    paddle = next(b for b in info.bodies if b.object_name == "paddle")
    assert paddle.kind == "kinematic"
    assert len(paddle.body["keyframes"]) == FRAMES - 1
    bake.bake_scene(scene)
    scene.frame_set(FRAMES)
    assert scene.objects["paddle"].matrix_world.translation.x == pytest.approx(10.0, abs=1e-5)
    # Everything the paddle swept is ahead of it.
    for obj in scene.rigidbody_world.collection.all_objects:
        if obj.name.startswith("box"):
            assert obj.matrix_world.translation.x > 10.0 + 0.1 + 0.25 - 0.01, obj.name


def test_nothing_falls_through_the_bowl():
    frames = 72
    scene = scenes.bowl(frames)
    info = scene_reader.read_scene(scene)
    bake.bake_scene(scene)
    names = [b.object_name for b in info.bodies]
    positions, orientations = poses_at(scene, names, frames)
    error, quality = error_at_end(info, positions, orientations, static_scene=False)
    assert error <= 0.005, quality
    centre = np.array([0.0, 0.0, scenes.BOWL_CENTRE_Z])
    for obj in scene.rigidbody_world.collection.all_objects:
        if obj.name.startswith("ball"):
            offset = np.array(obj.matrix_world.translation) - centre
            # Inside the sphere of the bowl (within its radius less the ball's, and a
            # millimetre) and not below its rim's plane by more than the radius: in the bowl.
            assert np.linalg.norm(offset) <= scenes.BOWL_RADIUS - 0.25 + 1e-3, obj.name
            assert offset[2] < 0.5, obj.name


@pytest.mark.parametrize("name", ["stack30", "heavy_on_light"])
def test_stacks_hold_at_the_default_preset(name):
    frames = 96
    scene = scenes.SCENES[name](frames)
    info = scene_reader.read_scene(scene)
    bake.bake_scene(scene, preset="default")
    names = [b.object_name for b in info.bodies]
    positions, orientations = poses_at(scene, names, frames)
    error, quality = error_at_end(info, positions, orientations, static_scene=True)
    assert error <= 0.005, quality


def test_unsupported_things_are_reported_naming_the_object():
    scene = scenes.stack30(4)
    cube = scene.objects["cube03"]
    cube.rigid_body.collision_shape = "COMPOUND"
    with pytest.raises(scene_reader.UnsupportedScene) as raised:
        bake.Baker(scene)
    problems = raised.value.problems
    assert any(p.startswith("cube03: ") and "Compound" in p for p in problems), problems


def test_a_line_is_refused_naming_the_object():
    # Two points span no surface: nothing a hull could be made of.
    scene = scenes.stack30(4)
    line = bpy.data.meshes.new("line")
    line.from_pydata([(-1, 0, 0), (1, 0, 0)], [(0, 1)], [])
    obj = bpy.data.objects.new("line", line)
    scene.collection.objects.link(obj)
    obj.location = (5.0, 0.0, 1.0)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.rigidbody.object_add(type="ACTIVE")
    obj.rigid_body.collision_shape = "CONVEX_HULL"
    with pytest.raises(scene_reader.UnsupportedScene) as raised:
        bake.Baker(scene)
    assert raised.value.problems == ["line: shape Convex Hull: the mesh is a point or a line, it has no surface to collide with"]


def test_settings_map_to_the_scene_format():
    scene = scenes.heavy_on_light(4)
    heavy = scene.objects["heavy"]
    heavy.rigid_body.friction = 0.3
    heavy.rigid_body.restitution = 0.2
    heavy.rigid_body.linear_damping = 0.5
    heavy.rigid_body.collision_collections[0] = False
    heavy.rigid_body.collision_collections[3] = True
    heavy.scale = (2.0, 1.0, 0.5)
    scene.objects["light0"].rigid_body.enabled = False
    scene.render.fps = 30
    info = scene_reader.read_scene(scene)
    bodies = {b.object_name: b for b in info.bodies}
    body = bodies["heavy"].body
    assert body["kind"] == "dynamic" and body["mass"] == 100.0
    assert body["material"]["friction"] == pytest.approx(0.3)
    assert body["material"]["restitution"] == pytest.approx(0.2)
    # Blender's rule by default: Bullet's products μa·μb and ea·eb.
    assert info.scene["solver"] == {"friction_combine": "multiply", "restitution_combine": "multiply"}
    assert "solver" not in scene_reader.read_scene(scene, materials="impulse").scene
    assert body["linear_damping"] == pytest.approx(math.log(2.0))
    assert body["groups"] == body["mask"] == 1 << 3
    # Blender's x, y, z extents (2, 1, 0.5) are impulse's x, z, y.
    assert body["shape"]["half_extents"] == pytest.approx([1.0, 0.25, 0.5])
    assert bodies["light0"].kind == "static"
    assert bodies["ground"].kind == "static"
    assert info.dt == pytest.approx(1 / 30)
    assert info.scene["gravity"] == pytest.approx([0.0, -9.81, 0.0])


def test_a_bake_in_chunks_stopped_early_keeps_the_frames_done():
    # What the modal operator does: chunks of frames between events, Esc → write what is done.
    scene = scenes.dominoes(FRAMES)
    whole = bake.bake_scene(scene)
    expected = np.stack(whole.positions)
    baker = bake.Baker(scene)
    while baker.frames_done < 10:
        baker.advance(max_frames=3, max_seconds=0.0)  # at least one frame a call
    assert baker.frames_done == 10 and not baker.done
    baker.write()
    np.testing.assert_array_equal(np.stack(baker.positions), expected[:10])
    locations, _ = keyed(scene.objects["domino05"])
    assert locations.shape == (10, 2, 3)
    np.testing.assert_array_equal(locations[:, 0, 0], np.arange(1, 11))


def test_split_steps_reach_the_world_and_keep_one_step_a_frame():
    # The panel's Split Steps at one step a frame: the world gets the tolerance, the step stays a
    # frame long, and no frame leaves two dominoes crossed deeper than without it.
    scene = scenes.dominoes(FRAMES)
    worst = {}
    for split in (0.0, 0.001):
        baker = bake.Baker(scene, frame_steps=1, split_overlap=split)
        assert baker.frame_steps == 1
        assert baker.world.settings.split_overlap == pytest.approx(split)
        deepest = 0.0
        while not baker.done:
            baker.advance(max_frames=1, max_seconds=0.0)
            deepest = max(deepest, baker.world.quality()["max_overlap_m"])
        assert np.isfinite(np.stack(baker.positions)).all()
        worst[split] = deepest
    assert worst[0.001] <= max(worst[0.0], 0.001), worst


def test_collision_steps_reach_the_world_and_keep_one_step_a_frame():
    # The panel's Collision Steps (4 unless set) at one step a frame: the world gets the count, the step stays a
    # frame long (the collision steps are within it), and no frame leaves two dominoes crossed
    # deeper than in whole steps by more than half a millimetre (4.2 mm, their sink at the
    # default, in both).
    scene = scenes.dominoes(FRAMES)
    assert bake.Baker(scene, frame_steps=1).world.settings.collision_steps == 4
    worst, stepped = {}, 0
    for most in (1, 4):
        baker = bake.Baker(scene, frame_steps=1, collision_steps=most)
        assert baker.frame_steps == 1
        assert baker.world.settings.collision_steps == most
        deepest = 0.0
        while not baker.done:
            baker.advance(max_frames=1, max_seconds=0.0)
            deepest = max(deepest, baker.world.quality()["max_overlap_m"])
            stepped += most > 1 and baker.world.diagnostics["collision_steps"] > 1
        assert np.isfinite(np.stack(baker.positions)).all()
        worst[most] = deepest
    assert stepped > 0  # dominoes striking the next take some frames in collision steps
    assert worst[4] <= worst[1] + 0.0005, worst
