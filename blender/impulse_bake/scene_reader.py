"""Read a Blender scene's Rigid Body World as an impulse scene (a dict of the scene format,
docs/scene-format.md), without any UI.

What maps to what (docs/blender.md has the animator's version):

- the Rigid Body World's collection (every object in it and its child collections with rigid
  body settings), its gravity (the scene's, times the world's effector weight for gravity; zero
  when the scene's gravity is off), its frame range (the point cache's start and end frame) and
  the time step dt = time_scale / fps;
- an active object is ``dynamic``; with "Animated" it is ``kinematic`` and follows the object's
  own animation (its world pose sampled at every frame becomes the body's keyframes); with
  "Dynamic" (``enabled``) off it is ``static``. A passive object is ``static``, or ``kinematic``
  when "Animated";
- shapes: box, sphere, capsule, cylinder and cone are sized from the object's bounding box times
  its scale as Blender sizes them (sphere radius: half the largest dimension; capsule, cylinder,
  cone: radius half the larger of x and y, height the z dimension, axis the local z), centred on
  the bounding box's centre (a one-part compound when that is not the object's origin); convex
  hull: the mesh's vertices; mesh: a two-sided triangle mesh for a static body, and for a
  dynamic or kinematic one a triangle mesh impulse decomposes into convex parts (with the mass
  properties of its solid when the mesh is closed);
- mass (kg), friction, bounciness (restitution) as given (impulse combines two bodies' values
  as √(μa·μb) and max(ea, eb), Bullet as μa·μb and ea·eb); Blender's damping d (the fraction of
  velocity lost per second) as impulse's rate −ln(1 − d) (1/s), the same decay per second;
- collision collections: the body's ``groups`` and ``mask`` are both the bit set of its
  collections, so two bodies collide when they share one, as in Blender;
- rigid body constraints: the scene's ``joints`` (:mod:`constraints`), read at the first frame;
  settings impulse does not follow are ``SceneInfo.warnings``.

Unsupported things (the compound-parent shape, a parent on a simulated
object, negative scale, a shape without geometry) are collected and raised together as
:class:`UnsupportedScene`, each message naming the object.
"""

import math
from dataclasses import dataclass, field

import bpy
import mathutils

from . import axes, constraints

#: Custom property holding an active object's pose before the first bake, so that a second
#: bake starts where the first one did and replaces it.
REST_PROPERTY = "impulse_rest"

#: Shapes smaller than this along an axis (m) are refused: impulse needs volume.
MIN_EXTENT = 1e-6


class UnsupportedScene(ValueError):
    """The scene holds things impulse cannot represent; ``problems`` lists one message per
    object, each starting with the object's name."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__("; ".join(self.problems))


@dataclass
class BodyInfo:
    """One rigid body as read: the Blender object's name, the impulse kind and the body's
    entry of the scene's ``bodies`` list."""

    object_name: str
    kind: str
    body: dict


@dataclass
class SceneInfo:
    """A Rigid Body World as an impulse scene.

    ``scene`` is the scene-format dict (bodies in ``bodies`` order); ``frame_start`` and
    ``frame_end`` the inclusive frame range, whose first frame is the initial state; ``dt`` the
    step (s), one per frame; ``warnings`` one message per constraint setting impulse does not
    follow (:mod:`constraints`), each naming the constraint object.
    """

    scene: dict
    bodies: list = field(default_factory=list)
    frame_start: int = 1
    frame_end: int = 250
    dt: float = 1.0 / 24.0
    warnings: list = field(default_factory=list)

    @property
    def steps(self):
        """Steps from the first frame to the last."""
        return self.frame_end - self.frame_start


def rigid_body_objects(scene):
    """The objects of the scene's Rigid Body World that have rigid body settings, sorted by
    name (the order of the impulse bodies). Raises :class:`UnsupportedScene` without a world or
    collection."""
    world = scene.rigidbody_world
    if world is None or world.collection is None:
        raise UnsupportedScene([f"{scene.name}: the scene has no Rigid Body World with a collection"])
    objects = {o.name: o for o in world.collection.all_objects if o.rigid_body is not None}
    return [objects[name] for name in sorted(objects)]


def restore_rest_poses(objects):
    """Undo an earlier bake: remove the location and quaternion F-curves a bake wrote and put
    each object back at its pose from before that bake."""
    from .keyframes import remove_baked_fcurves

    for obj in objects:
        rest = obj.get(REST_PROPERTY)
        if rest is None:
            continue
        remove_baked_fcurves(obj)
        obj.rotation_mode = str(rest["rotation_mode"])
        obj.location = tuple(rest["location"])
        obj.rotation_quaternion = tuple(rest["rotation_quaternion"])
        obj.rotation_euler = tuple(rest["rotation_euler"])
        obj.rotation_axis_angle = tuple(rest["rotation_axis_angle"])
        del obj[REST_PROPERTY]


