"""impulse.usd: UsdPhysics stages authored with pxr the way tools write them, read into scenes,
baked, and checked against the same scenes written as JSON, against closed forms, and by
OpenUSD's own validators (the UsdValidation registry usdchecker runs).

Skipped when OpenUSD's Python module (PyPI usd-core) is missing; CI installs it.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

pxr = pytest.importorskip("pxr")

from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade, UsdValidation  # noqa: E402

import impulse  # noqa: E402
from impulse import usd  # noqa: E402
from impulse.usd import _frames  # noqa: E402

ROUND_TRIP_SCENES = ["example-three-spheres", "shapes", "kinematic", "chain20", "ragdoll", "compound", "arch"]


# -- stages as tools author them ------------------------------------------------------------


def new_stage(path, up_axis="Y", meters_per_unit=1.0, rate=60.0, end=120.0):
    """A stage as Omniverse or Houdini start one: up axis, units, time codes, a PhysicsScene."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, up_axis)
    UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    stage.SetTimeCodesPerSecond(rate)
    stage.SetFramesPerSecond(rate)
    stage.SetStartTimeCode(0.0)
    stage.SetEndTimeCode(end)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    UsdPhysics.Scene.Define(stage, "/World/physicsScene")
    return stage


def memory_stage():
    """An in-memory stage in metres, y up (an unauthored metersPerUnit means centimetres)."""
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, "Y")
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdPhysics.Scene.Define(stage, "/physicsScene")
    return stage


def up(stage, height):
    """A point at ``height`` (stage units) above the origin, along the stage's up axis."""
    return (0.0, 0.0, height) if UsdGeom.GetStageUpAxis(stage) == "Z" else (0.0, height, 0.0)


def ground_plane(stage, path="/World/ground"):
    plane = UsdGeom.Plane.Define(stage, path)
    plane.CreateAxisAttr(UsdGeom.GetStageUpAxis(stage))
    UsdPhysics.CollisionAPI.Apply(plane.GetPrim())
    return plane


def rigid_cube(stage, path, size, position, mass=None):
    cube = UsdGeom.Cube.Define(stage, path)
    cube.CreateSizeAttr(size)
    cube.AddTranslateOp().Set(Gf.Vec3d(*position))
    UsdPhysics.RigidBodyAPI.Apply(cube.GetPrim())
    UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
    if mass is not None:
        UsdPhysics.MassAPI.Apply(cube.GetPrim()).CreateMassAttr(mass)
    return cube


def box_drop(path, up_axis, meters_per_unit):
    """A 1 m box dropped from 2 m (its centre) onto a ground plane, in the stage's units."""
    stage = new_stage(path, up_axis, meters_per_unit)
    unit = 1.0 / meters_per_unit
    ground_plane(stage)
    rigid_cube(stage, "/World/box", 1.0 * unit, up(stage, 2.0 * unit))
    stage.GetRootLayer().Save()
    return stage


def validation_errors(path):
    stage = Usd.Stage.Open(str(path))
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    return [error.GetErrorAsString() for error in UsdValidation.ValidationContext(validators).Validate(stage)]


def world_heights(path, prim_path, axis):
    stage = Usd.Stage.Open(str(path))
    prim = stage.GetPrimAtPath(prim_path)
    codes = prim.GetAttribute("xformOp:translate:impulse").GetTimeSamples()
    heights = []
    for code in codes:
        matrix = UsdGeom.XformCache(Usd.TimeCode(code)).GetLocalToWorldTransform(prim)
        heights.append(matrix.ExtractTranslation()[axis])
    return np.array(codes), np.array(heights)


def simulate(scene, steps):
    world = impulse.World.from_scene(scene)
    return world.simulate(steps)


# -- units, axes and the baked layer --------------------------------------------------------


def test_a_box_dropped_in_a_z_up_centimetre_stage_rests_on_the_ground_in_the_baked_layer(tmp_path):
    box_drop(tmp_path / "drop.usda", "Z", 0.01)
    out = tmp_path / "drop_baked.usda"
    report = usd.bake(tmp_path / "drop.usda", out)
    assert report.up_axis == "Z" and report.meters_per_unit == 0.01
    assert not report.dropped()
    codes, heights = world_heights(out, "/World/box", 2)
    # 120 time codes at 60 per second: 2 s, the box fell 1.5 m in 0.55 s and came to rest on
    # its face, centre 50 cm up (the soft contact's rest depth is well under a millimetre).
    assert codes[0] == 0.0 and codes[-1] == 120.0 and len(codes) == 121
    assert heights[0] == pytest.approx(200.0)
    assert heights[-1] == pytest.approx(50.0, abs=0.1)
    # Free fall before the contact: h = 200 cm − g t²/2 with g = 981 cm/s².
    t = codes[10] / 60.0
    assert heights[10] == pytest.approx(200.0 - 0.5 * 981.0 * t * t, rel=2e-3)

    baked = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(baked) == "Z"
    assert UsdGeom.GetStageMetersPerUnit(baked) == 0.01
    assert baked.GetTimeCodesPerSecond() == 60.0
    assert list(baked.GetRootLayer().subLayerPaths) == ["drop.usda"]
    ops = UsdGeom.Xformable(baked.GetPrimAtPath("/World/box")).GetOrderedXformOps()
    assert [op.GetOpName() for op in ops] == ["xformOp:translate:impulse", "xformOp:orient:impulse"]
    # The ground is static: not written.
    assert not baked.GetRootLayer().GetPrimAtPath("/World/ground")
    assert validation_errors(out) == []


def test_the_same_drop_authored_y_up_in_metres_bakes_to_the_same_motion(tmp_path):
    box_drop(tmp_path / "z.usda", "Z", 0.01)
    box_drop(tmp_path / "y.usda", "Y", 1.0)
    usd.bake(tmp_path / "z.usda", tmp_path / "z_baked.usda")
    usd.bake(tmp_path / "y.usda", tmp_path / "y_baked.usda")
    z_codes, z_heights = world_heights(tmp_path / "z_baked.usda", "/World/box", 2)
    y_codes, y_heights = world_heights(tmp_path / "y_baked.usda", "/World/box", 1)
    assert list(z_codes) == list(y_codes)
    np.testing.assert_allclose(z_heights * 0.01, y_heights, rtol=1e-5, atol=1e-7)


