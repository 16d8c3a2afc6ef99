"""Setups from the field, built as the interface builds them (field.py), each checked for what
a viewer of the baked animation sees: the thrown ball reaches the wall, the cube rests on the
plane, the ring threads the peg, the ball stays in the mug."""

import math

import bpy
import mathutils
import numpy as np
import pytest
from impulse_bake import bake, keyframes, scene_reader

import field

FRAMES = 48

#: What a flat shape's note says to choose its thickness when Collision Margin is not ticked.
UNTICKED_MARGIN = (
    "tick Collision Margin to choose it: twice the Margin; or give the mesh thickness, "
    "a Solidify modifier with Source Final"
)


@pytest.mark.parametrize(("flag", "animated"), [("rigid_body.kinematic", True), ("rigid_body.enabled", False)])
def test_a_ball_keyed_animated_then_released_keeps_flying_and_reaches_the_wall(flag, animated):
    # The standard throw: animate the ball with Animated ticked (or Dynamic unticked), key the
    # flag the other way after the last key of the throw; Blender's simulation takes over with
    # the animation's velocity.
    scene = field.startup(FRAMES)
    wall = field.add("cube", "Wall", size=1.0, location=(7.25, 0.0, 2.5))
    wall.scale = (0.5, 6.0, 5.0)
    field.rigid(wall, "PASSIVE")
    field.ground()
    ball = field.add("uv_sphere", "Ball", radius=0.5, location=(0.0, 0.0, 2.0))
    field.rigid(ball)
    field.key(ball, "location", 1, (0.0, 0.0, 2.0))
    field.key(ball, "location", 10, (3.0, 0.0, 2.5))
    field.key(ball, flag, 1, animated, interpolation=None)
    field.key(ball, flag, 10, animated, interpolation=None)
    field.key(ball, flag, 11, not animated, interpolation=None)

    bake.bake_scene(scene)

    # Until frame 10 the ball follows its animation, then it flies on (not frozen in the air).
    assert field.world_at(scene, ball, 5).translation.x == pytest.approx(4 * 3.0 / 9, abs=1e-4)
    assert field.world_at(scene, ball, 10).translation.x == pytest.approx(3.0, abs=1e-4)
    speed = 3.0 / 9 * scene.render.fps  # m/s along x at the release
    after = field.world_at(scene, ball, 13).translation
    assert after.x == pytest.approx(3.0 + 3 * speed / scene.render.fps, abs=0.05)
    xs = [field.world_at(scene, ball, f).translation.x for f in range(1, FRAMES + 1)]
    face = 7.0  # the wall's face towards the ball
    assert max(xs) == pytest.approx(face - 0.5, abs=0.02), "the ball reaches the wall"
    assert max(xs) <= face - 0.5 + 0.01, "and does not pass into it"
    # The ball's own animation is kept: the bake wrote into a copy of its action.
    assert ball.animation_data.action.get("impulse_original_action")


def test_a_simulated_ball_keyed_animated_again_snaps_to_its_animation_and_follows_it():
    scene = field.startup(FRAMES)
    field.ground()
    ball = field.add("uv_sphere", "Ball", radius=0.5, location=(0.0, 0.0, 0.5))
    field.rigid(ball)
    field.key(ball, "rigid_body.kinematic", 1, False, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 20, True, interpolation=None)
    # Held at the start until frame 20 (a constant key), then lifted and carried along x.
    field.key(ball, "location", 1, (0.0, 0.0, 0.5))
    field.key(ball, "location", 20, (0.0, 0.0, 3.0))
    field.key(ball, "location", 40, (4.0, 0.0, 3.0))
    for fcurve in keyframes._fcurve_collection(ball, create=False):
        if fcurve.data_path == "location":
            fcurve.keyframe_points[0].interpolation = "CONSTANT"
    bake.bake_scene(scene)
    assert field.world_at(scene, ball, 10).translation.z == pytest.approx(0.5, abs=0.01), "resting, simulated"
    for frame in (20, 30, 40):
        expected = (frame - 20) / 20 * 4.0
        at = field.world_at(scene, ball, frame).translation
        assert (at.x, at.z) == (pytest.approx(expected, abs=1e-3), pytest.approx(3.0, abs=1e-3)), frame


