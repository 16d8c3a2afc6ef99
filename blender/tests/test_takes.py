"""The Takes panel's logic and operators: goals set on objects, a search in a child process, and
"Bake take" keying exactly the take's trajectory."""

import math
import os
import sys

import bpy
import mathutils
import numpy as np
import pytest
from impulse_bake import axes, bake, keyframes, scene_reader
from impulse_bake import takes as takes_logic
import field
import scenes
from addon import load_addon

pytestmark = pytest.mark.usefixtures("addon")


@pytest.fixture(scope="module")
def addon(tmp_path_factory):
    """The add-on registered, loaded as test_operator.py loads it (from the zip named by
    ``IMPULSE_BLENDER_ADDON_ZIP``, else the source directory), or the module it already loaded
    in this session (its fixture checks that the module it imports is its own copy)."""
    module = sys.modules.get("impulse_blender")
    loaded_here = module is None
    if loaded_here:
        module = load_addon(tmp_path_factory, keep_path=False)
    module.register()
    yield module
    module.unregister()
    if loaded_here:  # test_operator.py loads its own copy afterwards
        for name in [n for n in sys.modules if n == "impulse_blender" or n.startswith("impulse_blender.")]:
            del sys.modules[name]

FRAMES = 61  # 2.5 s at 24 fps


def _die_scene():
    """A 0.2 m die dropped from 0.6 m onto a passive plane, tipped so it tumbles; the search
    varies its start angle, velocity and spin."""
    scene = scenes._reset(FRAMES)
    scenes._ground(scene, half=5.0)
    die = scenes._add(
        scene, "die", scenes._box_mesh("die", (0.2, 0.2, 0.2)), (0.0, 0.0, 0.6), rotation=(0.4, 0.3, 0.0)
    )
    die.rotation_mode = "QUATERNION"  # keyed as quaternions, compared component by component
    die.rotation_quaternion = mathutils.Euler((0.4, 0.3, 0.0)).to_quaternion()
    settings = scene.impulse_takes
    settings.position, settings.angle, settings.velocity, settings.angular_velocity = 0.0, 90.0, 1.0, 8.0
    settings.budget, settings.population, settings.stop_after, settings.workers = 64, 16, 1, 2
    scene.impulse_bake.preset = "fast"
    return scene, die


def test_goals_are_read_in_impulse_axes():
    scene, die = _die_scene()
    region = bpy.data.objects.new("target", None)
    scene.collection.objects.link(region)
    region.empty_display_type = "CUBE"
    region.empty_display_size = 0.5
    region.location = (1.0, 2.0, 0.25)
    region.scale = (2.0, 1.0, 1.0)
    bpy.context.view_layer.update()
    die.impulse_takes.region = region
    die.impulse_takes.face_up = "NEG_Y"
    die.impulse_takes.hits = scene.objects["ground"]
    info = scene_reader.read_scene(scene)
    goals = {g["type"]: g for g in takes_logic.read_goals(scene, info)}
    # Blender (x, y, z) is impulse (x, z, -y): the box x 0..2, y 1.5..2.5, z -0.25..0.75.
    box = goals["ends_inside"]["region"]["box"]
    assert box["min"] == pytest.approx([0.0, -0.25, -2.5])
    assert box["max"] == pytest.approx([2.0, 0.75, -1.5])
    # The die's local -Y is impulse's body-frame +Z; up is Blender's +Z, impulse's +Y.
    assert goals["rests_with_axis_up"]["axis"] == [0.0, 0.0, 1.0]
    assert goals["rests_with_axis_up"]["up"] == [0.0, 1.0, 0.0]
    assert goals["touches"]["other"] == "ground"
    die.impulse_takes.region = None
    die.impulse_takes.face_up = "NONE"
    die.impulse_takes.hits = None
    with pytest.raises(scene_reader.UnsupportedScene, match="no object has a goal"):
        takes_logic.read_goals(scene, info)