def test_units_and_axes_turn_into_si_and_y_up():
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, "Z")
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdPhysics.SetStageKilogramsPerUnit(stage, 0.001)  # grams
    UsdPhysics.Scene.Define(stage, "/physicsScene")
    ball = UsdGeom.Sphere.Define(stage, "/ball")
    ball.CreateRadiusAttr(10.0)
    ball.AddTranslateOp().Set(Gf.Vec3d(100.0, 200.0, 300.0))
    rigid = UsdPhysics.RigidBodyAPI.Apply(ball.GetPrim())
    rigid.CreateVelocityAttr(Gf.Vec3f(0.0, 0.0, 500.0))  # cm/s, up
    rigid.CreateAngularVelocityAttr(Gf.Vec3f(0.0, 0.0, 180.0))  # degrees/s about up
    UsdPhysics.CollisionAPI.Apply(ball.GetPrim())
    UsdPhysics.MassAPI.Apply(ball.GetPrim()).CreateMassAttr(2500.0)  # g
    scene, report = usd.stage_to_scene(stage)
    (body,) = scene["bodies"]
    assert scene["gravity"] == pytest.approx([0.0, -9.81, 0.0])  # the parser's 981 cm/s² down z
    assert body["shape"] == {"type": "sphere", "radius": 0.1}
    assert body["position"] == pytest.approx([1.0, 3.0, -2.0])  # (x, z, −y)
    assert body["linear_velocity"] == pytest.approx([0.0, 5.0, 0.0])
    assert body["angular_velocity"] == pytest.approx([0.0, math.pi, 0.0])
    assert body["mass"] == pytest.approx(2.5)
    assert report.bodies[0].path == "/ball"


def test_scale_and_hierarchy_compose_into_the_bodies_and_the_bake_writes_local_transforms(tmp_path):
    stage = new_stage(tmp_path / "nested.usda", "Y", 1.0, end=30.0)
    ground_plane(stage)
    parent = UsdGeom.Xform.Define(stage, "/World/rig")
    parent.AddTranslateOp().Set(Gf.Vec3d(1.0, 2.0, 0.0))
    parent.AddRotateYOp().Set(90.0)
    parent.AddScaleOp().Set(Gf.Vec3f(2.0, 2.0, 2.0))
    crate = UsdGeom.Cube.Define(stage, "/World/rig/crate")
    crate.CreateSizeAttr(1.0)
    crate.AddTranslateOp().Set(Gf.Vec3d(0.0, 1.0, 0.5))
    crate.AddScaleOp().Set(Gf.Vec3f(1.0, 0.5, 0.25))
    UsdPhysics.RigidBodyAPI.Apply(crate.GetPrim())
    UsdPhysics.CollisionAPI.Apply(crate.GetPrim())
    stage.GetRootLayer().Save()
    scene, _ = usd.stage_to_scene(stage)
    crate_body = scene["bodies"][1]
    # World: scale 2 then the rig's 90° about y: local (0, 1, 0.5)·2 → (1, 2, 0) turned → (1, 2, −1)... plus (1, 2, 0).
    assert crate_body["position"] == pytest.approx([2.0, 4.0, 0.0], abs=1e-6)
    assert sorted(crate_body["shape"]["half_extents"]) == pytest.approx([0.25, 0.5, 1.0])
    out = tmp_path / "nested_baked.usda"
    usd.bake(stage, out, steps=30)
    baked = Usd.Stage.Open(str(out))
    prim = baked.GetPrimAtPath("/World/rig/crate")
    start = UsdGeom.XformCache(Usd.TimeCode(0.0)).GetLocalToWorldTransform(prim)
    original = UsdGeom.XformCache(Usd.TimeCode(0.0)).GetLocalToWorldTransform(stage.GetPrimAtPath("/World/rig/crate"))
    assert all(abs(start[i][j] - original[i][j]) < 1e-5 for i in range(4) for j in range(4))
    ops = [op.GetOpName() for op in UsdGeom.Xformable(prim).GetOrderedXformOps()]
    assert ops == ["xformOp:translate:impulse", "xformOp:orient:impulse", "xformOp:scale:impulse"]
    trajectory = simulate(scene, 30)
    end = UsdGeom.XformCache(Usd.TimeCode(30.0)).GetLocalToWorldTransform(prim).ExtractTranslation()
    assert list(end) == pytest.approx(trajectory.positions[-1, 1].tolist(), abs=1e-5)
    assert validation_errors(out) == []


# -- each feature against its JSON equivalent -----------------------------------------------


def test_mass_api_precedence_mass_over_density_over_material(tmp_path):
    stage = new_stage(tmp_path / "mass.usda")
    ground_plane(stage)
    material = UsdShade.Material.Define(stage, "/World/steel")
    UsdPhysics.MaterialAPI.Apply(material.GetPrim()).CreateDensityAttr(7800.0)
    heavy = rigid_cube(stage, "/World/by_mass", 1.0, (0.0, 0.5, 0.0), mass=3.0)
    dense = rigid_cube(stage, "/World/by_density", 1.0, (2.0, 0.5, 0.0))
    UsdPhysics.MassAPI.Apply(dense.GetPrim()).CreateDensityAttr(500.0)
    steel = rigid_cube(stage, "/World/by_material", 1.0, (4.0, 0.5, 0.0))
    for cube in (heavy, dense, steel):
        binding = UsdShade.MaterialBindingAPI.Apply(cube.GetPrim())
        binding.Bind(material, UsdShade.Tokens.weakerThanDescendants, "physics")
    scene, _ = usd.stage_to_scene(stage)
    masses = impulse.World.from_scene(scene).masses
    # The body's mass wins over everything; its MassAPI density over its material's; the
    # material's over the default.
    assert masses[1:].tolist() == pytest.approx([3.0, 500.0, 7800.0], rel=1e-6)
    assert scene["bodies"][1]["mass"] == 3.0
    assert scene["bodies"][2]["material"]["density"] == 500.0
    assert scene["bodies"][3]["material"] == "steel"
    assert scene["materials"]["steel"]["density"] == 7800.0


