"""Read a Blender scene's Rigid Body World as an impulse scene (a dict of the scene format,
docs/scene-format.md), without any UI.

What maps to what (docs/blender.md has the animator's version):

- the Rigid Body World's collection (every object in it and its child collections with rigid
  body settings), its gravity (the scene's, times the world's effector weight for gravity; zero
  when the scene's gravity is off), its frame range (the point cache's start and end frame) and
  the time step dt = time_scale / fps;
- the scene as it is at the start frame is the initial state: the scene is set to the start
  frame and, when it was there already, objects whose transform the animator does not animate
  keep their unkeyed edits (a baked object moved in the viewport starts where it was put); a
  baked object showing its bake's start unchanged starts at the pose the animator set before
  the bake (:data:`keyframes.AUTHORED`: a take's bake starts from the take's varied start);
- an object is "animated" at a frame when "Animated" (``kinematic``) is ticked, or when it is
  Active with "Dynamic" (``enabled``) unticked (Blender then moves it with its own transform, as
  an animated one); both flags are read at every frame when they are keyed. An Active object is
  ``dynamic`` while not animated and ``kinematic`` (following its world pose at every frame)
  while animated; when the flags switch during the range the body switches with them
  (:class:`BodyInfo` ``animated``; the bake swaps it, :mod:`bake`). A Passive object is
  ``static``, or ``kinematic`` when animated at some frame. An object animated at every frame
  whose pose never changes is ``static``;
- shapes: :mod:`shapes` (origin-centred primitives, hulls, meshes, thin shapes, mirrored
  objects, the mesh Source);
- a simulated object with a parent is simulated in world space; its keyframes are written in
  its parent's space (:class:`BodyInfo` ``parent_space``);
- mass (kg), friction, bounciness (restitution); with ``materials="blender"`` (the default)
  a contact's friction and bounciness are the products μa·μb and ea·eb, as Bullet's
  (``btManifoldResult``), through the scene's ``solver.friction_combine`` and
  ``solver.restitution_combine`` ("multiply"); with ``"impulse"`` impulse's own √(μa·μb) and
  max(ea, eb); Blender's damping d (the fraction of
  velocity lost per second) as impulse's rate −ln(1 − d) (1/s), the same decay per second;
- collision collections: the body's ``groups`` and ``mask`` are both the bit set of its
  collections, so two bodies collide when they share one, as in Blender;
- rigid body constraints: the scene's ``joints`` (:mod:`constraints`), read at the first frame;
  settings impulse does not follow are ``SceneInfo.warnings``.

Problems (a shape without geometry, a Compound Parent without children, a zero scale) are collected for
every object and raised together as :class:`UnsupportedScene`, each message naming the object;
approximations (a flat shape baked thin) are ``SceneInfo.notes``.
"""

import math
from dataclasses import dataclass, field

import bpy
import mathutils

from . import axes, constraints, keyframes, shapes

#: The ways two bodies' friction and bounciness combine: Blender's (Bullet's) or impulse's own.
MATERIAL_RULES = ("blender", "impulse")

#: The rigid body flags an animator keys to switch between animation and simulation.
FLAG_PATHS = ("rigid_body.kinematic", "rigid_body.enabled")