def test_the_searched_scene_steps_as_the_bake():
    """The scene file a search varies gives the bake's bits with no settings besides it."""
    scene, _ = _die_scene()
    info = scene_reader.read_scene(scene)
    searched, count = takes_logic.search_scene(info, "fast")
    impulse = bake.import_impulse()
    world = impulse.World.from_scene(searched)
    baked, baked_count = bake.make_world(info.scene, "fast")
    assert count == baked_count == 3 and searched["steps"] == (FRAMES - 1) * 3
    for _ in range(20):
        world.step(count)
        baked.step(count)
    assert np.array_equal(world.positions, baked.positions)
    assert np.array_equal(world.orientations, baked.orientations)


def test_a_die_search_finds_a_take_and_bake_take_keys_it(tmp_path, monkeypatch):
    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    settings = scene.impulse_takes
    assert settings.directory.startswith(str(tmp_path))
    assert len(settings.takes) > 0 and settings.takes[0].met
    take_id = settings.takes[0].take_id

    assert bpy.ops.impulse.bake_take() == {"FINISHED"}
    assert not scene.rigidbody_world.enabled
    scene.frame_set(FRAMES)
    up = die.matrix_world.to_3x3().normalized() @ mathutils.Vector((0.0, 0.0, 1.0))
    assert up.z > math.cos(math.radians(10.0))

    # The keyframes are the take's trajectory: impulse.World.from_scene(take.scene()) stepped
    # the bake's steps per frame, in Blender's axes, to the bit of the F-curves' float32.
    from impulse.takes import load

    take = load(settings.directory)[take_id]
    world = bake.import_impulse().World.from_scene(take.scene())
    count = bake.steps_per_frame(scene.rigidbody_world.time_scale / scene.render.fps)
    row = world.index_of(world.handle_of(world.names.index("die")))
    positions, orientations = [world.positions[row].copy()], [world.orientations[row].copy()]
    for _ in range(FRAMES - 1):
        world.step(count)
        positions.append(world.positions[row].copy())
        orientations.append(world.orientations[row].copy())
    locations = axes.positions_to_blender(np.stack(positions))
    quaternions = axes.continuous_quaternions(axes.orientations_to_blender(np.stack(orientations))[:, None])[:, 0]
    fcurves = keyframes._fcurve_collection(die, create=False)
    for index in range(3):
        keyed = [p.co[1] for p in fcurves.find("location", index=index).keyframe_points]
        assert np.array_equal(np.float32(keyed), np.float32(locations[:, index]))
    for index in range(4):
        keyed = [p.co[1] for p in fcurves.find("rotation_quaternion", index=index).keyframe_points]
        assert len(keyed) == FRAMES
        assert np.array_equal(np.float32(keyed), np.float32(quaternions[:, index]))


def test_bake_take_refuses_a_scene_changed_since_the_search(tmp_path, monkeypatch):
    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    settings = scene.impulse_takes
    settings.budget, settings.stop_after = 16, 16
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    die.location.z += 0.1
    with pytest.raises(RuntimeError, match="changed since take"):
        bpy.ops.impulse.bake_take()
    assert scene.rigidbody_world.enabled


@pytest.fixture(scope="module")
def impulse_cli():
    """The ``impulse`` command that draws the stills: ``$IMPULSE_CLI``, else the repository's
    release build, else ``PATH``. Missing, the tests that need it are skipped, unless
    ``IMPULSE_REQUIRE_CLI=1`` (as in CI), where they fail."""
    import shutil

    repository = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    for candidate in (
        os.environ.get("IMPULSE_CLI"),
        os.path.join(repository, "target", "release", "impulse"),
        shutil.which("impulse"),
    ):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    message = "the impulse command is not built (cargo build --release -p impulse-cli)"
    if os.environ.get("IMPULSE_REQUIRE_CLI") == "1":
        pytest.fail(message)
    pytest.skip(message)


def _render_frames(cli, scene_path, steps, out, camera=()):
    """``impulse render`` of a scene file's first and last frames at the stills' size, with the
    ``camera`` flags given."""
    import subprocess

    size = "{}x{}".format(*takes_logic.PREVIEW_SIZE)
    subprocess.run(
        [cli, "render", scene_path, "--out", str(out), "--steps", str(steps), "--every", str(steps)]
        + ["--size", size, "--quiet", *camera],
        check=True,
    )
    with open(out / f"frame_{steps:05d}.png", "rb") as last, open(out / "frame_00000.png", "rb") as first:
        return first.read(), last.read()


