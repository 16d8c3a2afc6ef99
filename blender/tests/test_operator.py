"""The add-on registered in Blender and its operator run from a script.

With ``IMPULSE_BLENDER_ADDON_ZIP`` set (``.ci/run`` sets it to the plain add-on zip the build
script made), the zip is unpacked and its add-on registered (its ``impulse`` package from the
zip's ``vendor/`` when none is installed); otherwise the source directory ``blender/`` is.
"""

import os
import pathlib
import subprocess
import sys

import bpy
import pytest
from impulse_bake import keyframes

import scenes
from addon import load_addon


@pytest.fixture(scope="module")
def addon(tmp_path_factory):
    # Registered by hand rather than enabled through addon_utils: the scene builders reload
    # factory settings, which would disable an enabled add-on again.
    module = load_addon(tmp_path_factory)
    module.register()
    yield module
    module.unregister()


def test_the_operator_bakes_the_scene(addon):
    scene = scenes.heavy_on_light(12)
    scene.impulse_bake.preset = "fast"
    assert bpy.ops.impulse.bake.poll()
    assert bpy.ops.impulse.bake() == {"FINISHED"}
    heavy = scene.objects["heavy"]
    assert heavy.rotation_mode == "XYZ"  # left as the animator set it
    assert not scene.rigidbody_world.enabled
    fcurve = keyframes._fcurve_collection(heavy, create=False).find("location", index=2)
    assert len(fcurve.keyframe_points) == 12


def test_free_bake_returns_the_scene_to_blenders_simulation(addon):
    scene = scenes.heavy_on_light(12)
    heavy = scene.objects["heavy"]
    start = heavy.matrix_world.copy()
    assert bpy.ops.impulse.bake() == {"FINISHED"}
    assert bpy.ops.impulse.free_bake() == {"FINISHED"}
    assert scene.rigidbody_world.enabled
    assert heavy.animation_data is None
    scene.frame_set(1)
    assert (heavy.matrix_world.translation - start.translation).length < 1e-6


def test_the_operator_reports_a_plane_ground_in_the_panels_words(addon, capfd):
    """The tutorial's cube on a Plane, baked from the panel: the report names the Plane and
    the settings that choose its thickness, and nothing says the scene file's "thickness"."""
    import field

    scene = field.startup(24, keep_cube=True)
    cube = scene.objects["Cube"]
    cube.location = (0.0, 0.0, 4.0)
    field.rigid(cube)
    field.rigid(field.add("plane", "Plane", size=20.0), "PASSIVE")
    capfd.readouterr()
    assert bpy.ops.impulse.bake() == {"FINISHED"}
    said = capfd.readouterr()
    assert "impulse: Plane: a flat Convex Hull — baked as a thin shape 2 mm thick (tick Collision Margin" in said.out
    assert '"thickness"' not in said.out + said.err


def test_the_operator_reports_an_unsupported_scene(addon):
    scene = scenes.stack30(4)
    scene.objects["cube05"].rigid_body.collision_shape = "COMPOUND"
    with pytest.raises(RuntimeError, match="cube05: shape Compound Parent has no children with a rigid body"):
        bpy.ops.impulse.bake()
    assert scene.rigidbody_world.enabled


def test_the_operator_warns_of_constraint_settings_it_does_not_follow(addon, capfd):
    scene = scenes.heavy_on_light(4)
    empty = bpy.data.objects.new("off", None)
    scene.collection.objects.link(empty)
    bpy.context.view_layer.objects.active = empty
    empty.select_set(True)
    bpy.ops.rigidbody.constraint_add(type="FIXED")
    empty.rigid_body_constraint.object1 = scene.objects["light0"]
    empty.rigid_body_constraint.object2 = scene.objects["light1"]
    empty.rigid_body_constraint.enabled = False
    assert bpy.ops.impulse.bake() == {"FINISHED"}
    output = capfd.readouterr()
    assert "off: the constraint is disabled" in output.out + output.err


EXTENSION_CHECK = """
import bpy
bpy.context.preferences.system.use_online_access = False
result = bpy.ops.extensions.package_install_files(
    filepath={archive!r}, repo="user_default", enable_on_install=True
)
assert result == {{"FINISHED"}}, result
assert "bake" in dir(bpy.ops.impulse)
print("installed")
"""


@pytest.mark.skipif(
    not os.environ.get("IMPULSE_BLENDER_EXTENSION_ZIP"), reason="needs IMPULSE_BLENDER_EXTENSION_ZIP (set by .ci/run)"
)
def test_the_extension_installs_with_its_wheel(tmp_path):
    # In a child process with its own home: installing writes to Blender's user directories.
    archive = os.environ["IMPULSE_BLENDER_EXTENSION_ZIP"]
    environment = dict(os.environ, HOME=str(tmp_path))
    result = subprocess.run(
        [sys.executable, "-c", EXTENSION_CHECK.format(archive=str(pathlib.Path(archive).resolve()))],
        env=environment,
        check=False,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "installed" in result.stdout
    # Blender installed the bundled wheel into the extensions' own site-packages.
    assert list(tmp_path.glob(".config/blender/*/extensions/.local/lib/python*/site-packages/impulse/_impulse*"))