class UnsupportedScene(ValueError):
    """The scene holds things impulse cannot represent; ``problems`` lists one message per
    problem, each starting with the object's name."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__("; ".join(self.problems))


@dataclass
class BodyInfo:
    """One rigid body as read: the Blender object's name, the impulse kind at the start frame
    and the body's entry of the scene's ``bodies`` list.

    ``animated`` is None when the object is animated at every frame or at none; else one bool
    per frame of the range (the first the start frame): the body is kinematic during the step
    that ends at a frame where it is True, dynamic where False. ``poses`` are the object's
    world poses (impulse axes: position [x, y, z], orientation [x, y, z, w]) at every frame,
    for bodies that are animated at some frame. ``keyed``: the bake writes keyframes on the
    object (it is dynamic at some frame). ``scale`` is the object's world scale (signed: a
    mirrored object's is negative), ``basis_scale`` its own Scale, and ``parent_space`` the
    parent's space (the parent's world matrix times the parent inverse) at every frame for a
    keyed object with a parent, else None. ``active``: the object is Active; ``dynamics`` its
    ``mass`` and damping fields, in ``body`` while the body is dynamic; ``shape_label`` the
    collision shape's name in the panel; ``start`` the object's own location and
    rotation channels at the start frame (:func:`keyframes.start_values`).
    """

    object_name: str
    kind: str
    body: dict
    animated: list = None
    poses: list = None
    keyed: bool = False
    scale: tuple = (1.0, 1.0, 1.0)
    basis_scale: tuple = (1.0, 1.0, 1.0)
    parent_space: list = None
    active: bool = False
    dynamics: dict = field(default_factory=dict)
    shape_label: str = ""
    start: dict = None


@dataclass
class SceneInfo:
    """A Rigid Body World as an impulse scene.

    ``scene`` is the scene-format dict (bodies in ``bodies`` order); ``frame_start`` and
    ``frame_end`` the inclusive frame range, whose first frame is the initial state; ``dt`` the
    step (s), one per frame; ``warnings`` one message per constraint setting impulse does not
    follow (:mod:`constraints`), each naming the constraint object; ``notes`` one message per
    approximation (a flat shape baked thin), each naming the object.
    """

    scene: dict
    bodies: list = field(default_factory=list)
    frame_start: int = 1
    frame_end: int = 250
    dt: float = 1.0 / 24.0
    warnings: list = field(default_factory=list)
    notes: list = field(default_factory=list)

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


def _frame_rate(scene):
    return scene.render.fps / scene.render.fps_base


def _gravity(scene):
    world = scene.rigidbody_world
    if not scene.use_gravity:
        return [0.0, 0.0, 0.0]
    weight = world.effector_weights.gravity if world.effector_weights is not None else 1.0
    return axes.vector_to_impulse(mathutils.Vector(scene.gravity) * weight)


def _animated(obj):
    """Whether Blender moves the object with its own transform at the current frame."""
    rigid_body = obj.rigid_body
    return bool(rigid_body.kinematic or (rigid_body.type == "ACTIVE" and not rigid_body.enabled))


def _flags_keyed(obj):
    """Whether the object's "Animated" or "Dynamic" flag is keyed (or driven)."""
    fcurves = keyframes._fcurve_collection(obj, create=False)
    if fcurves is not None and any(fc.data_path in FLAG_PATHS for fc in fcurves):
        return True
    animation = obj.animation_data
    return animation is not None and any(d.data_path in FLAG_PATHS for d in animation.drivers)


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


def _pose(obj):
    """(position, orientation) in impulse axes of the object's world pose, and its world scale
    (signed: Blender's decomposition gives a mirrored matrix a proper rotation and a negative
    scale)."""
    location, rotation, scale = obj.matrix_world.decompose()
    return (axes.vector_to_impulse(location), axes.quaternion_to_impulse(rotation)), tuple(scale)


def _parent_space(obj):
    if obj.parent is None:
        return None
    return obj.parent.matrix_world @ obj.matrix_parent_inverse


def _transforms(objects):
    return {
        o.name: (
            tuple(o.location),
            tuple(o.rotation_quaternion),
            tuple(o.rotation_euler),
            tuple(o.rotation_axis_angle),
            tuple(o.scale),
        )
        for o in objects
    }


def _put_back(objects, saved):
    for o in objects:
        location, quaternion, euler, axis_angle, scale = saved[o.name]
        o.location, o.rotation_quaternion, o.rotation_euler = location, quaternion, euler
        o.rotation_axis_angle, o.scale = axis_angle, scale