def test_listed_takes_show_a_still_of_their_end(tmp_path, monkeypatch, addon, impulse_cli):
    """After a search, every listed take has a still: the last frame ``impulse render`` draws of
    the take's own scene (the same bytes; not its first frame), loaded for the list's icons."""
    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    settings = scene.impulse_takes
    settings.budget, settings.stop_after = 16, 16
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    monkeypatch.setenv("IMPULSE_CLI", impulse_cli)
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert settings.previews_note == ""
    takes_ui = sys.modules[addon.__name__ + ".takes_ui"]
    from impulse.takes import load

    found = load(settings.directory)
    steps = int(found.manifest["steps"])
    stills = {}
    for item in settings.takes:
        path = takes_logic.preview_path(settings.directory, item.take_id)
        with open(path, "rb") as file:
            stills[item.take_id] = file.read()
        image = bpy.data.images.load(path)
        assert tuple(image.size) == takes_logic.PREVIEW_SIZE
        bpy.data.images.remove(image)
        # Loaded for the list (Blender in the background makes no icon ids, only the image).
        assert tuple(takes_ui.preview(settings.directory, item.take_id).image_size) == takes_logic.PREVIEW_SIZE
    assert len(stills) == len(settings.takes) > 1
    assert len(set(stills.values())) > 1, "different takes end differently"
    chosen = settings.takes[0].take_id
    scene_path = tmp_path / "chosen.json"
    found[chosen].write_scene(str(scene_path))
    # Framed as the contact sheet's "goals" camera frames the take's preview.
    from impulse.takes._sheet import _camera_arguments

    camera = _camera_arguments("goals", found[chosen], found, takes_logic.PREVIEW_SIZE)
    assert camera
    first, last = _render_frames(impulse_cli, str(scene_path), steps, tmp_path / "frames", camera)
    assert stills[chosen] == last
    assert stills[chosen] != first


def test_without_the_impulse_command_the_list_says_why_it_has_no_stills(tmp_path, monkeypatch, addon):
    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    settings = scene.impulse_takes
    settings.budget, settings.stop_after = 16, 16
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    monkeypatch.setenv("IMPULSE_CLI", str(tmp_path / "no-such-impulse"))
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert len(settings.takes) > 0
    assert "impulse command is not found" in settings.previews_note
    takes_ui = sys.modules[addon.__name__ + ".takes_ui"]
    assert takes_ui.preview(settings.directory, settings.takes[0].take_id) is None


def test_goals_read_from_objects_score_the_bake():
    """The goals, run on the unvaried scene: the die lands near the origin on the ground, so a
    box around the origin and the ground are met, a box 2 m away along Blender's y is missed
    by about its distance, and the face it lands on is up."""
    scene, die = _die_scene()
    near, far = (bpy.data.objects.new(name, None) for name in ("near", "far"))
    for empty, location in ((near, (0.0, 0.0, 0.0)), (far, (0.0, 2.5, 0.0))):
        scene.collection.objects.link(empty)
        empty.empty_display_type = "CUBE"
        empty.empty_display_size = 0.5
        empty.location = location
    bpy.context.view_layer.update()
    die.impulse_takes.region = near
    die.impulse_takes.hits = scene.objects["ground"]
    info = scene_reader.read_scene(scene)
    searched, _ = takes_logic.search_scene(info, "fast")
    goals = takes_logic.read_goals(scene, info)
    die.impulse_takes.region = far
    goals.append(dict(takes_logic.read_goals(scene, info)[0], name="far"))
    from impulse.takes import evaluate

    costs = evaluate(searched, goals, searched["steps"])
    assert costs["die ends inside near"] == 0.0
    assert costs["die hits ground"] == 0.0
    end = bake.import_impulse().World.from_scene(searched)
    end.step(searched["steps"])
    x, y, z = axes.positions_to_blender(end.positions[end.names.index("die")])
    assert abs(x) < 0.5 and abs(y) < 0.5 and abs(z - 0.1) < 0.01
    assert costs["far"] == pytest.approx(2.0 - y, abs=1e-6)


