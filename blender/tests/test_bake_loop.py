"""The bake loop as an animator lives it: edit, bake, edit again, re-bake, a refused bake, free
the bake; and the messages of a refused bake, all at once, in the animator's terms."""

import re

import bpy
import pytest
from impulse_bake import bake, keyframes, messages, scene_reader

import field

FRAMES = 24


def _drop_scene():
    # A cube dropped 10 cm onto the ground: it lands and rests where it fell.
    scene = field.startup(FRAMES)
    field.ground()
    cube = field.add("cube", "Cube", size=1.0, location=(0.0, 0.0, 0.6))
    cube.rotation_euler = (0.0, 0.0, 0.4)
    field.rigid(cube)
    return scene, cube


def test_a_rebake_starts_from_an_unkeyed_edit_at_the_start_frame():
    scene, cube = _drop_scene()
    bake.bake_scene(scene)
    scene.frame_set(1)
    cube.location.x = 3.0  # moved in the viewport, not keyed
    bake.bake_scene(scene)
    assert field.world_at(scene, cube, 1).translation.x == pytest.approx(3.0, abs=1e-5)
    assert field.world_at(scene, cube, FRAMES).translation.x == pytest.approx(3.0, abs=0.01)


def test_a_rebake_starts_from_a_keyed_edit_made_at_another_frame():
    scene, cube = _drop_scene()
    bake.bake_scene(scene)
    scene.frame_set(1)
    cube.location.y = -2.0
    cube.keyframe_insert("location", frame=1)
    scene.frame_set(12)
    bake.bake_scene(scene)
    assert field.world_at(scene, cube, 1).translation.y == pytest.approx(-2.0, abs=1e-5)
    assert field.world_at(scene, cube, FRAMES).translation.y == pytest.approx(-2.0, abs=0.01)


def test_a_refused_bake_keeps_the_previous_bake_and_the_world():
    scene, cube = _drop_scene()
    bake.bake_scene(scene)
    before = [tuple(fc.keyframe_points[-1].co) for fc in keyframes.baked_fcurves(cube)]
    assert len(before) == 6  # location and Euler rotation: the rotation mode is kept
    cube.rigid_body.collision_shape = "COMPOUND"
    with pytest.raises(scene_reader.UnsupportedScene):
        bake.Baker(scene)
    assert [tuple(fc.keyframe_points[-1].co) for fc in keyframes.baked_fcurves(cube)] == before
    assert not scene.rigidbody_world.enabled
    assert field.world_at(scene, cube, FRAMES).translation.z == pytest.approx(0.5, abs=0.01)


def test_a_cancelled_bake_keeps_the_previous_bake():
    scene, cube = _drop_scene()
    bake.bake_scene(scene)
    before = [tuple(fc.keyframe_points[-1].co) for fc in keyframes.baked_fcurves(cube)]
    cube.location.x = 5.0
    baker = bake.Baker(scene)
    baker.advance(max_frames=5)
    del baker  # what Esc does: the frames done are dropped, nothing written
    assert [tuple(fc.keyframe_points[-1].co) for fc in keyframes.baked_fcurves(cube)] == before


def test_free_bake_removes_everything_the_bake_left():
    scene, cube = _drop_scene()
    start = field.world_at(scene, cube, 1)
    properties_before = set(cube.keys())
    bake.bake_scene(scene)
    assert cube.animation_data is not None
    assert bake.free_bake(scene) == 1
    assert cube.animation_data is None
    assert not [a for a in bpy.data.actions if a.users == 0 or keyframes.MADE in a]
    assert cube.rotation_mode == "XYZ"
    assert set(cube.keys()) == properties_before
    assert scene.rigidbody_world.enabled
    assert (field.world_at(scene, cube, 1).translation - start.translation).length < 1e-6


def test_free_bake_gives_a_thrown_object_its_animation_back():
    scene = field.startup(FRAMES)
    ball = field.add("uv_sphere", "Ball", radius=0.5, location=(0.0, 0.0, 2.0))
    field.rigid(ball)
    field.key(ball, "location", 1, (0.0, 0.0, 2.0))
    field.key(ball, "location", 5, (1.0, 0.0, 2.0))
    field.key(ball, "rigid_body.kinematic", 1, True, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 6, False, interpolation=None)
    action = ball.animation_data.action
    bake.bake_scene(scene)
    assert ball.animation_data.action is not action
    bake.free_bake(scene)
    assert ball.animation_data.action is action
    assert not action.use_fake_user
    assert len(bpy.data.actions) == 1
    assert field.world_at(scene, ball, 5).translation.x == pytest.approx(1.0, abs=1e-6)