def test_a_ball_released_while_spinning_keeps_its_spin():
    scene = field.startup(24)
    ball = field.add("cube", "Spinner", size=1.0, location=(0.0, 0.0, 5.0))
    field.rigid(ball)
    scene.use_gravity = False
    field.key(ball, "rotation_euler", 1, (0.0, 0.0, 0.0))
    field.key(ball, "rotation_euler", 5, (0.0, 0.0, math.radians(40.0)))
    field.key(ball, "rigid_body.kinematic", 1, True, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 5, True, interpolation=None)
    field.key(ball, "rigid_body.kinematic", 6, False, interpolation=None)
    bake.bake_scene(scene)
    # 10° a frame before the release, 10° a frame after it.
    angle = field.world_at(scene, ball, 9).to_euler().z
    assert math.degrees(angle) == pytest.approx(80.0, abs=0.5)
    assert ball.rotation_mode == "XYZ"


@pytest.mark.parametrize("shape", ["CONVEX_HULL", "BOX", "MESH"])
def test_a_cube_dropped_on_the_tutorial_plane_rests_on_it(shape):
    # Needs the engine's thin shapes for CONVEX_HULL and BOX (flat cuboid and hull).
    scene = field.startup(FRAMES, keep_cube=True)
    cube = scene.objects["Cube"]
    cube.location = (0.0, 0.0, 4.0)
    field.rigid(cube)
    plane = field.add("plane", "Plane", size=20.0)
    field.rigid(plane, "PASSIVE")
    plane.rigid_body.collision_shape = shape
    info = scene_reader.read_scene(scene)
    if shape != "MESH":
        label = "Convex Hull" if shape == "CONVEX_HULL" else "Box"
        assert f"Plane: a flat {label} — baked as a thin shape 2 mm thick ({UNTICKED_MARGIN})" in info.notes
    bake.bake_scene(scene)
    rest = field.world_at(scene, cube, FRAMES).translation
    assert rest.z == pytest.approx(1.0, abs=0.06)
    assert abs(rest.x) < 0.05 and abs(rest.y) < 0.05  # where it fell (a flat landing shifts it by a few cm)


def test_a_plane_grounds_bake_says_in_blenders_words_how_thick_it_is():
    """The tutorial's plane ground: the bake's only word on it is the note naming the Plane,
    its thickness and the setting that chooses it (no Python warning in the scene file's
    words); ticking Collision Margin or giving it a Solidify read with Source Final does what
    the note says. (test_operator.py: the operator reports the note.)"""
    import warnings

    scene = field.startup(FRAMES, keep_cube=True)
    cube = scene.objects["Cube"]
    cube.location = (0.0, 0.0, 4.0)
    field.rigid(cube)
    plane = field.add("plane", "Plane", size=20.0)
    field.rigid(plane, "PASSIVE")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert bake.Baker(scene).info.notes == [
            f"Plane: a flat Convex Hull — baked as a thin shape 2 mm thick ({UNTICKED_MARGIN})"
        ]
    plane.rigid_body.use_margin = True
    plane.rigid_body.collision_margin = 0.01
    assert bake.Baker(scene).info.notes == [
        "Plane: a flat Convex Hull — baked as a thin shape 20 mm thick (twice its Collision Margin)"
    ]
    plane.rigid_body.use_margin = False
    plane.modifiers.new("Solidify", "SOLIDIFY").thickness = 0.1
    plane.rigid_body.mesh_source = "FINAL"
    baker = bake.Baker(scene)
    assert baker.info.notes == []
    bodies = [b.object_name for b in baker.info.bodies]
    assert "thickness" not in baker.info.scene["bodies"][bodies.index("Plane")]["shape"]


def test_an_active_card_falls_flat_onto_the_ground():
    # Needs the engine's thin shapes: a plane made Active keeps the default Convex Hull.
    scene = field.startup(FRAMES)
    field.ground()
    card = field.add("plane", "Card", size=1.0, location=(0.0, 0.0, 2.0))
    field.rigid(card)
    bake.bake_scene(scene)
    vertices = field.world_vertices(scene, card, FRAMES)
    assert all(-0.01 < v.z < 0.06 for v in vertices), [tuple(v) for v in vertices]


