"""The comparison scenes built in Blender by script (z up, metres, Blender's rigid body defaults
except where a scene says otherwise), shared by the tests and scripts/blender-compare.py.

Each builder empties the current file, makes a Rigid Body World over ``frames`` frames
(frame 1 the initial state) and returns the scene. ``STATIC_SCENES`` should not move: their E
is the largest drift, sink or overlap; the others move by design and their E is the overlap.
"""

import math

import bmesh
import bpy


def _reset(frames):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    with bpy.context.temp_override(scene=scene):
        bpy.ops.rigidbody.world_add()
    world = scene.rigidbody_world
    if world.collection is None:
        world.collection = bpy.data.collections.new("RigidBodyWorld")
    scene.frame_start = 1
    scene.frame_end = frames
    world.point_cache.frame_start = 1
    world.point_cache.frame_end = frames
    return scene


def _box_mesh(name, size):
    mesh = bpy.data.meshes.new(name)
    work = bmesh.new()
    bmesh.ops.create_cube(work, size=1.0)
    for vertex in work.verts:
        vertex.co.x *= size[0]
        vertex.co.y *= size[1]
        vertex.co.z *= size[2]
    work.to_mesh(mesh)
    work.free()
    return mesh


def _sphere_mesh(name, radius):
    mesh = bpy.data.meshes.new(name)
    work = bmesh.new()
    bmesh.ops.create_uvsphere(work, u_segments=16, v_segments=8, radius=radius)
    work.to_mesh(mesh)
    work.free()
    return mesh


def _bowl_mesh(name, radius):
    """The lower half of a UV sphere of ``radius`` centred on the origin: an open bowl."""
    mesh = bpy.data.meshes.new(name)
    work = bmesh.new()
    bmesh.ops.create_uvsphere(work, u_segments=32, v_segments=16, radius=radius)
    bmesh.ops.delete(work, geom=[v for v in work.verts if v.co.z > 1e-4], context="VERTS")
    work.to_mesh(mesh)
    work.free()
    return mesh


def _add(scene, name, mesh, location, kind="ACTIVE", shape="BOX", rotation=(0.0, 0.0, 0.0), **settings):
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = rotation
    with bpy.context.temp_override(object=obj, active_object=obj, selected_objects=[obj], scene=scene):
        bpy.ops.rigidbody.object_add(type=kind)
    obj.rigid_body.collision_shape = shape
    for key, value in settings.items():
        setattr(obj.rigid_body, key, value)
    return obj


def _ground(scene, half=25.0):
    _add(scene, "ground", _box_mesh("ground", (2 * half, 2 * half, 1.0)), (0.0, 0.0, -0.5), kind="PASSIVE")


def stack30(frames=250):
    scene = _reset(frames)
    _ground(scene)
    cube = _box_mesh("cube", (1.0, 1.0, 1.0))
    for i in range(30):
        _add(scene, f"cube{i:02d}", cube, (0.0, 0.0, 0.5 + i))
    return scene


def pyramid20(frames=250):
    scene = _reset(frames)
    _ground(scene)
    cube = _box_mesh("cube", (1.0, 1.0, 1.0))
    for row in range(20):
        count = 20 - row
        for i in range(count):
            _add(scene, f"cube{row:02d}_{i:02d}", cube, (i - (count - 1) / 2, 0.0, 0.5 + row))
    return scene


def heavy_on_light(frames=250):
    """Five 1 kg cubes under a 100 kg one: a 100:1 mass ratio."""
    scene = _reset(frames)
    _ground(scene)
    cube = _box_mesh("cube", (1.0, 1.0, 1.0))
    for i in range(5):
        _add(scene, f"light{i}", cube, (0.0, 0.0, 0.5 + i), mass=1.0)
    _add(scene, "heavy", cube, (0.0, 0.0, 5.5), mass=100.0)
    return scene


def dominoes(frames=250):
    """A row of 20 dominoes 0.2 × 1 × 2 m, 1 m apart; the first one tipped by 20° towards the
    others."""
    scene = _reset(frames)
    _ground(scene)
    domino = _box_mesh("domino", (0.2, 1.0, 2.0))
    tilt = math.radians(20.0)
    for i in range(20):
        angle = tilt if i == 0 else 0.0
        height = 1.0 * math.cos(angle) + 0.1 * math.sin(angle)
        _add(scene, f"domino{i:02d}", domino, (float(i), 0.0, height + 1e-3), rotation=(0.0, angle, 0.0))
    return scene


BOWL_RADIUS = 3.0
BOWL_CENTRE_Z = 3.0


def bowl(frames=250):
    """48 balls of radius 0.25 m poured from a 4 × 4 × 3 grid into a mesh bowl (the lower half
    of a sphere of radius 3 m, centre 3 m up, a passive Mesh shape) standing on the ground."""
    scene = _reset(frames)
    _ground(scene)
    _add(scene, "bowl", _bowl_mesh("bowl", BOWL_RADIUS), (0.0, 0.0, BOWL_CENTRE_Z), kind="PASSIVE", shape="MESH")
    ball = _sphere_mesh("ball", 0.25)
    for layer in range(3):
        for i in range(4):
            for j in range(4):
                location = (0.6 * (i - 1.5), 0.6 * (j - 1.5), BOWL_CENTRE_Z + 0.5 + 0.6 * layer)
                _add(scene, f"ball{layer}_{i}_{j}", ball, location, shape="SPHERE")
    return scene


def paddle(frames=250):
    """An "Animated" paddle (0.2 × 6 × 1 m) keyed to sweep 12 m along x over the range through
    a 2 × 5 block of 0.5 m boxes."""
    scene = _reset(frames)
    _ground(scene)
    box = _box_mesh("box", (0.5, 0.5, 0.5))
    for i in range(2):
        for j in range(5):
            _add(scene, f"box{i}_{j}", box, (1.0 + 0.8 * i, 1.2 * (j - 2), 0.25))
    blade = _add(scene, "paddle", _box_mesh("paddle", (0.2, 6.0, 1.0)), (-2.0, 0.0, 0.55), kinematic=True)
    blade.keyframe_insert("location", frame=1)
    blade.location = (10.0, 0.0, 0.55)
    blade.keyframe_insert("location", frame=frames)
    return scene


SCENES = {
    "stack30": stack30,
    "pyramid20": pyramid20,
    "heavy_on_light": heavy_on_light,
    "dominoes": dominoes,
    "bowl": bowl,
    "paddle": paddle,
}

STATIC_SCENES = ("stack30", "pyramid20", "heavy_on_light")