def test_colliders_of_different_densities_weigh_their_sum():
    stage = memory_stage()
    body = UsdGeom.Xform.Define(stage, "/dumbbell")
    UsdPhysics.RigidBodyAPI.Apply(body.GetPrim())
    for name, x, density in (("left", -1.0, 1000.0), ("right", 1.0, 3000.0)):
        ball = UsdGeom.Sphere.Define(stage, f"/dumbbell/{name}")
        ball.CreateRadiusAttr(0.5)
        ball.AddTranslateOp().Set(Gf.Vec3d(x, 0.0, 0.0))
        UsdPhysics.CollisionAPI.Apply(ball.GetPrim())
        UsdPhysics.MassAPI.Apply(ball.GetPrim()).CreateDensityAttr(density)
    scene, report = usd.stage_to_scene(stage)
    (dumbbell,) = scene["bodies"]
    assert dumbbell["shape"]["type"] == "compound"
    assert [part["position"] for part in dumbbell["shape"]["parts"]] == [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
    volume = 4.0 / 3.0 * math.pi * 0.125
    assert dumbbell["mass"] == pytest.approx(4000.0 * volume, rel=1e-6)
    assert any("differ in mass or density" in issue.message for issue in report.approximated())


def test_materials_bound_for_physics_slide_as_their_json_equivalent(tmp_path):
    stage = new_stage(tmp_path / "slide.usda", end=90.0)
    ice = UsdShade.Material.Define(stage, "/World/Looks/ice")
    api = UsdPhysics.MaterialAPI.Apply(ice.GetPrim())
    api.CreateStaticFrictionAttr(0.1)
    api.CreateDynamicFrictionAttr(0.1)
    api.CreateRestitutionAttr(0.0)
    rubber = UsdShade.Material.Define(stage, "/World/Looks/rubber")
    api = UsdPhysics.MaterialAPI.Apply(rubber.GetPrim())
    api.CreateStaticFrictionAttr(0.9)
    api.CreateDynamicFrictionAttr(0.7)
    api.CreateRestitutionAttr(0.5)
    ground = ground_plane(stage)
    sliders = []
    for name, material, z in (("on_ice", ice, 0.0), ("on_rubber", rubber, 3.0)):
        cube = rigid_cube(stage, f"/World/{name}", 1.0, (0.0, 0.5, z))
        UsdPhysics.RigidBodyAPI(cube.GetPrim()).CreateVelocityAttr(Gf.Vec3f(4.0, 0.0, 0.0))
        UsdShade.MaterialBindingAPI.Apply(cube.GetPrim()).Bind(material, UsdShade.Tokens.weakerThanDescendants, "physics")
        sliders.append(cube)
    UsdShade.MaterialBindingAPI.Apply(ground.GetPrim()).Bind(ice, UsdShade.Tokens.weakerThanDescendants, "physics")
    scene, report = usd.stage_to_scene(stage)
    equivalent = {
        "gravity": [0.0, -9.81, 0.0],
        "dt": 1.0 / 60.0,
        "materials": {
            "ice": {"friction": 0.1, "restitution": 0.0, "density": 1000.0},
            "rubber": {"friction": 0.9, "restitution": 0.5, "density": 1000.0},
        },
        "bodies": [
            {"kind": "static", "shape": {"type": "half_space", "normal": [0.0, 1.0, 0.0]}, "material": "ice"},
            {"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
             "position": [0.0, 0.5, 0.0], "linear_velocity": [4.0, 0.0, 0.0], "material": "ice"},
            {"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]},
             "position": [0.0, 0.5, 3.0], "linear_velocity": [4.0, 0.0, 0.0], "material": "rubber"},
        ],
    }  # fmt: skip
    assert scene["materials"] == equivalent["materials"]
    assert [b.get("material") for b in scene["bodies"]] == ["ice", "ice", "rubber"]
    assert any("static friction 0.9 and dynamic friction 0.7" in i.message for i in report.approximated())
    ours, theirs = simulate(scene, 90), simulate(equivalent, 90)
    np.testing.assert_allclose(ours.positions, theirs.positions, atol=1e-6)
    # Friction μ between ice and ice, √(0.1·0.1): after 1.5 s the box has slid v t − μ g t²/2;
    # on rubber against ice, μ = √(0.1·0.9) = 0.3 (the static friction): it stops after
    # v²/(2μg) = 2.72 m.
    slid = ours.positions[-1, 1:, 0]
    assert slid[0] == pytest.approx(4.0 * 1.5 - 0.1 * 9.81 * 1.5**2 / 2.0, rel=0.01)  # still sliding at 1.5 s
    assert slid[1] == pytest.approx(16.0 / (2.0 * 0.3 * 9.81), rel=0.01)  # stopped at 1.36 s


def test_a_filtered_pair_and_collision_groups_let_bodies_pass_through(tmp_path):
    stage = new_stage(tmp_path / "filters.usda", end=60.0)
    ground = ground_plane(stage)
    ghost = rigid_cube(stage, "/World/ghost", 1.0, (0.0, 0.5, 0.0))
    rigid_cube(stage, "/World/solid", 1.0, (3.0, 0.5, 0.0))
    ghost_group = rigid_cube(stage, "/World/ghost_group", 1.0, (6.0, 0.5, 0.0))
    UsdPhysics.FilteredPairsAPI.Apply(ghost.GetPrim()).CreateFilteredPairsRel().AddTarget(ground.GetPath())
    falling = UsdPhysics.CollisionGroup.Define(stage, "/World/falling")
    floor = UsdPhysics.CollisionGroup.Define(stage, "/World/floor")
    falling.GetCollidersCollectionAPI().CreateIncludesRel().AddTarget(ghost_group.GetPath())
    floor.GetCollidersCollectionAPI().CreateIncludesRel().AddTarget(ground.GetPath())
    falling.CreateFilteredGroupsRel().AddTarget(floor.GetPath())
    scene, report = usd.stage_to_scene(stage)
    trajectory = simulate(scene, 60)
    heights = trajectory.positions[-1, 1:, 1]
    # In free fall for 1 s: 0.5 − g/2 = −4.4 m; the solid box rests.
    assert heights[0] == pytest.approx(0.5 - 9.81 / 2, abs=0.01)
    assert heights[1] == pytest.approx(0.5, abs=1e-3)
    assert heights[2] == pytest.approx(0.5 - 9.81 / 2, abs=0.01)
    # The falling bodies still collide with each other and with the solid one.
    bodies = scene["bodies"]

    def collide(a, b):
        return bool(bodies[a]["groups"] & bodies[b]["mask"]) and bool(bodies[b]["groups"] & bodies[a]["mask"])

    assert not collide(0, 1) and not collide(0, 3)
    assert collide(0, 2) and collide(1, 2) and collide(1, 3) and collide(2, 3)
    assert not report.dropped()


def hinge_stage(path, joint_type, **attributes):
    """A 1 kg bar hanging from the world by a joint at its top end, the bar along −y."""
    stage = new_stage(path, end=120.0)
    bar = rigid_cube(stage, "/World/bar", 1.0, (0.0, 2.0, 0.0), mass=1.0)
    bar.AddScaleOp().Set(Gf.Vec3f(0.1, 1.0, 0.1))
    joint = joint_type.Define(stage, "/World/joint")
    joint.CreateBody1Rel().SetTargets([bar.GetPath()])
    joint.CreateLocalPos0Attr(Gf.Vec3f(0.0, 2.5, 0.0))
    joint.CreateLocalPos1Attr(Gf.Vec3f(0.0, 0.5, 0.0))  # in the bar's scaled space: its top
    for name, value in attributes.items():
        getattr(joint, f"Create{name}Attr")(value)
    return stage, bar, joint


def test_a_revolute_joint_with_limits_stops_the_pendulum_as_its_json_equivalent(tmp_path):
    stage, bar, joint = hinge_stage(tmp_path / "hinge.usda", UsdPhysics.RevoluteJoint, Axis="Z", LowerLimit=-10.0, UpperLimit=40.0)
    # Turning at 2π rad/s about the hinge: the centre, 0.5 m below it, moves at π m/s.
    UsdPhysics.RigidBodyAPI(bar.GetPrim()).CreateAngularVelocityAttr(Gf.Vec3f(0.0, 0.0, 360.0))
    UsdPhysics.RigidBodyAPI(bar.GetPrim()).CreateVelocityAttr(Gf.Vec3f(math.pi, 0.0, 0.0))
    scene, report = usd.stage_to_scene(stage)
    (hinge,) = scene["joints"]
    assert hinge["type"] == "revolute" and hinge["body_b"] == 0
    assert hinge["anchor"] == pytest.approx([0.0, 2.5, 0.0])
    assert hinge["axis"] == pytest.approx([0.0, 0.0, 1.0])
    assert hinge["limits"] == pytest.approx([math.radians(-10.0), math.radians(40.0)])
    equivalent = {
        "dt": 1.0 / 60.0,
        "bodies": [
            {"kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [0.05, 0.5, 0.05]},
             "position": [0.0, 2.0, 0.0], "linear_velocity": [math.pi, 0.0, 0.0], "angular_velocity": [0.0, 0.0, 2.0 * math.pi],
             "mass": 1.0},
            {"kind": "static", "shape": {"type": "sphere", "radius": 0.001}, "position": [0.0, 0.0, 0.0],
             "groups": 0, "mask": 0},
        ],
        "joints": [{"type": "revolute", "body_a": 1, "body_b": 0, "anchor": [0.0, 2.5, 0.0], "axis": [0.0, 0.0, 1.0],
                    "limits": [math.radians(-10.0), math.radians(40.0)]}],
    }  # fmt: skip
    ours, theirs = simulate(scene, 120), simulate(equivalent, 120)
    np.testing.assert_allclose(ours.positions, theirs.positions, atol=1e-5)
    # The bar turns counter-clockwise about z (the stage's positive angle, body 1 against body
    # 0) up to the upper limit, 40°, and never past it or the lower one (to the joint's softness).
    angles = [2.0 * math.atan2(q[2], q[3]) for q in ours.orientations[:, 0]]
    assert max(angles) == pytest.approx(math.radians(40.0), abs=0.02)
    assert min(angles) > math.radians(-10.0) - 0.02
    assert not report.dropped()


def test_a_revolute_drive_spins_a_wheel_at_its_target_velocity(tmp_path):
    stage, bar, joint = hinge_stage(tmp_path / "motor.usda", UsdPhysics.RevoluteJoint, Axis="Z")
    UsdPhysics.MassAPI(bar.GetPrim()).CreateMassAttr(1.0)
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
    drive.CreateTypeAttr("force")
    drive.CreateTargetVelocityAttr(90.0)  # degrees/s
    drive.CreateDampingAttr(1.0e4)
    drive.CreateMaxForceAttr(100.0)
    scene, report = usd.stage_to_scene(stage)
    assert scene["joints"][0]["motor"] == {"velocity": pytest.approx(math.pi / 2), "max_force": 100.0}
    assert any("velocity drive" in issue.message for issue in report.approximated())
    world = impulse.World.from_scene(scene)
    world.step(60)
    assert world.angular_velocities[0, 2] == pytest.approx(math.pi / 2, rel=1e-3)


def test_an_acceleration_drive_is_a_position_motor_of_the_same_frequency(tmp_path):
    stage, bar, joint = hinge_stage(tmp_path / "servo.usda", UsdPhysics.RevoluteJoint, Axis="Z")
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
    drive.CreateTypeAttr("acceleration")
    omega = 2.0 * math.pi * 2.0  # 2 Hz
    drive.CreateStiffnessAttr(omega * omega * math.pi / 180.0)  # per degree
    drive.CreateDampingAttr(2.0 * 0.5 * omega * math.pi / 180.0)
    drive.CreateTargetPositionAttr(20.0)
    scene, _ = usd.stage_to_scene(stage)
    motor = scene["joints"][0]["motor"]
    assert motor["hertz"] == pytest.approx(2.0) and motor["damping_ratio"] == pytest.approx(0.5)
    assert motor["position"] == pytest.approx(math.radians(20.0))


def test_a_force_drive_is_a_position_motor_at_the_body_inertia_about_the_hinge(tmp_path):
    stage, bar, joint = hinge_stage(tmp_path / "force.usda", UsdPhysics.RevoluteJoint, Axis="Z")
    # The 1 kg bar, 0.1 × 1 × 0.1 m, about z through its top end: m(0.1² + 1²)/12 + m·0.5².
    inertia = (0.01 + 1.0) / 12.0 + 0.25
    omega = 2.0 * math.pi * 2.0
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
    drive.CreateTypeAttr("force")
    drive.CreateStiffnessAttr(inertia * omega * omega * math.pi / 180.0)  # N·m per degree
    drive.CreateDampingAttr(2.0 * 0.7 * inertia * omega * math.pi / 180.0)
    scene, report = usd.stage_to_scene(stage)
    motor = scene["joints"][0]["motor"]
    assert motor["hertz"] == pytest.approx(2.0, rel=1e-5) and motor["damping_ratio"] == pytest.approx(0.7, rel=1e-5)
    assert any(f"{inertia:.6g} kg·m²" in issue.message for issue in report.approximated())


def test_a_prismatic_joint_with_limits_stops_the_slider(tmp_path):
    stage, bar, joint = hinge_stage(tmp_path / "slider.usda", UsdPhysics.PrismaticJoint, Axis="Y", LowerLimit=-1.0, UpperLimit=0.0)
    scene, _ = usd.stage_to_scene(stage)
    (slider,) = scene["joints"]
    assert slider["type"] == "prismatic" and slider["limits"] == [-1.0, 0.0]
    trajectory = simulate(scene, 120)
    # Falls 1 m along the axis, then rests on the lower limit.
    assert trajectory.positions[-1, 0, 1] == pytest.approx(1.0, abs=5e-3)
    assert trajectory.positions[-1, 0, 0] == pytest.approx(0.0, abs=1e-4)


def test_fixed_spherical_distance_and_d6_joints_map_to_their_kinds():
    stage = memory_stage()
    cubes = [rigid_cube(stage, f"/c{i}", 1.0, (2.0 * i, 5.0, 0.0)) for i in range(5)]
    kinds = [UsdPhysics.FixedJoint, UsdPhysics.SphericalJoint, UsdPhysics.DistanceJoint, UsdPhysics.Joint]
    for i, kind in enumerate(kinds):
        joint = kind.Define(stage, f"/j{i}")
        joint.CreateBody0Rel().SetTargets([cubes[i].GetPath()])
        joint.CreateBody1Rel().SetTargets([cubes[i + 1].GetPath()])
        joint.CreateLocalPos0Attr(Gf.Vec3f(1.0, 0.0, 0.0))
        joint.CreateLocalPos1Attr(Gf.Vec3f(-1.0, 0.0, 0.0))
    UsdPhysics.SphericalJoint(stage.GetPrimAtPath("/j1")).CreateConeAngle0LimitAttr(30.0)
    UsdPhysics.SphericalJoint(stage.GetPrimAtPath("/j1")).CreateConeAngle1LimitAttr(30.0)
    UsdPhysics.DistanceJoint(stage.GetPrimAtPath("/j2")).CreateMaxDistanceAttr(0.5)
    d6 = stage.GetPrimAtPath("/j3")
    for dof in ("transX", "transY", "transZ"):
        limit = UsdPhysics.LimitAPI.Apply(d6, dof)
        limit.CreateLowAttr(1.0)
        limit.CreateHighAttr(-1.0)
    twist = UsdPhysics.LimitAPI.Apply(d6, "rotX")
    twist.CreateLowAttr(-45.0)
    twist.CreateHighAttr(45.0)
    scene, report = usd.stage_to_scene(stage)
    joints = scene["joints"]
    assert [j["type"] for j in joints] == ["fixed", "spherical", "distance", "generic"]
    assert joints[2]["limits"] == [0.0, 0.5]
    assert joints[2]["world_anchors"] == [[5.0, 5.0, 0.0], [5.0, 5.0, 0.0]]  # cube 2 at x = 4, cube 3 at 6
    assert joints[3]["dofs"] == {
        "linear_x": "locked",
        "linear_y": "locked",
        "linear_z": "locked",
        "angular_x": {"limits": pytest.approx([-math.pi / 4, math.pi / 4])},
        "angular_y": "free",
        "angular_z": "free",
    }
    assert [i.path for i in report.dropped()] == ["/j1"]  # the cone limit impulse lacks
    impulse.World.from_scene(scene).step(10)


def test_a_d6_drive_in_a_z_up_stage_turns_the_body_about_the_up_axis(tmp_path):
    """A D6 joint with its translations and x, y rotations locked and a velocity drive on
    rotZ (OpenUSD's joint example, authored here): its frames, identity in a z-up stage, are
    rolled against the scene's, so the stage's rotZ is the scene's angular_y."""
    stage = new_stage(tmp_path / "d6.usda", "Z", 0.01, rate=24.0, end=24.0)
    post = UsdGeom.Cube.Define(stage, "/World/post")
    post.CreateSizeAttr(100.0)
    post.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 1000.0))
    UsdPhysics.CollisionAPI.Apply(post.GetPrim())
    arm = rigid_cube(stage, "/World/arm", 100.0, (0.0, 120.0, 1000.0))
    joint = UsdPhysics.Joint.Define(stage, "/World/d6")
    joint.CreateBody0Rel().SetTargets([post.GetPath()])
    joint.CreateBody1Rel().SetTargets([arm.GetPath()])
    joint.CreateLocalPos0Attr(Gf.Vec3f(0.0, 60.0, 0.0))
    joint.CreateLocalPos1Attr(Gf.Vec3f(0.0, -60.0, 0.0))
    for dof in ("transX", "transY", "transZ", "rotX", "rotY"):
        limit = UsdPhysics.LimitAPI.Apply(joint.GetPrim(), dof)
        limit.CreateLowAttr(1.0)
        limit.CreateHighAttr(-1.0)
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "rotZ")
    drive.CreateTargetVelocityAttr(10.0)  # degrees/s
    drive.CreateDampingAttr(1.0e4)
    stage.GetRootLayer().Save()
    scene, _ = usd.stage_to_scene(stage)
    dofs = scene["joints"][0]["dofs"]
    assert dofs["angular_y"]["motor"]["velocity"] == pytest.approx(math.radians(10.0))
    assert [dofs[n] for n in ("linear_x", "linear_y", "linear_z", "angular_x", "angular_z")] == ["locked"] * 5
    out = tmp_path / "d6_baked.usda"
    usd.bake(tmp_path / "d6.usda", out)
    baked = Usd.Stage.Open(str(out))
    q = baked.GetPrimAtPath("/World/arm").GetAttribute("xformOp:orient:impulse").Get(24.0)
    imaginary = q.GetImaginary()
    # One second at 10°/s about the stage's z (up), about the post.
    assert 2.0 * math.degrees(math.atan2(imaginary[2], q.GetReal())) == pytest.approx(10.0, rel=1e-3)
    assert abs(imaginary[0]) < 1e-3 and abs(imaginary[1]) < 1e-3