def _frame_rate(scene):
    return scene.render.fps / scene.render.fps_base


def _gravity(scene):
    world = scene.rigidbody_world
    if not scene.use_gravity:
        return [0.0, 0.0, 0.0]
    weight = world.effector_weights.gravity if world.effector_weights is not None else 1.0
    return axes.vector_to_impulse(mathutils.Vector(scene.gravity) * weight)


def _bounds(obj):
    """Local bounding box (min, max) of the object's (evaluated) geometry."""
    corners = [mathutils.Vector(c) for c in obj.bound_box]
    lo = mathutils.Vector(min(c[i] for c in corners) for i in range(3))
    hi = mathutils.Vector(max(c[i] for c in corners) for i in range(3))
    return lo, hi


def _mesh_data(obj, depsgraph, rigid_body):
    """(vertices (V, 3) local, triangles (T, 3)) of the mesh Blender's rigid body would use
    (``mesh_source``: the base mesh, or the evaluated one with modifiers)."""
    if obj.type != "MESH":
        return None
    if rigid_body.mesh_source == "BASE":
        mesh = obj.data
        owner = None
    else:
        owner = obj.evaluated_get(depsgraph)
        mesh = owner.to_mesh()
    try:
        mesh.calc_loop_triangles()
        vertices = [tuple(v.co) for v in mesh.vertices]
        triangles = [tuple(t.vertices) for t in mesh.loop_triangles]
    finally:
        if owner is not None:
            owner.to_mesh_clear()
    return vertices, triangles


def _scaled(point, scale):
    return mathutils.Vector((point[0] * scale[0], point[1] * scale[1], point[2] * scale[2]))


def _primitive(shape_type, dims):
    """An impulse primitive (y axis = Blender's local z) for Blender's ``shape_type`` with the
    scaled bounding-box dimensions ``dims`` (Blender's local x, y, z)."""
    if shape_type == "BOX":
        return {"type": "cuboid", "half_extents": axes.extents_to_impulse(dims / 2)}
    if shape_type == "SPHERE":
        return {"type": "sphere", "radius": max(dims) / 2}
    radius = max(dims[0], dims[1]) / 2
    half_height = dims[2] / 2
    if shape_type == "CAPSULE":
        return {"type": "capsule", "half_height": max(half_height - radius, 0.0), "radius": radius}
    if shape_type == "CYLINDER":
        return {"type": "cylinder", "half_height": half_height, "radius": radius}
    return {"type": "cone", "half_height": half_height, "radius": radius}


def _hull(vertices, scale):
    return {
        "type": "convex_hull",
        "points": [axes.vector_to_impulse(_scaled(v, scale)) for v in vertices],
    }


def _trimesh(vertices, triangles, scale, two_sided=True):
    points = [_scaled(v, scale) for v in vertices]
    kept = []
    for a, b, c in triangles:
        # Impulse refuses triangles without area; Blender keeps them but they touch nothing.
        if (points[b] - points[a]).cross(points[c] - points[a]).length > 1e-12:
            kept.append([a, b, c])
    return {
        "type": "trimesh",
        "vertices": [axes.vector_to_impulse(p) for p in points],
        "indices": kept,
        **({"two_sided": True} if two_sided else {}),
    }


def _shape(obj, kind, scale, depsgraph, problems):
    rigid_body = obj.rigid_body
    shape_type = rigid_body.collision_shape
    name = obj.name
    if shape_type == "COMPOUND":
        problems.append(f"{name}: the Compound Parent collision shape is not supported")
        return None
    if shape_type in ("CONVEX_HULL", "MESH"):
        data = _mesh_data(obj, depsgraph, rigid_body)
        if data is None or len(data[0]) < 4:
            problems.append(f"{name}: a {shape_type.lower()} shape needs a mesh of 4 or more vertices")
            return None
        vertices, triangles = data
        if shape_type == "MESH":
            if not triangles:
                problems.append(f"{name}: the mesh shape has no faces")
                return None
            # A moving body's mesh is decomposed into convex parts; winding matters only to a
            # static one's contacts.
            return _trimesh(vertices, triangles, scale, two_sided=kind == "static")
        return _hull(vertices, scale)
    lo, hi = _bounds(obj)
    dims = _scaled(hi - lo, scale)
    if min(dims) < MIN_EXTENT and not (shape_type == "SPHERE" and max(dims) >= MIN_EXTENT):
        problems.append(
            f"{name}: the {shape_type.lower()} shape is flat (dimensions {tuple(round(d, 6) for d in dims)} m)"
        )
        return None
    shape = _primitive(shape_type, dims)
    centre = _scaled((lo + hi) / 2, scale)
    if centre.length > 1e-9 * max(1.0, max(dims)):
        shape = {"type": "compound", "parts": [{"shape": shape, "position": axes.vector_to_impulse(centre)}]}
    return shape


