"""Blender rigid body constraints baked with impulse, checked against physics: a hinged door's
hinge point stays put, a point-constraint pendulum swings with the closed-form period."""

import math

import bpy
import numpy as np
from impulse_bake import bake, constraints, scene_reader
from measure import poses_at

import scenes

G = 9.81


def constraint(scene, name, kind, object1, object2, location, rotation=(0.0, 0.0, 0.0)):
    """An empty at ``location`` (Euler ``rotation``) with a rigid body constraint of ``kind``
    between two objects."""
    empty = bpy.data.objects.new(name, None)
    scene.collection.objects.link(empty)
    empty.location = location
    empty.rotation_euler = rotation
    bpy.context.view_layer.objects.active = empty
    empty.select_set(True)
    bpy.ops.rigidbody.constraint_add(type=kind)
    empty.rigid_body_constraint.object1 = object1
    empty.rigid_body_constraint.object2 = object2
    return empty


def door_on_a_hinge(frames):
    """A static post and a 1 × 0.1 × 2 m door (Blender x, y, z) hinged at its top left corner
    about the world y axis (the empty's local Z turned onto y): the door swings about it."""
    scene = scenes._reset(frames)
    post = scenes._add(scene, "post", scenes._box_mesh("post", (0.2, 0.2, 3.0)), (0.0, 0.0, 1.5), kind="PASSIVE")
    door = scenes._add(scene, "door", scenes._box_mesh("door", (1.0, 0.1, 2.0)), (0.65, 0.0, 1.5))
    constraint(scene, "hinge", "HINGE", post, door, (0.15, 0.0, 2.5), rotation=(-math.pi / 2, 0.0, 0.0))
    return scene


def test_a_hinged_door_keeps_its_hinge_point():
    frames = 48
    scene = door_on_a_hinge(frames)
    info = scene_reader.read_scene(scene)
    (joint,) = info.scene["joints"]
    assert joint["type"] == "revolute" and joint["body_a"] == "post" and joint["body_b"] == "door"
    np.testing.assert_allclose(joint["axis"], [0.0, 0.0, -1.0], atol=1e-6)  # Blender's +y
    assert info.warnings == []
    bake.bake_scene(scene)
    scene.frame_set(1)
    door = scene.objects["door"]
    hinge_local = door.matrix_world.inverted() @ scene.objects["hinge"].matrix_world.to_translation()
    hinge_world = scene.objects["hinge"].matrix_world.to_translation().copy()
    gap, turn = 0.0, 0.0
    for frame in range(1, frames + 1):
        scene.frame_set(frame)
        gap = max(gap, (door.matrix_world @ hinge_local - hinge_world).length)
        turn = max(turn, door.matrix_world.to_quaternion().angle)
    print(f"door: largest hinge point gap {gap:.2e} m over {frames} frames, turned {turn:.2f} rad")
    # Hung from its top corner, released at rest atan(0.5/1) from hanging straight: it swings
    # to twice that (energy conservation), through the post it is joined to.
    assert abs(turn - 2 * math.atan(0.5)) < 0.03  # the peak falls between frames
    assert gap < 1e-3


def point_pendulum(frames, length, radius, theta0):
    """A ball of ``radius`` hung ``length`` below a static pivot by a point constraint at the
    pivot, released at ``theta0`` (rad) from the vertical in the x-z plane."""
    scene = scenes._reset(frames)
    pivot = scenes._add(scene, "pivot", scenes._box_mesh("pivot", (0.1, 0.1, 0.1)), (0.0, 0.0, 3.0), kind="PASSIVE")
    bob = scenes._add(
        scene,
        "bob",
        scenes._sphere_mesh("bob", radius),
        (length * math.sin(theta0), 0.0, 3.0 - length * math.cos(theta0)),
        shape="SPHERE",
        mass=1.0,
        linear_damping=0.0,
        angular_damping=0.0,
    )
    constraint(scene, "pivot point", "POINT", pivot, bob, (0.0, 0.0, 3.0))
    return scene