def test_a_cancelled_search_keeps_its_takes_and_resumes(tmp_path):
    """What Esc does in the panel: the child stopped after a generation; its takes are listed,
    and the same request run again reads them instead of running them."""
    import time

    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    variation = {"position": 0.0, "angle": 90.0, "velocity": 1.0, "angular_velocity": 8.0}
    request = takes_logic.build_request(scene, variation, population=8, preset="fast")
    job = takes_logic.SearchJob(str(tmp_path / "search"), request, budget=10_000, stop_after=10_000, workers=2)
    deadline = time.monotonic() + 60.0
    while job.takes_done() < 8 and job.running() and time.monotonic() < deadline:
        time.sleep(0.2)
    job.cancel()
    kept = job.finish()
    assert len(kept) >= 8
    again = takes_logic.SearchJob(str(tmp_path / "search"), request, budget=8, workers=2).wait()
    assert set(again) <= set(kept) and len(again) == len(kept)


@pytest.mark.skipif(
    not os.environ.get("IMPULSE_TAKES_SEEDS"), reason="on demand: IMPULSE_TAKES_SEEDS=1 (docs/testing.md)"
)
def test_die_searches_over_seeds(tmp_path):
    """Five searches of the die panel scene (seeds 0-4): each finds a +Z-up take within 64
    takes; prints the takes each needed to its first success."""
    scene, die = _die_scene()
    die.impulse_takes.face_up = "POS_Z"
    variation = {"position": 0.0, "angle": 90.0, "velocity": 1.0, "angular_velocity": 8.0}
    firsts = []
    for seed in range(5):
        request = takes_logic.build_request(scene, variation, seed=seed, population=16, preset="fast")
        found = takes_logic.SearchJob(str(tmp_path / f"seed{seed}"), request, budget=64, workers=2).wait()
        rows = found.table.to_pylist()
        met = [row["generation"] * 16 + row["index"] + 1 for row in rows if row["met"]]
        assert met, f"seed {seed}: no take met the goal in {len(rows)} takes"
        firsts.append(min(met))
    print(f"takes to the first +Z-up die, seeds 0-4: {firsts}, median {sorted(firsts)[2]}")


def _animator_die_scene(ground="plane"):
    """The die shot as an animator makes it: the factory startup file, the default cube
    deleted, a 0.2 m cube added tipped 0.6 m up and a ground added from the Add menu (a Plane,
    or a cube slab), each given Physics › Rigid Body with its default shape (Convex Hull); the
    die's +Z face up as the goal, the search's settings on the panel."""
    scene = field.startup(FRAMES)
    die = field.add("cube", "Die", size=0.2, location=(0.0, 0.0, 0.6), rotation=(0.4, 0.3, 0.0))
    field.rigid(die)
    if ground == "plane":
        field.rigid(field.add("plane", "Ground", size=10.0), "PASSIVE")
    else:
        field.ground()
    die.impulse_takes.face_up = "POS_Z"
    settings = scene.impulse_takes
    settings.position, settings.angle, settings.velocity, settings.angular_velocity = 0.0, 90.0, 1.0, 8.0
    settings.budget, settings.population, settings.stop_after, settings.workers = 16, 16, 16, 2
    scene.impulse_bake.preset = "fast"
    return scene, die


def _shown(obj):
    """What the viewport shows of ``obj``: its location and rotation channels, and its world
    matrix rounded to 1e-6 (the operator that added it set the matrix, Blender's evaluation
    of the channels may differ in the last bit)."""
    return (
        tuple(obj.location),
        tuple(obj.rotation_euler),
        tuple(obj.rotation_quaternion),
        [tuple(round(v, 6) + 0.0 for v in row) for row in obj.matrix_world],
    )