def concave_mesh(stage, path, position):
    """An L-shaped prism (a closed, concave mesh of 8 faces), 1 m tall."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    outline = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    points = [Gf.Vec3f(x * 0.5, y * 0.5, z) for z in (-0.25, 0.25) for x, y in outline]
    faces = [[5, 4, 3, 2, 1, 0], [6, 7, 8, 9, 10, 11]]
    faces += [[i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6] for i in range(6)]
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr([len(f) for f in faces])
    mesh.CreateFaceVertexIndicesAttr([i for f in faces for i in f])
    mesh.AddTranslateOp().Set(Gf.Vec3d(*position))
    UsdPhysics.RigidBodyAPI.Apply(mesh.GetPrim())
    UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())
    UsdPhysics.MeshCollisionAPI.Apply(mesh.GetPrim()).CreateApproximationAttr("convexDecomposition")
    return mesh


def test_a_hundred_convex_decomposition_meshes_bake_as_their_json_equivalent(tmp_path):
    stage = new_stage(tmp_path / "pour.usda", end=20.0)
    ground_plane(stage)
    for i in range(100):
        concave_mesh(stage, f"/World/piece_{i}", (1.5 * (i % 10), 1.0 + 1.5 * (i // 10), 0.0))
    stage.GetRootLayer().Save()
    scene, report = usd.stage_to_scene(stage, steps=20)
    pieces = scene["bodies"][1:]
    assert len(pieces) == 100
    first = pieces[0]["shape"]
    assert first["type"] == "trimesh" and len(first["indices"]) == 2 * 4 + 6 * 2
    assert "decomposition" not in first
    equivalent = json.loads(json.dumps(scene))
    for body in equivalent["bodies"]:
        body.pop("name", None)
    out = tmp_path / "pour_baked.usda"
    usd.bake(stage, out, steps=20)
    theirs = simulate(equivalent, 20)
    baked = Usd.Stage.Open(str(out))
    for index in (1, 50, 100):
        prim = baked.GetPrimAtPath(f"/World/piece_{index - 1}")
        position = UsdGeom.XformCache(Usd.TimeCode(20.0)).GetLocalToWorldTransform(prim).ExtractTranslation()
        assert list(position) == pytest.approx(theirs.positions[-1, index].tolist(), abs=1e-5)
    parts = impulse.Shape.from_dict(first).convex_parts()
    assert len(parts) >= 2  # concave: more than one hull
    assert not report.dropped()


def test_mesh_approximations_become_hulls_boxes_and_spheres():
    stage = memory_stage()
    shapes = {}
    for name, approximation in (("hull", "convexHull"), ("box", "boundingCube"), ("ball", "boundingSphere")):
        mesh = concave_mesh(stage, f"/{name}", (0.0, 0.0, 0.0))
        UsdPhysics.MeshCollisionAPI(mesh.GetPrim()).GetApproximationAttr().Set(approximation)
    scene, _ = usd.stage_to_scene(stage)
    shapes = {b["name"]: b for b in scene["bodies"]}
    assert shapes["/hull"]["shape"]["type"] == "convex_hull" and len(shapes["/hull"]["shape"]["points"]) == 12
    assert shapes["/box"]["shape"] == {"type": "cuboid", "half_extents": [0.5, 0.5, 0.25]}
    assert shapes["/box"]["position"] == [0.5, 0.5, 0.0]  # the bounding box's centre
    assert shapes["/ball"]["shape"]["type"] == "sphere"


def test_everything_not_simulated_is_reported_by_prim_path():
    stage = memory_stage()
    UsdPhysics.Scene.Define(stage, "/secondScene")
    lonely = UsdGeom.Xform.Define(stage, "/lonely")
    UsdPhysics.RigidBodyAPI.Apply(lonely.GetPrim())
    cube = rigid_cube(stage, "/cube", 1.0, (0.0, 0.0, 0.0))
    mass = UsdPhysics.MassAPI.Apply(cube.GetPrim())
    mass.CreateCenterOfMassAttr(Gf.Vec3f(0.1, 0.0, 0.0))
    mass.CreateDiagonalInertiaAttr(Gf.Vec3f(1.0, 2.0, 3.0))
    cube.GetPrim().CreateAttribute("physxRigidBody:maxDepenetrationVelocity", Sdf.ValueTypeNames.Float).Set(3.0)
    off = rigid_cube(stage, "/off", 1.0, (3.0, 0.0, 0.0))
    UsdPhysics.CollisionAPI(off.GetPrim()).CreateCollisionEnabledAttr(False)
    scene, report = usd.stage_to_scene(stage)
    messages = {(issue.path, issue.kind) for issue in report.issues}
    assert ("/secondScene", "dropped") in messages
    assert ("/lonely", "dropped") in messages
    assert ("/off", "dropped") in messages
    assert ("/cube", "approximated") in messages  # centre of mass and inertia
    assert any(i.path == "/cube" and "maxDepenetrationVelocity" in i.message for i in report.dropped())
    assert [b["name"] for b in scene["bodies"]] == ["/cube"]


def test_a_kinematic_body_animated_by_time_samples_moves_through_its_keyframes(tmp_path):
    stage = new_stage(tmp_path / "lift.usda", end=60.0)
    lift = rigid_cube(stage, "/World/lift", 1.0, (0.0, 0.0, 0.0))
    UsdPhysics.RigidBodyAPI(lift.GetPrim()).CreateKinematicEnabledAttr(True)
    translate = UsdGeom.Xformable(lift.GetPrim()).GetOrderedXformOps()[0]
    translate.Set(Gf.Vec3d(0.0, 0.0, 0.0), Usd.TimeCode(0.0))
    translate.Set(Gf.Vec3d(0.0, 2.0, 0.0), Usd.TimeCode(30.0))
    scene, _ = usd.stage_to_scene(stage)
    (body,) = scene["bodies"]
    assert body["kind"] == "kinematic"
    assert body["keyframes"] == [{"t": 0.5, "position": [0.0, 2.0, 0.0]}]
    trajectory = simulate(scene, 60)
    assert trajectory.positions[15, 0, 1] == pytest.approx(1.0, abs=1e-5)
    assert trajectory.positions[60, 0, 1] == pytest.approx(2.0, abs=1e-5)


# -- scenes to stages and back --------------------------------------------------------------


def canonical(scene: dict) -> dict:
    """A scene with every default filled in, body names for indices, and numbers as f32."""
    scene = json.loads(json.dumps(scene))
    materials = {"default": {}} | scene.get("materials", {})
    for material in materials.values():
        material.setdefault("friction", 0.5)
        material.setdefault("restitution", 0.0)
        material.setdefault("density", 1000.0)
    names = [body.get("name") for body in scene["bodies"]]
    for body in scene["bodies"]:
        body.setdefault("position", [0.0, 0.0, 0.0])
        body.setdefault("orientation", [0.0, 0.0, 0.0, 1.0])
        for field in ("linear_velocity", "angular_velocity"):
            body.setdefault(field, [0.0, 0.0, 0.0])
        body.setdefault("material", "default")
    for joint in scene.get("joints", []):
        for end in ("body_a", "body_b"):
            if isinstance(joint[end], str):
                joint[end] = names.index(joint[end])
        motors = [joint.get("motor")] + [d.get("motor") for d in joint.get("dofs", {}).values() if isinstance(d, dict)]
        for motor in motors:
            if motor is not None and "velocity" in motor:
                motor.pop("hertz", None)
                motor.pop("damping_ratio", None)
        if joint["type"] == "generic":
            for dof in ("linear_x", "linear_y", "linear_z", "angular_x", "angular_y", "angular_z"):
                joint.setdefault("dofs", {}).setdefault(dof, "locked")
        if joint["type"] in ("revolute", "prismatic", "generic") and "axis" not in joint and "axis_a" not in joint:
            joint["axis"] = [1.0, 0.0, 0.0]
    return {
        "name": scene.get("name", ""),
        "gravity": scene.get("gravity", [0.0, -9.81, 0.0]),
        "dt": scene.get("dt", 1.0 / 60.0),
        "steps": scene.get("steps", 600),
        "solver": scene.get("solver", {}),
        "seed": scene.get("seed", 0),
        "materials": materials,
        "bodies": scene["bodies"],
        "joints": scene.get("joints", []),
    }


def assert_same(a, b, path=""):
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), f"{path}: keys {sorted(a)} != {sorted(b)}"
        for key in a:
            assert_same(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {a} != {b}"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert np.float32(a) == np.float32(b), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


@pytest.mark.parametrize("name", ROUND_TRIP_SCENES)
def test_a_scene_goes_to_a_stage_and_back_unchanged(tmp_path, repository, name):
    source = repository / "scenes" / f"{name}.json"
    stage_path = tmp_path / f"{name}.usda"
    usd.scene_to_stage(source, stage_path)
    assert validation_errors(stage_path) == []
    scene, report = usd.stage_to_scene(stage_path)
    original = json.loads(source.read_text())
    ours, theirs = canonical(scene), canonical(original)
    joints_ours, joints_theirs = ours.pop("joints"), theirs.pop("joints")
    assert_same(ours, theirs)
    # Joints come back through their frames: anchors and axes to f32 rounding of the turns.
    assert len(joints_ours) == len(joints_theirs)
    for mine, given in zip(joints_ours, joints_theirs, strict=True):
        assert sorted(mine) == sorted(given)
        for key in mine:
            if key in ("anchor", "axis", "limits", "world_anchors"):
                np.testing.assert_allclose(np.array(mine[key]), np.array(given[key]), atol=2e-6)
            else:
                assert_same(mine[key], given[key], key)
    assert not report.dropped()
    # The two scenes run alike: the same bodies, and joints whose frames differ in f32 rounding.
    np.testing.assert_allclose(simulate(scene, 60).positions, simulate(original, 60).positions, atol=1e-4)


def test_python_m_impulse_usd_runs_exports_and_imports(tmp_path):
    from impulse.usd.__main__ import main

    box_drop(tmp_path / "drop.usda", "Z", 0.01)
    assert main(["run", str(tmp_path / "drop.usda"), "--out", str(tmp_path / "baked.usda"), "--steps", "30", "--quiet"]) == 0
    assert Usd.Stage.Open(str(tmp_path / "baked.usda")).GetEndTimeCode() == 30.0
    assert main(["export", str(tmp_path / "drop.usda"), "--out", str(tmp_path / "drop.json"), "--quiet"]) == 0
    scene = json.loads((tmp_path / "drop.json").read_text())
    assert scene["bodies"][1]["position"] == pytest.approx([0.0, 2.0, 0.0])
    assert main(["import", str(tmp_path / "drop.json"), "--out", str(tmp_path / "again.usda")]) == 0
    assert main(["run", str(tmp_path / "missing.usda"), "--out", str(tmp_path / "x.usda")]) == 2
    # --strict refuses a stage with anything dropped, before writing.
    stage = Usd.Stage.Open(str(tmp_path / "drop.usda"))
    UsdPhysics.Scene.Define(stage, "/World/secondScene")
    stage.GetRootLayer().Save()
    for command in ("run", "export"):
        out = tmp_path / f"strict_{command}.out"
        assert main([command, str(tmp_path / "drop.usda"), "--out", str(out), "--strict", "--quiet"]) == 3
        assert not out.exists()


def test_frames_turn_z_up_into_y_up():
    turn = _frames.up_rotation("Z")
    assert list(_frames.rotate(turn, (0.0, 0.0, 1.0))) == pytest.approx([0.0, 1.0, 0.0])
    assert list(_frames.rotate(turn, (0.0, 1.0, 0.0))) == pytest.approx([0.0, 0.0, -1.0])
    for axis in "XYZ":
        assert list(_frames.rotate(_frames.axis_rotation(axis), (0.0, 1.0, 0.0))) == pytest.approx(list(_frames.axis_vector(axis)))
        assert list(_frames.rotate(_frames.x_to_axis(axis), (1.0, 0.0, 0.0))) == pytest.approx(list(_frames.axis_vector(axis)))


def test_the_impulse_command_reads_and_bakes_stages_through_the_python_reader(tmp_path, impulse_cli):
    import os
    import subprocess
    import sys

    environment = dict(os.environ, IMPULSE_PYTHON=sys.executable)
    box_drop(tmp_path / "drop.usda", "Z", 0.01)

    def run(*arguments):
        return subprocess.run([impulse_cli, *arguments], capture_output=True, text=True, env=environment, check=False)

    baked = run("run", str(tmp_path / "drop.usda"), "--out", str(tmp_path / "baked.usda"), "--steps", "120")
    assert baked.returncode == 0, baked.stderr
    _, heights = world_heights(tmp_path / "baked.usda", "/World/box", 2)
    assert heights[-1] == pytest.approx(50.0, abs=0.1)
    # Any other run reads the stage's scene and runs it as impulse runs a JSON scene.
    csv = run("run", str(tmp_path / "drop.usda"), "--out", str(tmp_path / "drop.csv"), "--steps", "120", "--quiet")
    assert csv.returncode == 0, csv.stderr
    frame, _, body, _, y = (tmp_path / "drop.csv").read_text().strip().splitlines()[-1].split(",")[:5]
    assert (frame, body) == ("120", "1") and float(y) == pytest.approx(0.5, abs=1e-3)
    exported = run("export", str(tmp_path / "drop.usda"), "--out", str(tmp_path / "drop.json"))
    assert exported.returncode == 0, exported.stderr
    assert json.loads((tmp_path / "drop.json").read_text())["bodies"][1]["position"] == pytest.approx([0.0, 2.0, 0.0])
    written = run("export", str(tmp_path / "drop.json"), "--out", str(tmp_path / "again.usda"))
    assert written.returncode == 0, written.stderr
    assert validation_errors(tmp_path / "again.usda") == []
    missing = subprocess.run(
        [impulse_cli, "export", str(tmp_path / "drop.usda")],
        capture_output=True,
        text=True,
        env=dict(environment, IMPULSE_PYTHON=str(tmp_path / "no-python")),
        check=False,
    )
    assert missing.returncode != 0 and "could not be started" in missing.stderr


def test_the_issue_stage_bakes_with_every_feature_honoured(tmp_path):
    """100 convex-decomposition meshes, a revolute and a prismatic joint with limits and a drive,
    two materials and a filtered pair, in one z-up centimetre stage: each feature is in the
    scene, and the baked layer's poses are the scene's run, turned back into the stage."""
    stage = new_stage(tmp_path / "shot.usda", "Z", 0.01, end=30.0)
    ground = ground_plane(stage)
    for i in range(100):
        concave_mesh(stage, f"/World/piece_{i}", (150.0 * (i % 10), 150.0 * (i // 10), 100.0))
    for i in range(100):
        UsdGeom.Mesh(stage.GetPrimAtPath(f"/World/piece_{i}")).GetPointsAttr().Set(
            [p * 100.0 for p in UsdGeom.Mesh(stage.GetPrimAtPath(f"/World/piece_{i}")).GetPointsAttr().Get()]
        )
    looks = {}
    for name, friction in (("wood", 0.6), ("rubber", 1.0)):
        material = UsdShade.Material.Define(stage, f"/World/Looks/{name}")
        api = UsdPhysics.MaterialAPI.Apply(material.GetPrim())
        api.CreateStaticFrictionAttr(friction)
        api.CreateDynamicFrictionAttr(friction)
        looks[name] = material
    door = rigid_cube(stage, "/World/door", 100.0, (-500.0, 0.0, 300.0), mass=10.0)
    slider = rigid_cube(stage, "/World/slider", 50.0, (-800.0, 0.0, 300.0), mass=2.0)
    ghost = rigid_cube(stage, "/World/ghost", 50.0, (-1100.0, 0.0, 100.0))
    for prim, name in ((door, "wood"), (slider, "rubber"), (ghost, "wood")):
        UsdShade.MaterialBindingAPI.Apply(prim.GetPrim()).Bind(looks[name], UsdShade.Tokens.weakerThanDescendants, "physics")
    UsdPhysics.FilteredPairsAPI.Apply(ghost.GetPrim()).CreateFilteredPairsRel().AddTarget(ground.GetPath())
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/World/hinge")
    hinge.CreateBody1Rel().SetTargets([door.GetPath()])
    hinge.CreateLocalPos0Attr(Gf.Vec3f(-550.0, 0.0, 350.0))
    hinge.CreateLocalPos1Attr(Gf.Vec3f(-50.0, 0.0, 50.0))
    hinge.CreateAxisAttr("Y")
    hinge.CreateLowerLimitAttr(-45.0)
    hinge.CreateUpperLimitAttr(45.0)
    drive = UsdPhysics.DriveAPI.Apply(hinge.GetPrim(), "angular")
    drive.CreateTypeAttr("acceleration")
    drive.CreateStiffnessAttr(10.0)
    drive.CreateDampingAttr(1.0)
    drive.CreateTargetPositionAttr(20.0)
    rail = UsdPhysics.PrismaticJoint.Define(stage, "/World/rail")
    rail.CreateBody1Rel().SetTargets([slider.GetPath()])
    rail.CreateLocalPos0Attr(Gf.Vec3f(-800.0, 0.0, 300.0))
    rail.CreateAxisAttr("Z")
    rail.CreateLowerLimitAttr(-100.0)
    rail.CreateUpperLimitAttr(0.0)
    push = UsdPhysics.DriveAPI.Apply(rail.GetPrim(), "linear")
    push.CreateTargetVelocityAttr(50.0)
    push.CreateDampingAttr(1.0e4)
    push.CreateMaxForceAttr(1.0e5)
    stage.GetRootLayer().Save()

    scene, report = usd.stage_to_scene(stage)
    bodies = {body["name"]: body for body in scene["bodies"]}
    meshes = [b for b in scene["bodies"] if b["name"].startswith("/World/piece_")]
    assert len(meshes) == 100 and all(b["shape"]["type"] == "trimesh" for b in meshes)
    hinge_joint, rail_joint = scene["joints"]
    assert hinge_joint["type"] == "revolute" and hinge_joint["limits"] == pytest.approx([-math.pi / 4, math.pi / 4])
    assert hinge_joint["motor"]["position"] == pytest.approx(math.radians(20.0))
    assert rail_joint["type"] == "prismatic" and rail_joint["limits"] == pytest.approx([-1.0, 0.0])
    assert rail_joint["motor"] == {"velocity": pytest.approx(0.5), "max_force": pytest.approx(1000.0)}
    assert bodies["/World/door"]["material"] == "wood" and bodies["/World/slider"]["material"] == "rubber"
    ghost_body, ground_body = bodies["/World/ghost"], bodies["/World/ground"]
    assert not ghost_body["groups"] & ground_body["mask"]
    assert not report.dropped()

    out = tmp_path / "shot_baked.usda"
    usd.bake(tmp_path / "shot.usda", out)
    trajectory = simulate(scene, 30)
    baked = Usd.Stage.Open(str(out))
    turn = _frames.up_rotation("Z").GetInverse()
    for index, body in enumerate(scene["bodies"]):
        if body["kind"] == "static" or index % 17:
            continue
        prim = baked.GetPrimAtPath(body["name"])
        position = UsdGeom.XformCache(Usd.TimeCode(30.0)).GetLocalToWorldTransform(prim).ExtractTranslation()
        expected = _frames.rotate(turn, trajectory.positions[-1, index].tolist()) / 0.01
        assert list(position) == pytest.approx(list(expected), abs=1e-3)  # 10 µm in centimetres
    # The slider rode its rail up at 0.5 m/s until the upper limit... of 0: it stays at 0..-1 m.
    assert validation_errors(out) == []


def test_quaternion_arrays_round_trip_through_matrices_on_every_branch():
    rng = np.random.default_rng(7)
    q = rng.normal(size=(400, 4))
    # Half turns about each axis pick each of Shepperd's four branches.
    q[:4] = [[0, 0, 0, 1], [1, 0, 0, 1e-3], [0, 1, 0, 1e-3], [0, 0, 1, 1e-3]]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    back = _frames.matrix_quat(_frames.quat_matrix(q))
    np.testing.assert_allclose(np.abs(np.sum(back * q, axis=1)), 1.0, atol=1e-12)
    v = rng.normal(size=(400, 3))
    np.testing.assert_allclose(_frames.quat_rotate(q, v), np.einsum("nij,nj->ni", _frames.quat_matrix(q), v), atol=1e-12)
    a, b = q[:200], q[200:]
    product = _frames.quat_matrix(_frames.quat_multiply(a, b))
    np.testing.assert_allclose(product, _frames.quat_matrix(a) @ _frames.quat_matrix(b), atol=1e-12)
    # A scaled, turned, moved local matrix splits into its ops; a sheared one does not.
    matrices = np.zeros((400, 4, 4))
    matrices[:, :3, :3] = np.array([2.0, 3.0, 0.5])[None, :, None] * np.transpose(_frames.quat_matrix(q), (0, 2, 1))
    matrices[:, 3, :3] = v
    matrices[:, 3, 3] = 1.0
    translations, rotations, scale = _frames.trs_from_matrices(matrices)
    np.testing.assert_allclose(scale, [2.0, 3.0, 0.5])
    np.testing.assert_allclose(translations, v)
    np.testing.assert_allclose(np.abs(np.sum(rotations * q, axis=1)), 1.0, atol=1e-12)
    matrices[5, 0, 1] += 0.1
    assert _frames.trs_from_matrices(matrices) is None


def test_a_static_compound_is_one_disabled_rigid_body_and_comes_back_whole(tmp_path):
    rack = {
        "name": "rack",
        "kind": "static",
        "shape": {
            "type": "compound",
            "parts": [
                {"shape": {"type": "cuboid", "half_extents": [1.0, 0.1, 1.0]}, "position": [0.0, 0.0, 0.0]},
                {"shape": {"type": "sphere", "radius": 0.3}, "position": [0.0, 1.0, 0.0]},
            ],
        },
        "position": [0.0, 0.5, 0.0],
        "orientation": [0.0, 0.38268343, 0.0, 0.9238795],
    }
    ball = {"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.2}, "position": [0.0, 3.0, 0.0]}
    stage = usd.scene_to_stage({"bodies": [rack, ball]}, tmp_path / "rack.usda")
    assert not UsdPhysics.RigidBodyAPI(stage.GetPrimAtPath("/World/rack")).GetRigidBodyEnabledAttr().Get()
    scene, report = usd.stage_to_scene(tmp_path / "rack.usda")
    assert scene["bodies"] == [rack, ball]
    assert not report.issues