def test_a_point_constraint_pendulum_swings_with_the_physical_pendulum_period():
    """Period of a ball on a massless rod about the pivot: 2π√((L² + 2r²/5)/(g·L)), with the
    finite-amplitude factor (1 + θ0²/16); measured from the zero crossings of x within 1 %."""
    length, radius, theta0, frames = 1.0, 0.1, 0.1, 150
    scene = point_pendulum(frames, length, radius, theta0)
    info = scene_reader.read_scene(scene)
    assert [j["type"] for j in info.scene["joints"]] == ["spherical"]
    bake.bake_scene(scene)
    fps = scene.render.fps / scene.render.fps_base
    x = np.array([poses_at(scene, ["bob"], f)[0][0, 0] for f in range(1, frames + 1)])
    times = np.arange(frames) / fps
    crossing = np.nonzero(np.sign(x[:-1]) * np.sign(x[1:]) < 0)[0]
    t = times[crossing] + (times[crossing + 1] - times[crossing]) * x[crossing] / (x[crossing] - x[crossing + 1])
    assert len(t) >= 5, t
    period = 2 * (t[-1] - t[0]) / (len(t) - 1)
    expected = 2 * math.pi * math.sqrt((length**2 + 0.4 * radius**2) / (G * length)) * (1 + theta0**2 / 16)
    print(f"point pendulum: period {period:.4f} s, closed form {expected:.4f} s")
    assert abs(period / expected - 1) < 0.01


def test_constraint_settings_map_and_unsupported_ones_are_warned():
    scene = door_on_a_hinge(4)
    hinge = scene.objects["hinge"].rigid_body_constraint
    hinge.use_limit_ang_z = True
    hinge.limit_ang_z_lower, hinge.limit_ang_z_upper = -0.5, 1.0
    hinge.use_breaking = True
    hinge.breaking_threshold = 2.0
    hinge.use_override_solver_iterations = True
    hinge.disable_collisions = False
    post, door = scene.objects["post"], scene.objects["door"]
    off = constraint(scene, "off", "FIXED", post, door, (0.0, 0.0, 0.0))
    off.rigid_body_constraint.enabled = False
    constraint(scene, "loose", "POINT", post, None, (0.0, 0.0, 0.0))
    info = scene_reader.read_scene(scene)
    (joint,) = info.scene["joints"]
    np.testing.assert_allclose(joint["limits"], [-1.0, 0.5])  # Bullet's clockwise angle
    substep = constraints.bullet_substep(scene)
    assert math.isclose(substep, 1.0 / (24 * scene.rigidbody_world.substeps_per_frame))
    assert math.isclose(joint["break_force"], 2.0 / substep, rel_tol=1e-6)
    assert math.isclose(joint["break_window"], substep, rel_tol=1e-6)
    assert joint["collide_connected"] is True
    warnings = info.warnings
    assert any(w.startswith("hinge: ") and "iterations" in w for w in warnings), warnings
    assert any(w.startswith("off: ") and "disabled" in w for w in warnings), warnings
    assert any(w.startswith("loose: ") and "two objects" in w for w in warnings), warnings
    # The scene builds: the joints pass impulse's checks.
    bake.make_world(info.scene)


def test_a_hinge_limit_stops_the_door_where_blenders_own_simulation_does():
    """Hinge limits [−0.3, 1.5] rad: the falling door turns counter-clockwise about +y, which
    is Bullet's negative hinge angle, so Blender's simulation and the bake both stop it at
    0.3 rad."""
    frames = 60
    scene = door_on_a_hinge(frames)
    hinge = scene.objects["hinge"].rigid_body_constraint
    hinge.use_limit_ang_z = True
    hinge.limit_ang_z_lower, hinge.limit_ang_z_upper = -0.3, 1.5
    door = scene.objects["door"]
    for frame in range(1, frames + 1):
        scene.frame_set(frame)
    blender_angle = door.matrix_world.to_quaternion().angle
    bake.bake_scene(scene)
    scene.frame_set(frames)
    impulse_angle = door.matrix_world.to_quaternion().angle
    print(f"limited door: Blender {blender_angle:.4f} rad, impulse {impulse_angle:.4f} rad")
    assert abs(blender_angle - 0.3) < 0.02
    assert abs(impulse_angle - 0.3) < 0.02