def test_free_after_bake_take_puts_back_the_pose_the_animator_set(tmp_path, monkeypatch):
    scene, die = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    authored = _shown(die)
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    settings = scene.impulse_takes
    first, second = settings.takes[0].take_id, settings.takes[1].take_id

    assert bpy.ops.impulse.bake_take(take_id=first) == {"FINISHED"}
    scene.frame_set(1)
    varied = _shown(die)
    assert varied[1] != authored[1], "the take starts tipped otherwise than the animator set"
    # Another take baked over it is still a take of the same scene (not refused as changed).
    assert bpy.ops.impulse.bake_take(take_id=second) == {"FINISHED"}
    scene.frame_set(1)
    assert _shown(die) != varied

    scene.frame_set(30)
    assert bpy.ops.impulse.free_bake() == {"FINISHED"}
    assert _shown(die) == authored
    scene.frame_set(1)
    assert _shown(die) == authored
    assert scene.rigidbody_world.enabled
    assert not keyframes.is_baked(die) and keyframes.AUTHORED not in die


def test_bake_with_impulse_after_a_take_starts_from_the_pose_the_animator_set(tmp_path, monkeypatch):
    scene, die = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    authored = _shown(die)
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert bpy.ops.impulse.bake_take() == {"FINISHED"}
    scene.frame_set(1)
    assert _shown(die) != authored
    assert bpy.ops.impulse.bake() == {"FINISHED"}
    scene.frame_set(1)
    assert _shown(die) == authored
    # A baked die moved in the viewport at the start frame starts where it was put.
    die.location.x += 0.5
    bpy.context.view_layer.update()
    info = scene_reader.read_scene(scene)
    assert info.scene["bodies"][[b.object_name for b in info.bodies].index("Die")]["position"][0] == pytest.approx(
        authored[0][0] + 0.5
    )


class _Layout:
    """A stand-in for a panel's layout that keeps the labels drawn: (text, icon)."""

    def __init__(self, labels):
        self.labels = labels

    def column(self, **_options):
        return self

    row = column

    def label(self, text="", icon="NONE", **_options):
        self.labels.append((text, icon))

    def prop(self, *_arguments, **_options):
        pass

    operator = template_list = template_icon = prop


def _takes_panel_labels(addon):
    """The labels the scene's impulse Takes panel draws now, as (text, icon)."""
    import types

    labels = []
    panel = sys.modules[addon.__name__ + ".takes_ui"].SCENE_PT_impulse_takes
    panel.draw(types.SimpleNamespace(layout=_Layout(labels)), bpy.context)
    return labels


def _said(labels, icon):
    """The text of the note whose first line has ``icon``, its lines joined, without spaces
    (a long word, a path, is cut across lines)."""
    start = next(i for i, (_, shown) in enumerate(labels) if shown == icon)
    lines = [labels[start][0]]
    for text, shown in labels[start + 1 :]:
        if shown != "BLANK1":
            break
        lines.append(text)
    return "".join("".join(lines).split())