def test_a_parented_active_object_falls_in_world_space_and_is_keyed_in_its_parents():
    scene = field.startup(FRAMES)
    field.ground()
    bpy.ops.object.empty_add(location=(2.0, 1.0, 0.5), rotation=(0.0, 0.0, math.radians(90.0)))
    parent = bpy.context.object
    parent.name = "Rig"
    parent.scale = (2.0, 2.0, 2.0)
    cube = field.add("cube", "Crate", size=1.0, location=(3.0, 1.0, 4.0))
    field.select(cube)
    parent.select_set(True)
    bpy.context.view_layer.objects.active = parent
    # Parent without inverse: the crate's own transform is then in the rotated, scaled space.
    bpy.ops.object.parent_no_inverse_set(keep_transform=True)
    field.rigid(cube)
    start = field.world_at(scene, cube, 1)
    bake.bake_scene(scene)
    end = field.world_at(scene, cube, FRAMES)
    assert end.translation.z == pytest.approx(0.5, abs=0.01)
    # Where it landed (a flat landing shifts a hull by a few centimetres) and upright.
    assert end.translation.x == pytest.approx(3.0, abs=0.05) and end.translation.y == pytest.approx(1.0, abs=0.05)
    assert (end.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))).z == pytest.approx(1.0, abs=1e-3)
    assert tuple(cube.scale) == pytest.approx((1.0, 1.0, 1.0))
    # Keyed in the parent's rotated, scaled space: the location is not the world position.
    assert (cube.location - end.translation).length > 1.0
    assert tuple(field.world_at(scene, cube, 1).translation) == pytest.approx(tuple(start.translation), abs=1e-5)
    assert cube.parent is parent


def _wedge(name, location):
    """A ramp-shaped mesh (a cube whose top edge at +x is lowered to the bottom): asymmetric in
    x, so its mirror image differs from it."""
    obj = field.add("cube", name, size=1.0, location=location)
    for vertex in obj.data.vertices:
        if vertex.co.x > 0 and vertex.co.z > 0:
            vertex.co.z = -0.5
    return obj


def test_a_mirrored_object_falls_as_the_mirror_image_of_the_original():
    scene = field.startup(FRAMES)
    field.ground()
    original = _wedge("Wedge", (-3.0, 0.0, 2.0))
    original.rotation_euler = (0.3, 0.2, 0.0)
    mirrored = _wedge("WedgeMirrored", (3.0, 0.0, 2.0))
    mirrored.scale = (-1.0, 1.0, 1.0)
    mirrored.rotation_euler = (0.3, -0.2, 0.0)
    for obj in (original, mirrored):
        field.rigid(obj)
    bake.bake_scene(scene)
    a = np.array([tuple(v) for v in field.world_vertices(scene, original, FRAMES)])
    b = np.array([tuple(v) for v in field.world_vertices(scene, mirrored, FRAMES)])
    b[:, 0] *= -1.0
    np.testing.assert_allclose(np.sort(b, axis=0), np.sort(a, axis=0), atol=0.02)
    assert b[:, 2].min() == pytest.approx(0.0, abs=0.01)
    assert tuple(mirrored.scale) == pytest.approx((-1.0, 1.0, 1.0))


def test_a_compound_parent_falls_as_one_body_on_its_childrens_shapes():
    # A table: a top whose shape is Compound Parent, two legs parented to it (default shapes).
    scene = field.startup(FRAMES)
    field.ground()
    top = field.add("cube", "Table", size=1.0, location=(0.0, 0.0, 2.05))
    top.scale = (2.0, 1.0, 0.1)
    legs = []
    for side in (-1.0, 1.0):
        leg = field.add("cube", f"Leg{'L' if side < 0 else 'R'}", size=1.0, location=(0.9 * side, 0.0, 1.5))
        leg.scale = (0.1, 0.8, 1.0)
        legs.append(leg)
    bpy.context.view_layer.update()
    for leg in legs:
        field.select(leg)
        top.select_set(True)
        bpy.context.view_layer.objects.active = top
        bpy.ops.object.parent_set(type="OBJECT", keep_transform=True)
        field.rigid(leg)
    field.rigid(top)
    top.rigid_body.collision_shape = "COMPOUND"
    info = scene_reader.read_scene(scene)
    assert [b.object_name for b in info.bodies] == ["Ground", "Table"]
    assert len(info.bodies[1].body["shape"]["parts"]) == 2
    bake.bake_scene(scene)
    for leg in legs:
        lowest = min(v.z for v in field.world_vertices(scene, leg, FRAMES))
        assert lowest == pytest.approx(0.0, abs=0.01), leg.name
    assert field.world_at(scene, top, FRAMES).translation.z == pytest.approx(1.05, abs=0.01)