def _material(rigid_body):
    friction = max(float(rigid_body.friction), 0.0)
    return {"friction": friction, "restitution": min(max(float(rigid_body.restitution), 0.0), 1.0)}


def read_scene(scene, depsgraph=None, materials="blender", resolution=0):
    """The scene's Rigid Body World as a :class:`SceneInfo`.

    Reads the scene as it is at the world's first frame (see the module's notes) and, when
    objects are animated at some frame or parented, every frame of the range; the current
    frame is put back afterwards, with the objects' unkeyed transforms. Blender's own rigid body
    simulation is held off while reading. ``materials``: one of :data:`MATERIAL_RULES`;
    ``resolution``: a moving Mesh's decomposition resolution (:func:`shapes.build`). Raises
    :class:`UnsupportedScene` listing every problem of every object.
    """
    if materials not in MATERIAL_RULES:
        raise ValueError(f"materials must be one of {MATERIAL_RULES}, got {materials!r}")
    objects = rigid_body_objects(scene)
    world = scene.rigidbody_world
    cache = world.point_cache
    frame_start, frame_end = int(cache.frame_start), int(cache.frame_end)
    fps = _frame_rate(scene)
    dt = world.time_scale / fps
    problems, notes = [], []

    was_enabled = world.enabled
    frame_before = scene.frame_current
    saved = _transforms(objects)
    view_layer = bpy.context.view_layer
    world.enabled = False
    try:
        scene.frame_set(frame_start)
        if frame_before == frame_start:
            # Unkeyed edits at the start frame count, except on what the animator animates.
            _put_back([o for o in objects if not keyframes.animates_transform(o)], saved)
        # A baked object showing its bake's start unchanged starts where the animator set it:
        # a take's bake keys the take's varied start, which is not the scene's.
        for obj in objects:
            authored = keyframes.authored_start(obj)
            if authored is not None:
                for path, values in authored.items():
                    setattr(obj, path, values)
        view_layer.update()
        depsgraph = bpy.context.evaluated_depsgraph_get() if depsgraph is None else depsgraph
        meshes = shapes.Meshes(objects, depsgraph, view_layer)
        bodies, tracked = [], []
        in_world = {o.name for o in objects}
        children = {
            o.name: sorted((c for c in o.children if c.name in in_world), key=lambda c: c.name)
            for o in objects
            if o.rigid_body.collision_shape == "COMPOUND"
        }
        parts = {c.name for group in children.values() for c in group}
        for obj in objects:
            if obj.name in parts:
                continue  # a part of its parent's Compound Parent shape
            rigid_body = obj.rigid_body
            keyed_flags = _flags_keyed(obj)
            animated = _animated(obj)
            if animated:
                kind = "kinematic"
            elif rigid_body.type == "PASSIVE":
                kind = "static"
            else:
                kind = "dynamic"
            pose, scale = _pose(obj)
            if min(abs(s) for s in scale) < 1e-9:
                problems.append(f"{obj.name}: its scale {tuple(round(s, 6) for s in scale)} has a zero: it has no volume")
                continue
            # The shape of the kind the body has while simulated, if it ever is.
            if rigid_body.type == "ACTIVE" and (kind == "dynamic" or keyed_flags):
                shape_kind = "dynamic"
            elif keyed_flags or kind == "kinematic":
                shape_kind = "kinematic"
            else:
                shape_kind = "static"
            if obj.name in children:
                shape, shape_notes, shape_problems = shapes.compound(obj, children[obj.name], meshes)
            else:
                shape, shape_notes, shape_problems = shapes.build(obj, shape_kind, scale, meshes, resolution)
            notes += shape_notes
            problems += shape_problems
            if shape is None:
                continue
            body = {
                "name": obj.name,
                "kind": kind,
                "shape": shape,
                "position": pose[0],
                "orientation": pose[1],
                "material": _material(rigid_body),
                "groups": _groups(rigid_body),
                "mask": _groups(rigid_body),
            }
            info = BodyInfo(obj.name, kind, body, scale=scale, basis_scale=tuple(obj.scale))
            info.start = keyframes.start_values(obj)
            info.active = rigid_body.type == "ACTIVE"
            info.shape_label = shapes.SHAPE_NAMES.get(rigid_body.collision_shape, rigid_body.collision_shape)
            if info.active:
                info.dynamics = {
                    "mass": float(rigid_body.mass),
                    "linear_damping": _damping_rate(rigid_body.linear_damping),
                    "angular_damping": _damping_rate(rigid_body.angular_damping),
                }
            info.keyed = rigid_body.type == "ACTIVE" and (kind == "dynamic" or keyed_flags)
            bodies.append(info)
            if kind == "kinematic" or keyed_flags or (info.keyed and obj.parent is not None):
                tracked.append((obj, info, keyed_flags))
                info.poses = [pose]
                info.animated = [animated]
                if info.keyed and obj.parent is not None:
                    info.parent_space = [_parent_space(obj)]

        masses = {b.object_name: b.dynamics["mass"] for b in bodies if b.kind == "dynamic"}
        joints, warnings = constraints.read_constraints(scene, {b.object_name: b.kind for b in bodies}, masses)

        if tracked and not problems:
            for frame in range(frame_start + 1, frame_end + 1):
                scene.frame_set(frame)
                for obj, info, _ in tracked:
                    info.poses.append(_pose(obj)[0])
                    info.animated.append(_animated(obj))
                    if info.parent_space is not None:
                        info.parent_space.append(_parent_space(obj))
            for _obj, info, _keyed_flags in tracked:
                _settle_kind(info, dt)
        for info in bodies:
            if info.kind == "dynamic":
                info.body.update(info.dynamics)
    finally:
        if scene.frame_current != frame_before:
            scene.frame_set(frame_before)
        if frame_before == frame_start:
            _put_back(objects, saved)
            view_layer.update()
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
    if materials == "blender":
        impulse_scene["solver"] = {"friction_combine": "multiply", "restitution_combine": "multiply"}
    if joints:
        impulse_scene["joints"] = joints
    return SceneInfo(impulse_scene, bodies, frame_start, frame_end, dt, warnings, notes)