def test_a_search_whose_pyarrow_needs_another_numpy_says_so_in_the_panel(tmp_path, monkeypatch, addon):
    """Blender's Python with a pyarrow built for NumPy 2 (``pip install pyarrow`` into Blender
    5.0, whose NumPy is 1.26): the search child fails importing it. The panel says that, and
    what to install, not that the directory holds no takes."""
    scene, _ = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    # pyarrow 26's own refusal, from a package that shadows the installed one in the child
    # only: its sitecustomize puts the shadow first, before the directory impulse came from.
    broken = tmp_path / "shadow" / "pyarrow"
    broken.mkdir(parents=True)
    (broken / "__init__.py").write_text('raise ImportError("pyarrow requires NumPy 2.0 or newer, found 1.26.4")\n')
    (tmp_path / "site").mkdir()
    (tmp_path / "site" / "sitecustomize.py").write_text(f"import sys\nsys.path.insert(0, {str(broken.parent)!r})\n")
    monkeypatch.setenv("PYTHONPATH", str(tmp_path / "site"))
    settings = scene.impulse_takes
    with pytest.raises(RuntimeError, match="pyarrow requires NumPy 2.0 or newer"):
        bpy.ops.impulse.takes_search()
    note = settings.search_note
    assert note.startswith("the search failed (exit code 1): ImportError: pyarrow requires NumPy 2.0 or newer")
    # The pyarrow for this Python's NumPy (Blender 5.0's 1.26: below 19).
    wanted = "'pyarrow<19'" if int(np.__version__.split(".")[0]) < 2 else "--upgrade pyarrow"
    assert f"{sys.executable} -m pip install {wanted}" in note
    assert "not a takes search directory" not in note
    assert len(settings.takes) == 0
    assert _said(_takes_panel_labels(addon), "ERROR") == "".join(note.split())

    monkeypatch.delenv("PYTHONPATH")
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert settings.search_note == "" and len(settings.takes) > 0
    listed = (settings.directory, [item.take_id for item in settings.takes])
    # The child ran, but this process cannot import pyarrow to read its table; a search of
    # another seed fails so, and the takes listed stay with their directory (Bake Take reads it).
    settings.seed = 1
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)
    with pytest.raises(RuntimeError, match=f"cannot read the takes in .*pip install {wanted}"):
        bpy.ops.impulse.takes_search()
    assert settings.search_note.startswith("cannot read the takes in ")
    assert (settings.directory, [item.take_id for item in settings.takes]) == listed


def test_a_search_that_fails_says_the_childs_error_in_the_panel(tmp_path, monkeypatch):
    """A child that stops with its own error (exit code 2) is shown by that error."""
    scene, _ = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    scene.impulse_takes.population = 2
    request = takes_logic.build_request(scene, {"position": 0.0, "angle": 90.0, "velocity": 1.0, "angular_velocity": 8.0})
    request["goals"][0]["body"] = "Dice"
    job = takes_logic.SearchJob(str(tmp_path / "search"), request, budget=4, workers=1)
    with pytest.raises(RuntimeError) as failed:
        job.wait()
    assert str(failed.value).startswith("the search failed (exit code 2): ")
    assert "Dice" in str(failed.value)


def _die_pixels(path):
    """Pixels of a still that show the die: ``impulse render`` draws moving bodies blue, the
    ground grey and the sky pale."""
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:]).reshape(-1, 4)
    bpy.data.images.remove(image)
    red, green, blue = pixels[:, 0], pixels[:, 1], pixels[:, 2]
    return int(np.sum((blue > red + 0.15) & (blue > green + 0.1)))


def test_a_plane_grounds_takes_have_stills_with_the_plane_drawn(tmp_path, monkeypatch, impulse_cli):
    """The die on a Plane ground (the tutorial's ground): every listed take has its still,
    framed on the die where it rests (at least 20 × 20 of its pixels, where ``impulse
    render``'s own view of the start showed it about 18 × 18 and let it roll out of frame), and
    the Plane is in it (the take's first frame differs from the same frame without it)."""
    scene, _ = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    monkeypatch.setenv("IMPULSE_CLI", impulse_cli)
    settings = scene.impulse_takes
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert settings.previews_note == ""
    assert len(settings.takes) > 1
    for item in settings.takes:
        assert _die_pixels(takes_logic.preview_path(settings.directory, item.take_id)) >= 20 * 20, item.take_id
    import json

    from impulse.takes import load

    take = load(settings.directory)[settings.takes[0].take_id]
    with_plane = tmp_path / "with.json"
    take.write_scene(str(with_plane))
    written = json.loads(with_plane.read_text())
    written["bodies"] = [body for body in written["bodies"] if body.get("name") != "Ground"]
    without_plane = tmp_path / "without.json"
    without_plane.write_text(json.dumps(written))
    first_with, _ = _render_frames(impulse_cli, str(with_plane), 1, tmp_path / "with")
    first_without, _ = _render_frames(impulse_cli, str(without_plane), 1, tmp_path / "without")
    assert first_with != first_without