def test_source_deform_is_the_base_mesh_with_the_leading_deform_modifiers():
    scene = field.startup(4)
    cube = field.add("cube", "Bevelled", size=2.0, location=(0.0, 0.0, 3.0))
    cube.modifiers.new("Displace", "DISPLACE").strength = 0.5  # deform-only: moves the 8 points
    cube.modifiers.new("Bevel", "BEVEL")
    cube.modifiers.new("Subdivision", "SUBSURF")
    field.rigid(cube)
    shapes = {}
    for source in ("BASE", "DEFORM", "FINAL"):
        cube.rigid_body.mesh_source = source
        shapes[source] = scene_reader.read_scene(scene).bodies[0].body["shape"]
    # The base and deformed meshes are centred boxes (their hulls are boxes): cuboids.
    assert shapes["BASE"] == {"type": "cuboid", "half_extents": pytest.approx([1.0, 1.0, 1.0])}
    # Displace moves the corners along their normals by strength × (1 − midlevel) = 0.25.
    grown = 1.0 + 0.25 / math.sqrt(3.0)
    assert shapes["DEFORM"] == {"type": "cuboid", "half_extents": pytest.approx([grown] * 3, abs=1e-5)}
    assert shapes["FINAL"]["type"] == "convex_hull" and len(shapes["FINAL"]["points"]) > 50
    assert all(m.show_viewport for m in cube.modifiers)


def test_a_convex_hull_of_a_centred_box_is_a_cuboid_and_of_anything_else_a_hull():
    # The Add menu's cube with the default shape (Convex Hull), scaled: the same solid as a
    # cuboid, which the engine takes by its exact box paths.
    scene = field.startup(4)
    slab = field.add("cube", "Slab", size=1.0, location=(0.0, 0.0, 3.0))
    slab.scale = (4.0, 2.0, 0.5)
    bpy.context.view_layer.update()
    field.rigid(slab)
    body = scene_reader.read_scene(scene).bodies[0].body
    # impulse's y is Blender's z.
    assert body["shape"] == {"type": "cuboid", "half_extents": pytest.approx([2.0, 0.25, 1.0])}
    # Its origin off the box's centre, or its mesh turned inside the object: a hull of 8 points.
    for vertex in slab.data.vertices:
        vertex.co.z += 0.5
    assert scene_reader.read_scene(scene).bodies[0].body["shape"]["type"] == "convex_hull"
    for vertex in slab.data.vertices:
        vertex.co.z -= 0.5
        vertex.co = mathutils.Matrix.Rotation(0.3, 3, "Z") @ vertex.co
    shape = scene_reader.read_scene(scene).bodies[0].body["shape"]
    assert shape["type"] == "convex_hull" and len(shape["points"]) == 8


def test_a_box_shape_is_centred_on_the_origin_as_blender_centres_it():
    scene = field.startup(4)
    crate = field.add("cube", "Crate", size=1.0, location=(0.0, 0.0, 3.0))
    for vertex in crate.data.vertices:
        vertex.co.z += 0.5  # the origin at the bottom face
    field.rigid(crate)
    crate.rigid_body.collision_shape = "BOX"
    body = scene_reader.read_scene(scene).bodies[0].body
    assert body["shape"] == {"type": "cuboid", "half_extents": pytest.approx([0.5, 0.5, 0.5])}


@pytest.mark.parametrize(("materials", "slides"), [("blender", True), ("impulse", False)])
def test_friction_combines_as_blender_multiplies_it_or_as_impulse_does(materials, slides):
    # Both frictions 0.5 on a 20° ramp (tan 20° = 0.36): Blender's μa·μb = 0.25 slides, impulse's
    # √(μa·μb) = 0.5 holds.
    scene = field.startup(FRAMES)
    ramp = field.add("cube", "Ramp", size=1.0, location=(0.0, 0.0, 0.0), rotation=(0.0, math.radians(20.0), 0.0))
    ramp.scale = (10.0, 4.0, 0.2)
    field.rigid(ramp, "PASSIVE")
    block = field.add("cube", "Block", size=0.5)
    normal = ramp.matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))
    block.location = normal.normalized() * (0.1 + 0.25)
    block.rotation_euler = ramp.rotation_euler
    field.rigid(block)
    for obj in (ramp, block):
        obj.rigid_body.friction = 0.5
    start = field.world_at(scene, block, 1).translation.copy()
    bake.bake_scene(scene, materials=materials)
    moved = (field.world_at(scene, block, FRAMES).translation - start).length
    if slides:
        assert moved > 0.5
    else:
        assert moved < 0.01