def _kind(rigid_body):
    if rigid_body.kinematic:
        return "kinematic"
    if rigid_body.type == "PASSIVE" or not rigid_body.enabled:
        return "static"
    return "dynamic"


def _damping_rate(fraction):
    """Blender's (Bullet's) damping, the fraction of velocity lost per second, as impulse's
    rate c (1/s) with the same loss per second: (1 − d) = e^(−c)."""
    return -math.log(1.0 - min(max(fraction, 0.0), 1.0 - 1e-6))


def _groups(rigid_body):
    bits = 0
    for i, on in enumerate(rigid_body.collision_collections):
        if on:
            bits |= 1 << i
    return bits


def _pose(matrix):
    location, rotation, scale = matrix.decompose()
    return location, rotation, scale


def read_scene(scene, depsgraph=None):
    """The scene's Rigid Body World as a :class:`SceneInfo`.

    Sets the scene to the world's first frame (the initial state) and, when objects are
    "Animated", to every frame of the range to sample their poses; the current frame is put
    back afterwards. Blender's own rigid body simulation is held off while reading. Raises
    :class:`UnsupportedScene` listing every object it cannot represent.
    """
    objects = rigid_body_objects(scene)
    world = scene.rigidbody_world
    cache = world.point_cache
    frame_start, frame_end = int(cache.frame_start), int(cache.frame_end)
    fps = _frame_rate(scene)
    dt = world.time_scale / fps
    problems = []

    was_enabled = world.enabled
    frame_before = scene.frame_current
    world.enabled = False
    try:
        scene.frame_set(frame_start)
        depsgraph = bpy.context.evaluated_depsgraph_get() if depsgraph is None else depsgraph
        bodies = []
        for obj in objects:
            rigid_body = obj.rigid_body
            kind = _kind(rigid_body)
            if kind == "dynamic" and obj.parent is not None:
                problems.append(f"{obj.name}: a simulated object with a parent is not supported")
                continue
            location, rotation, scale = _pose(obj.matrix_world)
            if min(scale) <= 0:
                problems.append(f"{obj.name}: negative or zero scale {tuple(scale)} is not supported")
                continue
            shape = _shape(obj, kind, scale, depsgraph, problems)
            if shape is None:
                continue
            body = {
                "name": obj.name,
                "kind": kind,
                "shape": shape,
                "position": axes.vector_to_impulse(location),
                "orientation": axes.quaternion_to_impulse(rotation),
                "material": {
                    "friction": max(float(rigid_body.friction), 0.0),
                    "restitution": min(max(float(rigid_body.restitution), 0.0), 1.0),
                },
                "groups": _groups(rigid_body),
                "mask": _groups(rigid_body),
            }
            if kind == "dynamic":
                body["mass"] = float(rigid_body.mass)
                body["linear_damping"] = _damping_rate(rigid_body.linear_damping)
                body["angular_damping"] = _damping_rate(rigid_body.angular_damping)
            bodies.append(BodyInfo(obj.name, kind, body))

        joints, warnings = constraints.read_constraints(
            scene,
            {b.object_name: b.kind for b in bodies},
            {b.object_name: b.body["mass"] for b in bodies if b.kind == "dynamic"},
        )

        kinematic = [b for b in bodies if b.kind == "kinematic"]
        if kinematic and not problems:
            samples = {b.object_name: [] for b in kinematic}
            for frame in range(frame_start + 1, frame_end + 1):
                scene.frame_set(frame)
                for b in kinematic:
                    location, rotation, _ = _pose(scene.objects[b.object_name].matrix_world)
                    samples[b.object_name].append(
                        {
                            "t": (frame - frame_start) * dt,
                            "position": axes.vector_to_impulse(location),
                            "orientation": axes.quaternion_to_impulse(rotation),
                        }
                    )
            for b in kinematic:
                keys = samples[b.object_name]
                if keys:
                    b.body["keyframes"] = keys
    finally:
        scene.frame_set(frame_before)
        world.enabled = was_enabled
    if problems:
        raise UnsupportedScene(problems)

    impulse_scene = {
        "name": scene.name,
        "gravity": _gravity(scene),
        "dt": dt,
        "steps": frame_end - frame_start,
        "bodies": [b.body for b in bodies],
    }
    if joints:
        impulse_scene["joints"] = joints
    return SceneInfo(impulse_scene, bodies, frame_start, frame_end, dt, warnings)