def test_a_still_that_cannot_be_drawn_is_explained_in_the_panel(tmp_path, monkeypatch, addon):
    """``impulse render`` refusing a take's scene: the panel says how many stills are missing
    and why, the engine's body index as the object's name."""
    scene, _ = _animator_die_scene()
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))
    refusing = tmp_path / "impulse"
    refusing.write_text("#!/bin/sh\necho 'error: cannot draw body 1: the convex hull of 8 points has no volume' >&2\nexit 2\n")
    refusing.chmod(0o755)
    monkeypatch.setenv("IMPULSE_CLI", str(refusing))
    settings = scene.impulse_takes
    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    listed = len(settings.takes)
    assert listed > 1
    assert settings.previews_note.startswith(f"No still for {listed} of {listed} takes: impulse render of take ")
    assert settings.previews_note.endswith(' failed: cannot draw body "Ground": the convex hull of 8 points has no volume')
    assert _said(_takes_panel_labels(addon), "INFO") == "".join(settings.previews_note.split())


def test_a_keyed_throw_is_searched_from_its_release_and_baked(tmp_path, monkeypatch):
    """The bowling shot as an animator keys it: a ball animated with Animated ticked to frame
    10, Animated keyed off at 11, toward a pin it should hit. The take starts at the release
    with the keys' velocity (varied like any start); Bake Take keys the animation until the
    release and the take's world from it, to the bit of the F-curves' float32."""
    scene = field.startup(FRAMES)
    field.ground()
    pin = field.add("cube", "Pin", size=0.2, location=(4.0, 0.0, 0.3))
    pin.scale = (1.0, 1.0, 3.0)
    field.rigid(pin)
    pin.impulse_takes.vary = False
    ball = field.add("uv_sphere", "Ball", radius=0.2, location=(0.0, 0.0, 0.2))
    field.rigid(ball)
    field.key(ball, "location", 1, (0.0, 0.0, 0.2))
    field.key(ball, "location", 10, (1.5, 0.0, 0.2))
    field.key(ball, "rigid_body.kinematic", 1, True, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 10, True, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 11, False, interpolation=None)
    ball.impulse_takes.hits = pin
    settings = scene.impulse_takes
    settings.position, settings.angle, settings.velocity, settings.angular_velocity = 0.0, 0.0, 0.5, 0.0
    settings.budget, settings.population, settings.stop_after, settings.workers = 8, 8, 8, 2
    scene.impulse_bake.preset = "fast"
    monkeypatch.setattr(takes_logic.tempfile, "gettempdir", lambda: str(tmp_path))

    assert bpy.ops.impulse.takes_search() == {"FINISHED"}
    assert settings.takes[0].met
    from impulse.takes import load

    found = load(settings.directory)
    names = [b["name"] for b in found.base_scene["bodies"]]
    thrown = found.base_scene["bodies"][names.index("Ball")]
    # Released after frame 10 at the keys' last velocity: 1.5 m in 9 frames at 24 fps, along x.
    assert thrown["kind"] == "dynamic"
    assert thrown["linear_velocity"] == pytest.approx([4.0, 0.0, 0.0], abs=1e-4)
    count = bake.steps_per_frame(1.0 / scene.render.fps)
    assert found.base_scene["steps"] == (FRAMES - 10) * count
    take = found[settings.takes[0].take_id]
    varied = take.scene()["bodies"][names.index("Ball")]["linear_velocity"]
    assert varied != thrown["linear_velocity"]

    assert bpy.ops.impulse.bake_take() == {"FINISHED"}
    fcurves = keyframes._fcurve_collection(ball, create=False)
    keyed = np.float32([[p.co[1] for p in fcurves.find("location", index=k).keyframe_points] for k in range(3)]).T
    assert len(keyed) == FRAMES
    # Until the release, the animation (linear keys: frame 5 is 4/9 of the way).
    assert keyed[4] == pytest.approx([1.5 * 4 / 9, 0.0, 0.2], abs=1e-5)
    # From the release, the take's world.
    world = bake.import_impulse().World.from_scene(take.scene())
    row = world.index_of(world.handle_of(names.index("Ball")))
    positions = [world.positions[row].copy()]
    for _ in range(FRAMES - 10):
        world.step(count)
        positions.append(world.positions[row].copy())
    assert np.array_equal(keyed[9:], np.float32(axes.positions_to_blender(np.stack(positions))))
    pin_end = field.world_at(scene, pin, FRAMES).translation
    assert pin_end.x > 4.05 or pin_end.z < 0.25, "the pin was hit"

    # Another take over it, then Free: the throw's own animation back, the pin at its start.
    assert bpy.ops.impulse.bake_take(take_id=settings.takes[1].take_id) == {"FINISHED"}
    assert bpy.ops.impulse.free_bake() == {"FINISHED"}
    assert field.world_at(scene, ball, 5).translation.x == pytest.approx(1.5 * 4 / 9, abs=1e-5)
    assert tuple(field.world_at(scene, pin, 1).translation) == pytest.approx((4.0, 0.0, 0.3), abs=1e-6)