def test_a_moving_mesh_shape_is_a_triangle_mesh_never_its_hull():
    scene = field.startup(4)
    ring = field.add("torus", "Ring", location=(0.0, 0.0, 3.0))
    field.rigid(ring)
    floor = field.add("plane", "Floor", size=20.0)
    field.rigid(floor, "PASSIVE")
    for obj in (ring, floor):
        obj.rigid_body.collision_shape = "MESH"
    bodies = {b.object_name: b.body for b in scene_reader.read_scene(scene, resolution=96).bodies}
    assert bodies["Ring"]["shape"]["type"] == "trimesh"
    assert bodies["Ring"]["shape"]["decomposition"] == {"resolution": 96}
    assert len(bodies["Ring"]["shape"]["indices"]) == 2 * len(ring.data.polygons)
    assert bodies["Floor"]["shape"]["two_sided"] and "decomposition" not in bodies["Floor"]["shape"]


def test_a_torus_dropped_over_a_peg_threads_onto_it():
    # Needs the engine's convex decomposition of a Mesh shape on a dynamic body.
    scene = field.startup(72)
    field.ground()
    peg = field.add("cylinder", "Peg", radius=0.2, depth=2.0, location=(0.0, 0.0, 1.0))
    field.rigid(peg, "PASSIVE")
    ring = field.add("torus", "Ring", major_radius=0.8, minor_radius=0.15, location=(0.05, 0.0, 3.0))
    field.rigid(ring)
    ring.rigid_body.collision_shape = "MESH"
    bake.bake_scene(scene)
    rest = field.world_at(scene, ring, 72).translation
    assert rest.z < 0.3, "the ring slid down the peg to the ground"
    assert math.hypot(rest.x, rest.y) < 0.8, "around the peg"


def test_a_ball_dropped_into_a_mug_stays_in_it_and_the_mug_stays_on_the_floor():
    # Needs the engine's convex decomposition of a Mesh shape on a dynamic body.
    scene = field.startup(72)
    floor = field.add("plane", "Floor", size=20.0)
    field.rigid(floor, "PASSIVE")
    floor.rigid_body.collision_shape = "MESH"
    mug = field.add("cylinder", "Mug", radius=1.0, depth=2.0, location=(0.0, 0.0, 1.05))
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    top = [p for p in mug.data.polygons if p.normal.z > 0.99]
    for polygon in top:
        polygon.select = True
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.delete(type="ONLY_FACE")
    bpy.ops.object.mode_set(mode="OBJECT")
    mug.modifiers.new("Solidify", "SOLIDIFY").thickness = 0.1
    field.rigid(mug)
    mug.rigid_body.collision_shape = "MESH"
    mug.rigid_body.mesh_source = "FINAL"
    ball = field.add("uv_sphere", "Ball", radius=0.3, location=(0.1, 0.0, 4.0))
    field.rigid(ball)
    bake.bake_scene(scene)
    ball_at = field.world_at(scene, ball, 72).translation
    assert math.hypot(ball_at.x, ball_at.y) < 1.0, "the ball is inside the mug's wall"
    assert 0.0 < ball_at.z < 2.05, "below the rim, above the floor"
    lowest = min(v.z for v in field.world_vertices(scene, mug, 72))
    assert lowest > -0.01, "the mug stands on the floor"


@pytest.mark.parametrize("fps", [24, 60])
def test_tumbling_pins_land_on_a_default_ground_without_sinking_into_it(fps):
    # Ten pin-sized cylinders (12 sides, 0.38 m tall; Convex Hull, the default) dropped at
    # seeded tilts onto the Add menu's cube scaled into a ground (a cuboid, above): at no frame
    # is a vertex more than 5 mm under the ground's top (0.01 mm at 24 fps, 0.55 mm at 60; with
    # the ground a hull of 8 points, 0.18 and 0.55 mm).
    scene = field.startup(2 * fps)
    scene.render.fps = fps
    field.ground()
    rng = np.random.default_rng(7)
    pins = []
    for k in range(10):
        tilt = rng.uniform(-1.2, 1.2, size=2)
        pin = field.add(
            "cylinder",
            f"Pin{k}",
            vertices=12,
            radius=0.06,
            depth=0.38,
            location=((k % 5) * 0.8 - 1.6, (k // 5) * 0.8 - 0.4, rng.uniform(0.4, 1.2)),
            rotation=(tilt[0], tilt[1], rng.uniform(0.0, math.tau)),
        )
        pins.append(field.rigid(pin))
    bake.bake_scene(scene)
    deepest = max(
        -min(v.z for v in field.world_vertices(scene, pin, frame))
        for pin in pins
        for frame in range(1, 2 * fps + 1)
    )
    assert deepest <= 5e-3, f"a pin's vertex {deepest * 1e3:.2f} mm under the ground"
