"""Joints from Python, checked against physics: a pendulum's period (closed form), a hinge's
coordinate against the body's pose, a breakable joint against statics, the built-in chain's
stretch, the LCP's joint rows, and the errors of bad input."""

import math

import impulse
import numpy as np
import pytest

G = 9.81
DT = 1.0 / 60.0


def zero_crossing_times(times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The times where `values` changes sign, linearly interpolated between samples."""
    sign_change = np.nonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)[0]
    t0, t1 = times[sign_change], times[sign_change + 1]
    v0, v1 = values[sign_change], values[sign_change + 1]
    return t0 + (t1 - t0) * v0 / (v0 - v1)


def measured_period(times: np.ndarray, values: np.ndarray) -> float:
    """The mean period between the first and last zero crossing (two crossings a period)."""
    crossings = zero_crossing_times(times, values)
    assert len(crossings) >= 5, crossings
    return 2.0 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)


def pivot_and_bob(world: impulse.World, bob: impulse.BodyBuilder) -> tuple:
    pivot = world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(0.05, 0.05, 0.05), translation=(0, 2, 0))
    )
    return pivot, world.insert(bob)


def test_a_simple_pendulum_swings_with_the_period_of_the_closed_form():
    """A particle on a rod (distance joint, min = max = L) released at θ0 = 0.05 rad: the
    small-amplitude period 2π√(L/g), with the finite-amplitude term (1 + θ0²/16), within
    0.5 %."""
    length, theta0 = 1.0, 0.05
    world = impulse.World(gravity=(0, -G, 0), dt=DT)
    start = (length * math.sin(theta0), 2.0 - length * math.cos(theta0), 0.0)
    pivot, bob = pivot_and_bob(world, impulse.BodyBuilder.particle(0.05, translation=start))
    world.insert_joint(
        impulse.JointBuilder.distance(pivot, bob, length, length).world_anchors((0, 2, 0), start)
    )
    steps = int(8.0 / DT)
    x = np.empty(steps)
    for k in range(steps):
        world.step()
        x[k] = world.positions[world.index_of(bob), 0]
    period = measured_period(DT * np.arange(1, steps + 1), x)
    expected = 2 * math.pi * math.sqrt(length / G) * (1 + theta0**2 / 16)
    print(
        f"pendulum period {period:.5f} s, closed form {expected:.5f} s ({period / expected - 1:+.1e})"
    )
    assert abs(period / expected - 1) < 0.005


def test_a_hinge_coordinate_follows_the_swinging_body():
    """A ball on a hinge about z through the pivot: the hinge angle (coordinate 3) is the
    change of the bob's direction from the pivot (counter-clockwise about +z), the linear
    coordinates stay near 0, and the period is the physical pendulum's
    2π√((L² + 2r²/5)/(g L))."""
    length, radius, theta0 = 1.0, 0.1, 0.1
    world = impulse.World(gravity=(0, -G, 0), dt=DT)
    start = (length * math.sin(theta0), 2.0 - length * math.cos(theta0), 0.0)
    pivot, bob = pivot_and_bob(
        world, impulse.BodyBuilder.dynamic(impulse.Shape.ball(radius), translation=start)
    )
    hinge = world.insert_joint(
        impulse.JointBuilder.revolute(pivot, bob).world_anchor((0, 2, 0)).world_axis((0, 0, 1))
    )
    direction0 = math.atan2(start[1] - 2.0, start[0])
    steps = int(6.0 / DT)
    angle_error, drift = 0.0, 0.0
    x = np.empty(steps)
    for k in range(steps):
        world.step()
        p = world.positions[world.index_of(bob)]
        x[k] = p[0]
        coordinates = world.joint_coordinates(hinge)
        assert coordinates.shape == (6,)
        expected = math.atan2(p[1] - 2.0, p[0]) - direction0
        angle_error = max(angle_error, abs(coordinates[3] - expected))
        drift = max(drift, float(np.abs(coordinates[:3]).max()))
    period = measured_period(DT * np.arange(1, steps + 1), x)
    inertia_length = (length**2 + 0.4 * radius**2) / length
    expected_period = 2 * math.pi * math.sqrt(inertia_length / G) * (1 + theta0**2 / 16)
    print(
        f"hinge: max angle error {angle_error:.2e} rad, max drift {drift:.2e} m, "
        f"period {period:.5f} s, closed form {expected_period:.5f} s"
    )
    assert angle_error < 1e-3
    assert drift < 1e-3
    assert abs(period / expected_period - 1) < 0.005
    view = world.joint(hinge)
    assert view["kind"] == "revolute" and not view["broken"]
    assert view["force"].shape == (3,) and view["torque"].shape == (3,)


def test_a_door_swinging_through_its_own_post_is_not_stopped():
    """A 1 × 2 m door hung from its top corner on a hinge to a static post it overlaps as it
    swings (joined bodies do not collide): released at rest α = atan(0.5/1) from its
    equilibrium, it swings to 2α by energy conservation, the continuous stage not clamping it
    at the post."""
    world = impulse.World(gravity=(0, -G, 0), dt=1 / 72)
    post = world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(0.1, 1.5, 0.1), translation=(0, 1.5, 0))
    )
    door = world.insert(
        impulse.BodyBuilder.dynamic(
            impulse.Shape.cuboid(0.5, 1.0, 0.05), translation=(0.65, 1.5, 0), mass=1.0
        )
    )
    hinge = world.insert_joint(
        impulse.JointBuilder.revolute(post, door).world_anchor((0.15, 2.5, 0)).world_axis((0, 0, 1))
    )
    swing = 0.0
    for _ in range(120):
        world.step()
        swing = max(swing, -float(world.joint_coordinates(hinge)[3]))
    expected = 2 * math.atan(0.5)
    print(f"door through its post: swing {swing:.4f} rad, energy conservation {expected:.4f} rad")
    assert abs(swing - expected) < 0.01


#: A break window (s): Bullet's substep at Blender's defaults.
WINDOW = 1.0 / 240.0


def hang(load: float, strength: float = 100.0, window: float = 0.0) -> tuple:
    """A mass of weight `load`·`strength` (N) hung below a static beam by one fixed joint of
    strength `strength` (N) measured over `window` s; stepped 2 s one step at a time. Returns
    the world, the joint and the events of every step."""
    world = impulse.World(
        gravity=(0, -G, 0), dt=DT, settings=impulse.Settings.preset("default").replace(sleep=False)
    )
    beam = world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(0.5, 0.05, 0.5), translation=(0, 1, 0))
    )
    weight = world.insert(
        impulse.BodyBuilder.dynamic(
            impulse.Shape.cuboid(0.1, 0.1, 0.1), translation=(0, 0.85, 0), mass=load * strength / G
        )
    )
    joint = world.insert_joint(
        impulse.JointBuilder.fixed(beam, weight)
        .world_anchor((0, 0.95, 0))
        .breakable(strength, window=window)
        .name("hook")
    )
    events = []
    for _ in range(120):
        world.step()
        events.extend(world.joint_events())
    return world, joint, events


@pytest.mark.parametrize("window", [0.0, WINDOW])
def test_a_breakable_joint_holds_a_weight_below_its_strength(window):
    """Strength 1.05·m·g: by statics the joint carries m·g, holds, and its force is m·g up,
    with or without a break window."""
    world, joint, events = hang(1 / 1.05, window=window)
    view = world.joint(joint)
    weight = 100.0 / 1.05
    print(f"holding: force {view['force']} N, weight {weight:.3f} N")
    assert events == []
    assert not view["broken"]
    assert abs(view["force"][1] - weight) < 1e-3 * weight
    assert world.joint_events() == []


@pytest.mark.parametrize("window", [0.0, WINDOW])
def test_a_breakable_joint_breaks_under_a_weight_above_its_strength(window):
    """Strength 0.95·m·g: breaks, with one event naming it and reporting the strength, with or
    without a break window."""
    world, joint, events = hang(1 / 0.95, window=window)
    print(f"breaking: events {events}")
    assert len(events) == 1
    (event,) = events
    assert event["type"] == "broken" and event["joint"] == joint and event["name"] == "hook"
    assert abs(event["force"] - 100.0) < 1e-3 * 100.0
    assert world.joint(joint)["broken"]


def kicked(kick: float, window: float) -> list:
    """A mass of weight 0.3·F hung below a static beam by one fixed joint of strength F = 100 N
    measured over `window` s, at rest after 0.5 s, then kicked downwards with a momentum of
    `kick`·F·(1/240 s). Returns the events of the second after the kick."""
    strength = 100.0
    world = impulse.World(
        gravity=(0, -G, 0), dt=DT, settings=impulse.Settings.preset("default").replace(sleep=False)
    )
    beam = world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(0.5, 0.05, 0.5), translation=(0, 1, 0))
    )
    mass = 0.3 * strength / G
    weight = world.insert(
        impulse.BodyBuilder.dynamic(impulse.Shape.cuboid(0.1, 0.1, 0.1), translation=(0, 0.85, 0), mass=mass)
    )
    world.insert_joint(
        impulse.JointBuilder.fixed(beam, weight).world_anchor((0, 0.95, 0)).breakable(strength, window=window)
    )
    world.step(30)
    velocities = world.linear_velocities.copy()
    velocities[world.index_of(weight)] = (0.0, -kick * strength * WINDOW / mass, 0.0)
    world.linear_velocities = velocities
    events = []
    for _ in range(60):
        world.step()
        events.extend(world.joint_events())
    return events


def test_a_break_window_keeps_the_static_strength_and_measures_a_blow_over_the_window():
    """Measured over 1/240 s the joint takes a blow of 0.3·F·(1/240 s) on top of its 0.3·F load
    (0.6 of its window's strength) and breaks under one of 1.5·F·(1/240 s); measured over a
    substep of the default preset (1/1200 s) the small blow is more than the substep's F·h and
    breaks it."""
    assert kicked(0.3, WINDOW) == []
    assert len(kicked(1.5, WINDOW)) == 1
    assert len(kicked(0.3, 0.0)) == 1
    assert kicked(0.0, WINDOW) == []


def test_a_joint_built_by_kind_name_is_the_named_constructors_joint():
    """`JointBuilder.new(kind, a, b)` takes every kind by its name and gives the joint its
    named constructor gives: a hinge swings the same to the bit; an unknown name raises."""
    names = ["fixed", "spherical", "revolute", "prismatic", "distance", "generic"]
    trajectories = []
    by_name = lambda a, b: impulse.JointBuilder.new("revolute", a, b)  # noqa: E731
    for make in (impulse.JointBuilder.revolute, by_name):
        world = impulse.World(gravity=(0, -G, 0), dt=DT)
        pivot, bob = pivot_and_bob(
            world, impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.1), translation=(0.5, 1.5, 0))
        )
        for name in names:
            assert impulse.JointBuilder.new(name, pivot, bob).kind == name
        world.insert_joint(make(pivot, bob).world_anchor((0, 2, 0)).world_axis((0, 0, 1)))
        for _ in range(30):
            world.step()
        trajectories.append(world.positions.copy())
    assert np.array_equal(trajectories[0], trajectories[1])
    assert abs(trajectories[0][1, 2]) < 1e-6  # the hinge about z keeps the bob in its plane
    with pytest.raises(impulse.WorldError, match="no joint kind 'hinge'; one of fixed, spherical"):
        impulse.JointBuilder.new("hinge", pivot, bob)


def test_bad_joints_raise_world_error_naming_the_field():
    world = impulse.World()
    post = world.insert(impulse.BodyBuilder.fixed(impulse.Shape.ball(0.1)))
    ball = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.1), translation=(1, 0, 0)))
    gone = world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.1), translation=(2, 0, 0)))
    world.remove(gone)
    with pytest.raises(impulse.WorldError, match="body_b: names no body"):
        world.insert_joint(impulse.JointBuilder.spherical(post, gone))
    with pytest.raises(impulse.WorldError, match="anchor_a: must be finite"):
        world.insert_joint(impulse.JointBuilder.spherical(post, ball).world_anchor((np.nan, 0, 0)))
    with pytest.raises(impulse.WorldError, match=r"limits: lower \(1\) must be ≤ upper \(0\)"):
        world.insert_joint(impulse.JointBuilder.revolute(post, ball).limits(1.0, 0.0))
    with pytest.raises(impulse.WorldError, match="must differ"):
        world.insert_joint(impulse.JointBuilder.fixed(ball, ball))
    with pytest.raises(impulse.WorldError, match="no main degree of freedom"):
        world.insert_joint(impulse.JointBuilder.fixed(post, ball).limits(0.0, 1.0))
    with pytest.raises(impulse.WorldError, match="no degree of freedom 'angular_w'"):
        impulse.JointBuilder.generic(post, ball).dof("angular_w", "free")
    with pytest.raises(impulse.WorldError, match="both `lower` and `upper`"):
        impulse.JointBuilder.generic(post, ball).dof("angular_x", "limited", lower=0.0)
    assert world.joint_count == 0
    handle = world.insert_joint(impulse.JointBuilder.spherical(post, ball).name("ok"))
    assert world.remove_joint(handle) == "ok"
    with pytest.raises(impulse.WorldError, match="no joint"):
        world.joint(handle)
    with pytest.raises(impulse.WorldError, match="no joint"):
        world.remove_joint(handle)
    with pytest.raises(impulse.WorldError, match="no joint"):
        world.joint_coordinates(handle)


def test_joint_handles_are_hashable_and_ordered():
    world = impulse.World()
    post = world.insert(impulse.BodyBuilder.fixed(impulse.Shape.ball(0.1)))
    balls = [
        world.insert(impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.1), translation=(k, 0, 0)))
        for k in (1, 2)
    ]
    first, second = (world.insert_joint(impulse.JointBuilder.spherical(post, b)) for b in balls)
    assert first < second and first != second and len({first, second, first}) == 2
    assert [j["handle"] for j in world.joints()] == [first, second]
    world.remove_joint(first)
    third = world.insert_joint(impulse.JointBuilder.spherical(post, balls[0]))
    assert third.index == first.index and third.generation == first.generation + 1
    assert third != first


def test_the_builtin_chain_keeps_its_links_together():
    """chain20: 20 spherical joints; swinging down for 3 s, every joint's anchors stay within
    1 cm of each other (the linear coordinates of a spherical joint are its stretch)."""
    world = impulse.World.from_scene("chain20")
    assert world.joint_count == 20
    handles = [j["handle"] for j in world.joints()]
    stretch = 0.0
    for _ in range(180):
        world.step()
        for handle in handles:
            stretch = max(stretch, float(np.linalg.norm(world.joint_coordinates(handle)[:3])))
    print(f"chain20: largest anchor gap over 3 s {stretch:.2e} m")
    assert stretch < 0.01


def test_the_lcp_of_a_pendulum_has_its_joint_rows_after_the_contacts():
    """A ball on a hinge resting against the ground: contact rows first (joint_of_row −1),
    then the hinge's rows (contact_of_row −1, joint_of_row 0)."""
    world = impulse.World(dt=DT)
    world.insert(
        impulse.BodyBuilder.fixed(impulse.Shape.cuboid(2, 0.5, 2), translation=(0, -0.5, 0))
    )
    pivot = world.insert(impulse.BodyBuilder.fixed(impulse.Shape.ball(0.05), translation=(0, 2, 0)))
    bob = world.insert(
        impulse.BodyBuilder.dynamic(impulse.Shape.ball(0.2), translation=(1, 0.2, 0))
    )
    world.insert_joint(
        impulse.JointBuilder.revolute(pivot, bob).world_anchor((0, 2, 0)).world_axis((0, 0, 1))
    )
    world.step()
    lcp = world.contact_lcp()
    n = lcp["b"].shape[0]
    joint_of_row, contact_of_row = lcp["joint_of_row"], lcp["contact_of_row"]
    assert joint_of_row.shape == (n,) and contact_of_row.shape == (n,)
    joint_rows = joint_of_row >= 0
    print(f"LCP rows: {n}, of the hinge: {joint_rows.sum()}")
    assert joint_rows.any() and (~joint_rows).any()
    assert set(joint_of_row[joint_rows]) == {0}
    assert (contact_of_row[joint_rows] == -1).all()
    assert (contact_of_row[~joint_rows] >= 0).all()
    first_joint_row = int(np.argmax(joint_rows))
    assert joint_rows[first_joint_row:].all()