def test_a_search_where_no_take_meets_the_goals_lists_its_takes(tmp_path):
    """Exit code 1 with the child's summary is a search that ran (no take met every goal),
    not a failure: its takes are read."""
    scene, die = _animator_die_scene()
    far = bpy.data.objects.new("Far", None)
    scene.collection.objects.link(far)
    far.empty_display_type = "CUBE"
    far.empty_display_size = 0.1
    far.location = (50.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    die.impulse_takes.face_up = "NONE"
    die.impulse_takes.region = far
    request = takes_logic.build_request(scene, {"position": 0.0, "angle": 90.0, "velocity": 1.0, "angular_velocity": 8.0})
    job = takes_logic.SearchJob(str(tmp_path / "search"), request, budget=8, workers=1)
    found = job.wait()
    assert job.process.returncode == 1
    assert len(found) == 8 and not found.met()


def test_a_search_keeps_the_mesh_split_for_the_next_session(tmp_path):
    """A ring (a torus with shape Mesh) searched: the search's own processes split it and keep
    the parts in the add-on's user directory, where the bake and later sessions read them."""
    import shutil

    cache = bake.decomposition_cache_directory()
    shutil.rmtree(cache, ignore_errors=True)
    scene = field.startup(24)
    field.ground()
    ring = field.add("torus", "Ring", location=(0.0, 0.0, 1.0))
    field.rigid(ring)
    ring.rigid_body.collision_shape = "MESH"
    ring.impulse_takes.hits = scene.objects["Ground"]
    request = takes_logic.build_request(scene, {"position": 0.0, "angle": 30.0, "velocity": 0.0, "angular_velocity": 0.0})
    takes_logic.SearchJob(str(tmp_path / "search"), request, budget=2, workers=1).wait()
    kept = os.listdir(cache)
    assert len(kept) == 1 and kept[0].endswith(".vhacd")


def test_throws_released_at_different_frames_are_refused_naming_them():
    """Two balls keyed Animated until frames 10 and 15: a take starts at one release, so the
    search is refused before it runs, naming both and their frames."""
    scene = field.startup(FRAMES)
    field.ground()
    for name, last, y in (("Ball", 10, 0.0), ("Ball2", 15, 2.0)):
        ball = field.add("uv_sphere", name, radius=0.2, location=(0.0, y, 0.2))
        field.rigid(ball)
        field.key(ball, "location", 1, (0.0, y, 0.2))
        field.key(ball, "location", last, (1.5, y, 0.2))
        field.key(ball, "rigid_body.kinematic", 1, True, interpolation=None)
        field.key(ball, "rigid_body.kinematic", last, True, interpolation=None)
        field.key(ball, "rigid_body.kinematic", last + 1, False, interpolation=None)
        ball.impulse_takes.hits = scene.objects["Ground"]
    variation = {"position": 0.0, "angle": 0.0, "velocity": 0.5, "angular_velocity": 0.0}
    with pytest.raises(scene_reader.UnsupportedScene) as refused:
        takes_logic.build_request(scene, variation)
    assert refused.value.problems == [
        "the keyed throws are released at different frames (Ball after frame 10, Ball2 after frame 15); "
        "a take starts at one release"
    ]