def _settle_kind(info, dt):
    """Fix the body's kind from its per-frame flags and poses: the animated frames' poses as
    keyframes of a kinematic start, a switch list for an Active object whose flags change, a
    static body for one animated throughout that never moves."""
    body = info.body
    flags = info.animated
    moves = any(p != info.poses[0] for p in info.poses)
    if all(flags) or not any(flags) or not info.active:
        info.animated = None
    if not info.active:
        # Passive: kinematic while animated, holding its last animated pose between.
        if not any(flags) or not moves:
            info.kind = body["kind"] = "static"
            info.poses = None
            return
        info.kind = body["kind"] = "kinematic"
        held, keys = info.poses[0], []
        for i in range(1, len(flags)):
            held = info.poses[i] if flags[i] else held
            keys.append(held)
        _set_keyframes(body, keys, dt)
        return
    if info.animated is None and all(flags):
        info.keyed = False
        if not moves:
            info.kind = body["kind"] = "static"
            info.poses = None
            return
        _set_keyframes(body, info.poses[1:], dt)
        return
    if info.animated is None:
        return
    # Switching: kinematic from the start while animated (keyframes until the first switch).
    if flags[0] or flags[1]:
        info.kind = body["kind"] = "kinematic"
        run = 1
        while run < len(flags) and flags[run]:
            run += 1
        _set_keyframes(body, info.poses[1:run], dt)
    info.keyed = True


def _set_keyframes(body, poses, dt):
    body.pop("keyframes", None)
    if poses:
        body["keyframes"] = [
            {"t": (i + 1) * dt, "position": p, "orientation": q} for i, (p, q) in enumerate(poses)
        ]