def test_a_second_bake_of_an_unchanged_scene_is_no_heavier(tmp_path):
    scene, cube = _drop_scene()
    for i in range(10):
        other = field.add("cube", f"Box{i}", size=0.5, location=(i - 5.0, 2.0, 1.0 + 0.1 * i))
        field.rigid(other)
    bake.bake_scene(scene)
    first = tmp_path / "first.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(first), copy=True)
    actions = len(bpy.data.actions)
    bake.bake_scene(scene)
    second = tmp_path / "second.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(second), copy=True)
    assert len(bpy.data.actions) == actions
    assert sum(len(keyframes.baked_fcurves(o)) for o in scene.objects) == 11 * 6
    assert abs(second.stat().st_size - first.stat().st_size) <= 0.05 * first.stat().st_size


def test_every_problem_is_reported_at_once_in_the_animators_terms():
    scene, cube = _drop_scene()
    cube.rigid_body.collision_shape = "COMPOUND"
    other = field.add("cube", "Sheet", size=1.0, location=(3.0, 0.0, 2.0))
    other.scale = (1.0, 0.0, 1.0)
    field.rigid(other)
    with pytest.raises(scene_reader.UnsupportedScene) as raised:
        bake.Baker(scene)
    problems = raised.value.problems
    assert len(problems) == 2, problems
    assert problems[0].startswith("Cube: shape Compound Parent ")
    assert problems[1].startswith("Sheet: its scale ")


def test_the_engines_refusals_are_translated_for_every_body():
    scene = field.startup(4)
    for name, x in (("Left", -2.0), ("Right", 2.0)):
        obj = field.add("cube", name, size=1.0, location=(x, 0.0, 2.0))
        field.rigid(obj)
        obj.rigid_body.collision_shape = "BOX"
    info = scene_reader.read_scene(scene)
    for body in info.scene["bodies"]:
        body["shape"]["half_extents"][0] = -1.0  # what the engine refuses

    def build(scene_dict):
        bake.make_world(scene_dict)

    try:
        build(info.scene)
    except Exception as error:  # the engine's SceneError
        problems = messages.every_problem(info, error, build)
    else:
        pytest.fail("the engine took a negative half extent")
    assert [p.split(":")[0] for p in problems] == ["Left", "Right"]
    for problem in problems:
        assert problem.startswith(problem.split(":")[0] + ": shape Box: ")
        assert "bodies[" not in problem and not re.search(r":\d+:\d+", problem), problem


#: One Blender session (a fresh Python process with ``bpy``): a ring (a torus, Physics › Rigid
#: Body, shape Mesh: split into convex parts) and, with the argument ``two``, a second, larger
#: ring, read for a bake; prints the cache directory and the seconds the world took to build.
SESSION = """
import json, sys, time
sys.path[:0] = sys.argv[1:3]
import field
from impulse_bake import bake
scene = field.startup(4)
for name, radius in [("Ring", 1.0), ("Ring2", 1.5)][: 2 if sys.argv[3] == "two" else 1]:
    ring = field.add("torus", name, major_radius=radius, location=(3.0 * radius, 0.0, 3.0))
    field.rigid(ring)
    ring.rigid_body.collision_shape = "MESH"
start = time.perf_counter()
bake.Baker(scene)
print(json.dumps({"directory": bake.decomposition_cache_directory(), "seconds": time.perf_counter() - start}))
"""


def _session(user, rings):
    import json
    import os
    import pathlib
    import subprocess
    import sys

    tests = pathlib.Path(__file__).resolve().parent
    done = subprocess.run(
        [sys.executable, "-c", SESSION, str(tests), str(tests.parent), rings],
        env=dict(os.environ, BLENDER_USER_DATAFILES=str(user)),
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_mesh_split_in_one_session_is_read_in_the_next(tmp_path):
    """The convex parts of a moving Mesh shape are kept in the add-on's user directory: a new
    session reads them (the file is not written again) and adds the parts of a new mesh."""
    import os

    first = _session(tmp_path / "user", "one")
    directory = first["directory"]
    assert directory.startswith(str(tmp_path / "user"))
    kept = os.listdir(directory)
    assert len(kept) == 1 and kept[0].endswith(".vhacd")
    path = os.path.join(directory, kept[0])
    long_ago = 946_684_800  # 2000-01-01: a file written again would have a new time
    os.utime(path, (long_ago, long_ago))

    second = _session(tmp_path / "user", "two")
    assert second["directory"] == directory
    assert len(os.listdir(directory)) == 2, "the new ring's parts are kept too"
    assert os.stat(path).st_mtime == long_ago, "the first ring's parts were read, not split again"
