"""A UsdPhysics stage as a scene (docs/scene-format.md), with a report of what did not map.

OpenUSD's own parser (``UsdPhysics.LoadUsdPhysicsFromRange``) reads the physics description
with the schema's rules (which colliders belong to which body, scale folded into the shapes'
sizes, joint frames relative to their bodies, physics material bindings, collision group
tables); this module turns its descriptors into a scene and reads what the parser leaves to
the simulator itself: mass properties (``MassAPI`` with its precedence rules), mesh points,
the time step, kinematic animation and impulse's own ``impulse:`` attributes.
"""

from __future__ import annotations

import json
import math
import os
import warnings

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from . import _frames as frames
from ._report import BodyPrim, Report

#: Earth's gravity (m/s²), the magnitude of a scene without a PhysicsScene prim.
EARTH_GRAVITY = 9.81
#: The force or torque limit written for an unlimited drive (the scene needs a finite one).
UNLIMITED_FORCE = 1.0e30
#: A distance joint's upper limit (m) when the stage enables none.
UNLIMITED_DISTANCE = 1.0e6
#: A scene's default density (kg/m³).
DEFAULT_DENSITY = 1000.0

_SHAPE_TYPES = (
    "SphereShape",
    "CubeShape",
    "CapsuleShape",
    "Capsule1Shape",
    "CylinderShape",
    "Cylinder1Shape",
    "ConeShape",
    "MeshShape",
    "PlaneShape",
    "CustomShape",
    "SpherePointsShape",
)
_JOINT_TYPES = (
    "FixedJoint",
    "RevoluteJoint",
    "PrismaticJoint",
    "SphericalJoint",
    "DistanceJoint",
    "D6Joint",
    "CustomJoint",
)
# Authored attributes in these namespaces are physics: each is either mapped (marked so by the
# reader) or reported.
_PHYSICS_NAMESPACES = ("physics:", "physx", "drive:", "limit:", "impulse:")
_DOF_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_DOF_NAMES = {
    "TransX": "linear_x",
    "TransY": "linear_y",
    "TransZ": "linear_z",
    "RotX": "angular_x",
    "RotY": "angular_y",
    "RotZ": "angular_z",
}


def open_stage(source: str | os.PathLike | Usd.Stage) -> Usd.Stage:
    """``source`` opened as a stage (``.usda``, ``.usdc``, ``.usdz``, any layer OpenUSD reads,
    with its references, payloads, sublayers and variants composed), or the stage itself.

    Raises ``FileNotFoundError`` for a missing file and ``ValueError`` for one OpenUSD cannot
    open."""
    if isinstance(source, Usd.Stage):
        return source
    path = os.fspath(source)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path}: no such stage file")
    try:
        stage = Usd.Stage.Open(path)
    except Exception as error:  # pxr raises Tf.ErrorException
        raise ValueError(f"{path}: OpenUSD cannot open it: {error}") from error
    if stage is None:
        raise ValueError(f"{path}: OpenUSD cannot open it")
    return stage


def load_descriptors(stage: Usd.Stage) -> dict[str, list[tuple[str, object]]]:
    """The UsdPhysics parser's descriptors of the whole stage, by object type name
    (``"RigidBody"``, ``"CubeShape"``, ``"RevoluteJoint"``, …): lists of (prim path, desc)."""
    load = getattr(UsdPhysics, "UsdPhysicsLoadStageFromPrimRange", None)
    if load is None:
        load = getattr(UsdPhysics, "LoadUsdPhysicsFromRange", None)
    if load is None:
        raise RuntimeError(
            "this usd-core has no UsdPhysics.LoadUsdPhysicsFromRange, OpenUSD's physics parser "
            "(a newer release has it: pip install -U usd-core)"
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        result = load(stage, [Sdf.Path.absoluteRootPath])
    parsed: dict[str, list[tuple[str, object]]] = {}
    for object_type, (paths, descs) in result.items():
        parsed[str(object_type).rsplit(".", 1)[-1]] = [
            (str(path), desc) for path, desc in zip(paths, descs, strict=False)
        ]
    return parsed


def stage_to_scene(
    source: str | os.PathLike | Usd.Stage, *, steps: int | None = None
) -> tuple[dict, Report]:
    """The scene of a UsdPhysics stage, and the report of what it does not simulate as authored.

    ``source`` is a stage file (``.usda``, ``.usdc``, ``.usdz``) or an open ``Usd.Stage``. The
    scene is a dict of docs/scene-format.md (SI units, y up), ready for
    ``impulse.World.from_scene``; ``steps`` replaces the number of steps (default: the stage's
    time code range at the scene's time step, else 600). Bodies are in the order of the
    report's ``bodies``, which also say which prim each body moves. docs/usd.md gives the
    mapping attribute by attribute.

    Raises ``FileNotFoundError``/``ValueError`` for a file OpenUSD cannot open, and
    ``ValueError`` for a stage without anything to simulate.
    """
    stage = open_stage(source)
    return _Reader(stage).read(steps)


class _Reader:
    def __init__(self, stage: Usd.Stage):
        self.stage = stage
        self.up_axis = str(UsdGeom.GetStageUpAxis(stage))
        self.L = float(UsdGeom.GetStageMetersPerUnit(stage))
        self.M = float(UsdPhysics.GetStageKilogramsPerUnit(stage))
        self.A = frames.up_rotation(self.up_axis)
        self.report = Report(
            up_axis=self.up_axis,
            meters_per_unit=self.L,
            kilograms_per_unit=self.M,
            time_codes_per_second=float(stage.GetTimeCodesPerSecond()),
            start_time_code=float(stage.GetStartTimeCode()),
            end_time_code=float(stage.GetEndTimeCode()) if stage.HasAuthoredTimeCodeRange() else None,
        )
        self.time = (
            Usd.TimeCode(stage.GetStartTimeCode())
            if stage.HasAuthoredTimeCodeRange()
            else Usd.TimeCode.EarliestTime()
        )
        self.xforms = UsdGeom.XformCache(self.time)
        self.handled: set[tuple[str, str]] = set()
        self.bodies: list[dict] = []
        self.body_paths: dict[str, int] = {}
        self.materials: dict[str, dict] = {}
        self.inline_materials: dict[str, dict] = {}
        self.material_names: dict[str, str] = {}
        self.body_groups: list[frozenset[str]] = []
        self.body_colliders: list[set[str]] = []
        self.filtered_pairs: list[tuple[str, str]] = []

    # -- helpers ---------------------------------------------------------------------------

    def mark(self, path: object, *names: str) -> None:
        """Marks attributes of a prim as mapped (the rest of its physics ones get reported)."""
        for name in names:
            self.handled.add((str(path), name))

    def attribute(self, prim: Usd.Prim, name: str, mark: bool = True):
        """An authored attribute's value at the read time, else None."""
        attribute = prim.GetAttribute(name)
        if not attribute or not attribute.HasAuthoredValue():
            return None
        if mark:
            self.mark(prim.GetPath(), name)
        return attribute.Get(self.time)

    def length(self, value) -> float:
        return float(value) * self.L

    def world_vector(self, v) -> list[float]:
        """A world vector of the stage (in stage units) in the scene's frame, in metres."""
        turned = frames.rotate(self.A, v)
        return [float(c) * self.L for c in turned]

    def world_pose(self, prim: Usd.Prim) -> tuple[Gf.Vec3d, Gf.Quatd, Gf.Vec3d]:
        """A prim's world position (stage units), rotation and scale, in the stage's frame.

        A prim with only a translate and an orient op under untransformed parents is read from
        the ops themselves (the bits a scene wrote come back unchanged); any other transform
        through the world matrix."""
        direct = self._direct_pose(prim)
        if direct is not None:
            return direct
        matrix = self.xforms.GetLocalToWorldTransform(prim)
        position, rotation, scale, shear = frames.rigid_from_matrix(matrix)
        if shear:
            self.report.add(
                prim.GetPath(),
                "approximated",
                "its world transform has shear (a non-uniform scale turned against its "
                "rotation): read as rotation and per-axis scale",
            )
        return position, rotation, scale

    def _direct_pose(self, prim: Usd.Prim, time: Usd.TimeCode | None = None):
        """A prim's world position and rotation read from its ops and its ancestors' when
        exactly one of them has a translate (and an orient) and the others nothing but, at or
        below it, a scale: the layout impulse writes, read without going through matrices so
        that a scene's numbers come back to the bit. Else None."""
        time = self.time if time is None else time
        chain = []
        current = prim
        while current and not current.IsPseudoRoot():
            chain.append(current)
            current = current.GetParent()
        placed = None
        for item in chain:
            xformable = UsdGeom.Xformable(item)
            if not xformable:
                if item.GetAttribute("xformOpOrder"):
                    return None
                continue
            resets = xformable.GetResetXformStack()
            ops = xformable.GetOrderedXformOps()
            kinds = [op.GetOpType() for op in ops]
            if any(op.IsInverseOp() for op in ops):
                return None
            if kinds in ([], [UsdGeom.XformOp.TypeScale]):
                if kinds and placed is not None:
                    return None  # a scale above the translate would scale its translation
                if resets:
                    break  # the ancestors' transforms do not apply
                continue
            if placed is not None or kinds not in (
                [UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.TypeOrient],
                [UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.TypeOrient, UsdGeom.XformOp.TypeScale],
                [UsdGeom.XformOp.TypeTranslate],
                [UsdGeom.XformOp.TypeTranslate, UsdGeom.XformOp.TypeScale],
            ):
                return None
            placed = ops
            if resets:
                break
        if placed is None:
            return Gf.Vec3d(0.0), Gf.Quatd(frames.IDENTITY), Gf.Vec3d(1.0, 1.0, 1.0)
        position = Gf.Vec3d(*placed[0].Get(time))
        has_orient = len(placed) > 1 and placed[1].GetOpType() == UsdGeom.XformOp.TypeOrient
        rotation = frames.quat(placed[1].Get(time)) if has_orient else Gf.Quatd(frames.IDENTITY)
        return position, rotation, Gf.Vec3d(1.0, 1.0, 1.0)

    def scene_pose(self, position, rotation: Gf.Quatd) -> tuple[list[float], list[float]]:
        """A stage world pose (stage units) as a scene's position and orientation."""
        return self.world_vector(position), frames.xyzw(self.A * rotation)

    # -- the stage -------------------------------------------------------------------------

    def read(self, steps: int | None) -> tuple[dict, Report]:
        descriptors = load_descriptors(self.stage)
        self.order = {str(prim.GetPath()): i for i, prim in enumerate(self.stage.Traverse())}
        scene: dict = {}
        self.read_physics_scene(descriptors, scene)
        self.read_materials(descriptors)
        self.read_groups(descriptors)
        self.read_bodies(descriptors)
        joints = self.read_joints(descriptors)
        self.apply_filters()
        if not self.bodies:
            raise ValueError(
                f"{self.stage.GetRootLayer().identifier}: no rigid body or collider to simulate "
                "(no prim has UsdPhysics.RigidBodyAPI or CollisionAPI)"
            )
        if self.materials:
            scene["materials"] = self.materials
        scene["bodies"] = self.bodies
        if joints:
            scene["joints"] = joints
        if steps is not None:
            scene["steps"] = int(steps)
        elif "steps" not in scene and self.report.end_time_code is not None:
            frames_span = self.report.end_time_code - self.report.start_time_code
            seconds = frames_span / self.report.time_codes_per_second
            scene["steps"] = max(0, round(seconds / scene["dt"]))
        self.report_unmapped()
        return _single_precision(scene), self.report

    def read_physics_scene(self, descriptors, scene: dict) -> None:
        scenes = descriptors.get("Scene", [])
        tcps = self.report.time_codes_per_second
        if not scenes:
            self.report.add(
                "/",
                "note",
                f"no PhysicsScene prim: gravity {EARTH_GRAVITY} m/s² down the up axis",
            )
            gravity = [0.0, -EARTH_GRAVITY, 0.0]
            prim = None
        else:
            path, desc = scenes[0]
            for other, _ in scenes[1:]:
                self.report.add(
                    other, "dropped", f"a second PhysicsScene: only {path} is simulated"
                )
            prim = self.stage.GetPrimAtPath(path)
            self.mark(path, "physics:gravityDirection", "physics:gravityMagnitude")
            direction = Gf.Vec3d(*desc.gravityDirection)
            magnitude = float(desc.gravityMagnitude)
            gravity = self.world_vector(direction * magnitude)
            gravity = [0.0 if c == 0.0 else c for c in gravity]
        scene["name"] = os.path.splitext(os.path.basename(self.stage.GetRootLayer().identifier))[0]
        scene["gravity"] = gravity
        dt = 1.0 / tcps
        if prim is not None:
            rate = self.attribute(prim, "physxScene:timeStepsPerSecond")
            own_dt = self.attribute(prim, "impulse:dt")
            if rate is not None and float(rate) > 0:
                dt = 1.0 / float(rate)
            elif own_dt is not None:
                dt = float(own_dt)
            for field, name in (("name", "impulse:name"), ("steps", "impulse:steps"), ("seed", "impulse:seed")):
                value = self.attribute(prim, name)
                if value is not None:
                    scene[field] = value if field == "name" else int(value)
            solver = self.attribute(prim, "impulse:solver")
            if solver:
                scene["solver"] = json.loads(solver)
        scene["dt"] = dt

    def read_materials(self, descriptors) -> None:
        used: set[str] = {"default"}
        for path, desc in descriptors.get("RigidBodyMaterial", []):
            prim = self.stage.GetPrimAtPath(path)
            inline = bool(self.attribute(prim, "impulse:inline"))
            name = self.attribute(prim, "impulse:name") or prim.GetName()
            base, number = name, 2
            while name in used and name != "default" and not inline:
                name, number = f"{base}_{number}", number + 1
            used.add(name)
            self.mark(
                path,
                "physics:staticFriction",
                "physics:dynamicFriction",
                "physics:restitution",
                "physics:density",
            )
            static, dynamic = float(desc.staticFriction), float(desc.dynamicFriction)
            if static != dynamic:
                self.report.add(
                    path,
                    "approximated",
                    f"static friction {static:g} and dynamic friction {dynamic:g} differ: impulse "
                    "has one Coulomb coefficient, the static one (whether a body sticks)",
                )
            material: dict = {"friction": max(static, 0.0)}
            restitution = float(desc.restitution)
            if not 0.0 <= restitution <= 1.0:
                self.report.add(
                    path, "approximated", f"restitution {restitution:g} clamped into [0, 1]"
                )
            material["restitution"] = min(max(restitution, 0.0), 1.0)
            density = float(desc.density)
            material["density"] = (
                density * self.M / self.L**3 if density > 0.0 else DEFAULT_DENSITY
            )
            for field, attribute in (
                ("roughness", "impulse:roughness"),
                ("impact_perturbation", "impulse:impactPerturbation"),
            ):
                value = self.attribute(prim, attribute)
                if value is not None:
                    material[field] = float(value)
            if inline:
                self.inline_materials[path] = material
            else:
                self.material_names[path] = name
                self.materials[name] = material

    def read_groups(self, descriptors) -> None:
        """Collision groups: which pairs of groups collide (OpenUSD's group table, with the
        filtered groups, their inversion and merge groups)."""
        self.group_paths = [path for path, _ in descriptors.get("CollisionGroup", [])]
        self.group_table = None
        for path in self.group_paths:
            self.mark(path, "physics:mergeGroup", "physics:invertFilteredGroups")
        if self.group_paths:
            self.group_table = UsdPhysics.CollisionGroup.ComputeCollisionGroupTable(self.stage)

    # -- bodies ----------------------------------------------------------------------------

    def read_bodies(self, descriptors) -> None:
        shapes: dict[str, list[tuple[str, str, object]]] = {}
        statics: list[tuple[str, str, object]] = []
        for type_name in _SHAPE_TYPES:
            for path, desc in descriptors.get(type_name, []):
                self.mark(path, "physics:collisionEnabled", "physics:approximation")
                if not desc.collisionEnabled:
                    self.report.add(path, "dropped", "a collider with collisionEnabled = false")
                    continue
                body = str(desc.rigidBody)
                if body:
                    shapes.setdefault(body, []).append((path, type_name, desc))
                else:
                    statics.append((path, type_name, desc))
        # The parser leaves the colliders of a disabled rigid body without a body; they are
        # that static body's, at their poses relative to it.
        disabled = {path: desc for path, desc in descriptors.get("RigidBody", []) if not desc.rigidBodyEnabled}
        if disabled:
            kept = []
            for path, type_name, desc in statics:
                owner = Sdf.Path(path)
                while owner != Sdf.Path.absoluteRootPath and str(owner) not in disabled:
                    owner = owner.GetParentPath()
                if str(owner) in disabled:
                    relative = _RelativeCollider(desc, self.world_pose(self.stage.GetPrimAtPath(owner)))
                    shapes.setdefault(str(owner), []).append((path, type_name, relative))
                else:
                    kept.append((path, type_name, desc))
            statics = kept
        for colliders in shapes.values():
            colliders.sort(key=lambda item: self.order.get(item[0], len(self.order)))
        # Bodies in the stage's order (a scene written as a stage comes back in its order).
        items = [(path, "body", desc) for path, desc in descriptors.get("RigidBody", [])]
        items += [(path, type_name, desc) for path, type_name, desc in statics]
        items.sort(key=lambda item: self.order.get(item[0], len(self.order)))
        for path, what, desc in items:
            if what == "body":
                self.read_rigid_body(path, desc, shapes.pop(path, []))
            else:
                self.read_static_collider(path, what, desc)
        for body, colliders in shapes.items():
            for path, _, _ in colliders:
                self.report.add(path, "dropped", f"its rigid body {body} was not parsed")

    def read_rigid_body(self, path: str, desc, colliders) -> None:
        prim = self.stage.GetPrimAtPath(path)
        self.mark(
            path,
            "physics:rigidBodyEnabled",
            "physics:kinematicEnabled",
            "physics:velocity",
            "physics:angularVelocity",
            "physics:startsAsleep",
        )
        if not colliders:
            self.report.add(
                path, "dropped", "a rigid body without an enabled collider has no shape to simulate"
            )
            return
        position, rotation, _ = self.world_pose(prim)
        if not desc.rigidBodyEnabled:
            kind = "static"
        elif desc.kinematicBody:
            kind = "kinematic"
        else:
            kind = self.attribute(prim, "impulse:kind") or "dynamic"
        if desc.startsAsleep:
            self.report.add(
                path, "approximated", "startsAsleep: impulse starts every body awake"
            )
        body, offset_position, offset_rotation = self.body_shape(path, colliders, kind)
        if body is None:
            return
        world_position = position + frames.rotate(rotation, offset_position)
        world_rotation = rotation * offset_rotation
        body["kind"] = kind
        body["position"], body["orientation"] = self.scene_pose(world_position, world_rotation)
        if kind in ("dynamic", "kinematic", "particle"):
            self.read_velocities(prim, desc, body, world_position, position, rotation)
        if kind == "kinematic":
            self.read_keyframes(prim, body, offset_position, offset_rotation)
        if kind != "static":
            self.read_mass(prim, body, colliders)
        self.read_own_body_attributes(prim, body)
        self.add_body(path, body, offset_position, offset_rotation, moves=kind != "static", colliders=colliders)

    def read_static_collider(self, path: str, type_name: str, desc) -> None:
        # A collider without a rigid body is static, at its own world pose: the parser's
        # local pose is then its world pose, with the scale already in its sizes.
        body, offset_position, offset_rotation = self.body_shape(
            path, [(path, type_name, desc)], "static", standalone=True
        )
        if body is None:
            return
        position = Gf.Vec3d(*desc.localPos)
        rotation = frames.quat(desc.localRot)
        prim = self.stage.GetPrimAtPath(path)
        direct = self._direct_pose(prim)
        if direct is not None:
            position, rotation = direct[0], direct[1]
        world_position = position + frames.rotate(rotation, offset_position)
        world_rotation = rotation * offset_rotation
        body["kind"] = "static"
        body["position"], body["orientation"] = self.scene_pose(world_position, world_rotation)
        self.read_own_body_attributes(prim, body)
        self.add_body(path, body, offset_position, offset_rotation, moves=False, colliders=[(path, type_name, desc)])

    def add_body(self, path, body, offset_position, offset_rotation, *, moves, colliders) -> None:
        index = len(self.bodies)
        prim = self.stage.GetPrimAtPath(path)
        name = self.attribute(prim, "impulse:name")
        if name is None:
            body["name"] = path
        elif name:
            body["name"] = name
        if _single_precision(body.get("orientation")) == [0.0, 0.0, 0.0, 1.0]:
            del body["orientation"]
        # The order impulse writes a body's fields in.
        first = ("name", "kind", "shape", "position", "orientation")
        ordered = {key: body[key] for key in first if key in body}
        ordered.update((key, value) for key, value in body.items() if key not in first)
        self.bodies.append(ordered)
        self.body_paths[path] = index
        offset = frames.xyzw(offset_rotation)
        self.report.bodies.append(
            BodyPrim(
                index=index,
                path=path,
                offset_position=tuple(float(c) * self.L for c in offset_position),
                offset_orientation=tuple(offset),
                moves=moves,
            )
        )
        groups: set[str] = set()
        for _, _, desc in colliders:
            groups.update(str(group) for group in desc.collisionGroups)
        self.body_groups.append(frozenset(groups))
        self.body_colliders.append({collider_path for collider_path, _, _ in colliders} | {path})

    def read_velocities(self, prim, desc, body, world_position, prim_position, prim_rotation) -> None:
        linear = Gf.Vec3d(*desc.linearVelocity)
        angular = Gf.Vec3d(*desc.angularVelocity) * (math.pi / 180.0)
        if self.attribute(prim, "physxRigidBody:localSpaceVelocities"):
            linear = frames.rotate(prim_rotation, linear)
            angular = frames.rotate(prim_rotation, angular)
        # The stage's velocity is the prim origin's; a scene's the body origin's, which the
        # offset moved: v_body = v_prim + ω × r.
        lever = world_position - prim_position
        linear = linear + Gf.Cross(angular, lever)
        if linear != Gf.Vec3d(0.0):
            body["linear_velocity"] = self.world_vector(linear)
        if angular != Gf.Vec3d(0.0):
            body["angular_velocity"] = [float(c) for c in frames.rotate(self.A, angular)]

    def read_keyframes(self, prim, body, offset_position, offset_rotation) -> None:
        """A kinematic body animated by time samples: a keyframe at each time sample of its
        transform (of its ops and its ancestors'), which USD interpolates as a scene's
        keyframes are (linearly in position, by slerp in orientation)."""
        chain = []
        current = prim
        while current and not current.IsPseudoRoot():
            xformable = UsdGeom.Xformable(current)
            if xformable:
                chain.append(xformable)
            current = current.GetParent()
        if not any(x.TransformMightBeTimeVarying() for x in chain):
            return
        start = self.report.start_time_code
        codes: set[float] = set()
        for xformable in chain:
            codes.update(float(c) for c in xformable.GetTimeSamples())
        codes = sorted(c for c in codes if c > start)
        if not codes:
            return
        tcps = self.report.time_codes_per_second
        keyframes = []
        for code in codes:
            pose = self._direct_pose(prim, Usd.TimeCode(code))
            if pose is None:
                cache = UsdGeom.XformCache(Usd.TimeCode(code))
                pose = frames.rigid_from_matrix(cache.GetLocalToWorldTransform(prim))
            position, rotation = pose[0], pose[1]
            world_position = position + frames.rotate(rotation, offset_position)
            world_rotation = rotation * offset_rotation
            scene_position, scene_rotation = self.scene_pose(world_position, world_rotation)
            keyframe = {"t": (code - start) / tcps, "position": scene_position}
            if scene_rotation != [0.0, 0.0, 0.0, 1.0]:
                keyframe["orientation"] = scene_rotation
            keyframes.append(keyframe)
        body.pop("linear_velocity", None)
        body.pop("angular_velocity", None)
        body["keyframes"] = keyframes

    def read_own_body_attributes(self, prim, body) -> None:
        """impulse's own attributes (what UsdPhysics has no attribute for)."""
        for field, name, convert in (
            ("linear_damping", "impulse:linearDamping", float),
            ("angular_damping", "impulse:angularDamping", float),
            ("lock_rotation", "impulse:lockRotation", bool),
            ("groups", "impulse:groups", int),
            ("mask", "impulse:mask", int),
        ):
            value = self.attribute(prim, name)
            if value is not None:
                body[field] = convert(value)
        for field, name in (("locked_axes", "impulse:lockedAxes"), ("roughness_draws", "impulse:roughnessDraws")):
            value = self.attribute(prim, name)
            if value:
                body[field] = json.loads(value)
        for name, label in (
            ("physxRigidBody:linearDamping", "linear_damping"),
            ("physxRigidBody:angularDamping", "angular_damping"),
        ):
            value = self.attribute(prim, name)
            if value is not None and label not in body:
                # PhysX's damping is per second, v ← v·(1 − h·c) per step; impulse's
                # v ← v/(1 + h·c) per substep: equal to first order in h·c.
                body[label] = max(float(value), 0.0)

    # -- shapes ----------------------------------------------------------------------------

    def body_shape(self, body_path, colliders, kind, standalone=False):
        """A body's shape from its colliders, and the offset of its frame from its prim's.

        One collider: the body's frame is the collider's (turned so that its axis is y), so
        the shape is plain. Several: a compound of the colliders at their local poses."""
        parts = []
        for path, type_name, desc in colliders:
            part = self.collider_shape(path, type_name, desc, kind)
            if part is None:
                continue
            shape, local_position, local_rotation = part
            if standalone:
                # The parser's local pose of a lone collider is its world pose: keep only the
                # part the reader added (the axis turn, a bounding shape's centre).
                inverse = frames.quat(desc.localRot).GetInverse()
                local_position = frames.rotate(inverse, local_position - Gf.Vec3d(*desc.localPos))
                local_rotation = inverse * local_rotation
            parts.append((path, shape, local_position, local_rotation))
        if not parts:
            self.report.add(body_path, "dropped", "none of its colliders can be simulated")
            return None, None, None
        material = self.body_material(body_path, colliders)
        if len(parts) == 1:
            _, shape, local_position, local_rotation = parts[0]
            body = {"shape": shape}
            if material is not None:
                body["material"] = material
            return body, Gf.Vec3d(local_position), Gf.Quatd(local_rotation)
        convex = ("sphere", "cuboid", "capsule", "cylinder", "cone", "convex_hull")
        compound = []
        for path, shape, local_position, local_rotation in parts:
            if shape["type"] == "half_space" or shape["type"] == "heightfield":
                self.report.add(path, "dropped", f"a {shape['type']} cannot be part of a body with other colliders")
                continue
            if shape["type"] == "trimesh":
                pieces = self.decompose(path, shape)
                if pieces is None:
                    continue
                for piece in pieces:
                    compound.append(self.part(piece, local_position, local_rotation))
                continue
            if shape["type"] == "compound":
                for inner in shape["parts"]:
                    inner_rotation = frames.from_xyzw(inner.get("orientation", [0, 0, 0, 1]))
                    inner_position = Gf.Vec3d(*inner.get("position", [0, 0, 0]))
                    compound.append(
                        self.part(
                            inner["shape"],
                            local_position + frames.rotate(local_rotation, inner_position),
                            local_rotation * inner_rotation,
                        )
                    )
                continue
            if shape["type"] not in convex and "border_radius" not in shape:
                self.report.add(path, "dropped", f"a {shape['type']} cannot be a compound's part")
                continue
            compound.append(self.part(shape, local_position, local_rotation))
        if not compound:
            return None, None, None
        body = {"shape": {"type": "compound", "parts": compound}}
        own = self.compound_shape([path for path, _, _, _ in parts], compound)
        if own is not None:
            body["shape"] = own
        if material is not None:
            body["material"] = material
        return body, Gf.Vec3d(0.0), Gf.Quatd(frames.IDENTITY)

    def compound_shape(self, paths, derived):
        """A compound impulse wrote (``impulse:shape`` on the colliders' common parent), used
        while its parts sit where the stage's colliders do."""
        common = Sdf.Path(paths[0])
        for path in paths[1:]:
            common = common.GetCommonPrefix(Sdf.Path(path))
        prim = self.stage.GetPrimAtPath(common)
        own = self.attribute(prim, "impulse:shape") if prim else None
        if not own:
            return None
        own = json.loads(own)
        parts = own.get("parts", [])
        if own.get("type") != "compound" or len(parts) != len(derived):
            return None
        for mine, theirs in zip(parts, derived, strict=True):
            if not _close(mine.get("position", [0.0, 0.0, 0.0]), theirs["position"]):
                return None
        return own

    def part(self, shape, local_position, local_rotation) -> dict:
        part = {"shape": shape, "position": [float(c) * self.L for c in local_position]}
        if not frames.is_identity(local_rotation):
            part["orientation"] = frames.xyzw(local_rotation)
        return part

    def decompose(self, path, shape):
        """A moving mesh among several colliders: its convex parts (impulse's V-HACD), as
        hulls in the mesh's frame (stage units, like the other parts' positions)."""
        try:
            import impulse
        except ImportError:
            self.report.add(path, "dropped", "a mesh among several colliders needs impulse's module to decompose it")
            return None
        built = impulse.Shape.trimesh(
            shape["vertices"], shape["indices"], decomposition=shape.get("decomposition")
        )
        pieces = []
        for vertices, _ in built.convex_parts():
            pieces.append({"type": "convex_hull", "points": [[float(c) for c in v] for v in vertices]})
        self.report.add(
            path,
            "note",
            f"a moving mesh among several colliders: its {len(pieces)} convex parts are parts of the body's compound",
        )
        return pieces

    def collider_shape(self, path, type_name, desc, kind):
        """One collider's shape (metres, its own frame turned so its axis is y) and its pose
        in the body's frame (stage units)."""
        prim = self.stage.GetPrimAtPath(path)
        local_position = Gf.Vec3d(*desc.localPos)
        local_rotation = frames.quat(desc.localRot)
        L = self.L
        own = self.attribute(prim, "impulse:shape")
        own = json.loads(own) if own else None
        if own is not None and (own.get("type") == "heightfield" or "file" in own):
            # impulse's own shapes that a USD mesh only draws.
            self.mark(path, "points", "faceVertexCounts", "faceVertexIndices", "physics:approximation")
            return own, local_position, local_rotation
        shape_attributes = {
            "SphereShape": ["radius"],
            "CubeShape": ["size"],
            "CapsuleShape": ["radius", "height", "axis"],
            "Capsule1Shape": ["radiusTop", "radiusBottom", "height", "axis"],
            "CylinderShape": ["radius", "height", "axis"],
            "Cylinder1Shape": ["radiusTop", "radiusBottom", "height", "axis"],
            "ConeShape": ["radius", "height", "axis"],
            "PlaneShape": ["axis"],
        }
        if type_name == "SphereShape":
            shape = {"type": "sphere", "radius": float(desc.radius) * L}
            self.scale_note(path, desc, "a sphere")
        elif type_name == "CubeShape":
            half = [float(c) * L for c in desc.halfExtents]
            shape = {"type": "cuboid", "half_extents": half}
        elif type_name in ("CapsuleShape", "CylinderShape", "ConeShape", "Capsule1Shape", "Cylinder1Shape"):
            radius = float(desc.radius) if hasattr(desc, "radius") else None
            if radius is None:
                top, bottom = float(desc.topRadius), float(desc.bottomRadius)
                radius = max(top, bottom)
                if top != bottom:
                    self.report.add(
                        path,
                        "approximated",
                        f"radii {top:g} (top) and {bottom:g} (bottom) differ: simulated with the larger",
                    )
            kind_name = {"Capsule": "capsule", "Cylinder": "cylinder", "Cone": "cone"}[
                type_name.replace("Shape", "").rstrip("1")
            ]
            shape = {"type": kind_name, "half_height": float(desc.halfHeight) * L, "radius": radius * L}
            local_rotation = local_rotation * frames.axis_rotation(str(desc.axis).rsplit(".", 1)[-1])
            self.scale_note(path, desc, f"a {kind_name}")
        elif type_name == "PlaneShape":
            if kind != "static":
                self.report.add(path, "dropped", "a plane on a moving body (impulse's half-spaces are static)")
                return None
            axis = str(desc.axis).rsplit(".", 1)[-1]
            shape = {"type": "half_space", "normal": [float(c) for c in frames.axis_vector(axis)]}
            self.mark(path, "width", "length")
        elif type_name == "MeshShape":
            shape = self.mesh_shape(prim, desc, kind)
            if shape is None:
                return None
            if shape["type"] in ("cuboid", "sphere") and "center" in shape:
                center = shape.pop("center")
                local_position = local_position + frames.rotate(local_rotation, Gf.Vec3d(*center) / L)
        else:
            self.report.add(path, "dropped", f"a {type_name} collider has no impulse shape")
            return None
        for name in shape_attributes.get(type_name, []):
            self.mark(path, name)
        if own is not None:
            shape = self.own_shape(path, own, shape)
        return shape, local_position, local_rotation

    def own_shape(self, path, own: dict, derived: dict) -> dict:
        """A shape impulse wrote (``impulse:shape``) where the schema's is its approximation
        (a rounded or thin shape): used while its inner shape is still the schema's, else
        the schema's shape wins (an artist resized the prim)."""
        inner = {k: v for k, v in own.items() if k not in ("border_radius", "thickness")}
        if _close(inner, derived):
            return own
        self.report.add(
            path, "note", "its impulse:shape disagrees with its schema shape: the schema's is used"
        )
        return derived

    def scale_note(self, path, desc, what) -> None:
        scale = [abs(float(c)) for c in desc.localScale]
        if max(scale) - min(scale) > 1e-6 * max(scale):
            self.report.add(
                path,
                "approximated",
                f"{what} under the non-uniform scale {tuple(round(c, 6) for c in scale)}: "
                "sized by the schema's rule (the larger scale for round sections)",
            )

    def mesh_shape(self, prim, desc, kind):
        path = str(prim.GetPath())
        mesh = UsdGeom.Mesh(prim)
        self.mark(path, "points", "faceVertexCounts", "faceVertexIndices", "orientation", "doubleSided")
        points = mesh.GetPointsAttr().Get(self.time)
        counts = mesh.GetFaceVertexCountsAttr().Get(self.time)
        indices = mesh.GetFaceVertexIndicesAttr().Get(self.time)
        if points is None or len(points) == 0:
            self.report.add(path, "dropped", "a mesh collider without points")
            return None
        scale = np.array([float(c) for c in desc.meshScale])
        vertices = np.array(points, dtype=np.float64) * scale * self.L
        approximation = str(desc.approximation) or "none"
        if approximation in ("convexHull", "convexDecomposition", "none", "meshSimplification", "sdf") and (
            counts is None or indices is None or len(counts) == 0
        ) and approximation != "convexHull":
            self.report.add(path, "dropped", "a mesh collider without faces")
            return None
        if approximation == "boundingCube":
            low, high = vertices.min(axis=0), vertices.max(axis=0)
            return {
                "type": "cuboid",
                "half_extents": [float(c) for c in (high - low) / 2],
                "center": [float(c) for c in (high + low) / 2],
            }
        if approximation == "boundingSphere":
            low, high = vertices.min(axis=0), vertices.max(axis=0)
            center = (high + low) / 2
            radius = float(np.max(np.linalg.norm(vertices - center, axis=1)))
            self.report.add(path, "note", "boundingSphere: the sphere about the points' bounding box centre")
            return {"type": "sphere", "radius": radius, "center": [float(c) for c in center]}
        if approximation == "convexHull":
            return {"type": "convex_hull", "points": [[float(c) for c in v] for v in vertices]}
        triangles = self.triangles(path, mesh, counts, indices, len(points))
        if triangles is None:
            return None
        triangles = self.drop_degenerate(path, vertices, triangles)
        if triangles is None:
            return None
        shape = {
            "type": "trimesh",
            "vertices": [[float(c) for c in v] for v in vertices],
            "indices": [[int(i) for i in t] for t in triangles],
        }
        if approximation not in ("none", "convexDecomposition"):
            self.report.add(
                path,
                "approximated",
                f"physics:approximation {approximation!r}: simulated as the mesh itself"
                + ("" if kind == "static" else " (decomposed into convex parts)"),
            )
        if kind == "static":
            if approximation == "convexDecomposition":
                self.report.add(path, "note", "convexDecomposition on a static body: its mesh is used as it is")
            if desc.doubleSided:
                shape["two_sided"] = True
            return shape
        if approximation == "none":
            self.report.add(
                path,
                "approximated",
                "a moving triangle mesh (approximation none) is simulated as its convex decomposition",
            )
        decomposition = {}
        hulls = self.attribute(prim, "physxConvexDecompositionCollision:maxConvexHulls")
        if hulls is not None and int(hulls) >= 1:
            decomposition["max_parts"] = int(hulls)
        for name in ("voxelResolution", "errorPercentage", "hullVertexLimit", "minThickness", "shrinkWrap"):
            if self.attribute(prim, f"physxConvexDecompositionCollision:{name}", mark=False) is not None:
                self.report.add(
                    path,
                    "approximated",
                    f"physxConvexDecompositionCollision:{name}: impulse's V-HACD takes its own "
                    "parameters (resolution, concavity, max_parts)",
                )
                self.mark(path, f"physxConvexDecompositionCollision:{name}")
        own = self.attribute(prim, "impulse:decomposition")
        if own:
            decomposition.update(json.loads(own))
        if decomposition:
            shape["decomposition"] = decomposition
        return shape

    def triangles(self, path, mesh, counts, indices, vertex_count):
        counts = np.asarray(counts, dtype=np.int64)
        indices = np.asarray(indices, dtype=np.int64)
        if counts.sum() != len(indices) or (indices < 0).any() or (indices >= vertex_count).any():
            self.report.add(path, "dropped", "its faceVertexCounts and faceVertexIndices disagree with its points")
            return None
        triangles = []
        start = 0
        skipped = 0
        for count in counts:
            face = indices[start : start + count]
            start += count
            if count < 3:
                skipped += 1
                continue
            for k in range(1, count - 1):
                triangles.append((face[0], face[k], face[k + 1]))
        if skipped:
            self.report.add(path, "dropped", f"{skipped} faces of fewer than 3 vertices")
        if not triangles:
            self.report.add(path, "dropped", "a mesh collider without triangles")
            return None
        triangles = np.array(triangles, dtype=np.int64)
        if mesh.GetOrientationAttr().Get(self.time) == UsdGeom.Tokens.leftHanded:
            triangles = triangles[:, ::-1]
        return triangles

    def drop_degenerate(self, path, vertices, triangles):
        a, b, c = (vertices[triangles[:, k]] for k in range(3))
        area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
        extent = float(np.max(vertices.max(axis=0) - vertices.min(axis=0))) or 1.0
        keep = area2 > 1e-10 * extent**2
        if not keep.all():
            self.report.add(path, "dropped", f"{int((~keep).sum())} triangles without area")
        if not keep.any():
            return None
        return triangles[keep]

    # -- materials and mass ----------------------------------------------------------------

    def collider_material(self, desc):
        """A collider's material: a name of the scene's materials, an inline material (a dict),
        or None for the default."""
        materials = [str(m) for m in desc.materials]
        if not materials:
            return None
        if materials[0] in self.inline_materials:
            return dict(self.inline_materials[materials[0]])
        name = self.material_names.get(materials[0])
        return None if name == "default" else name

    def body_material(self, body_path, colliders):
        found = [self.collider_material(desc) for _, _, desc in colliders]
        if any(item != found[0] for item in found[1:]):
            self.report.add(
                body_path,
                "approximated",
                "its colliders have different physics materials: the body takes the first's",
            )
        return found[0] if found else None

    def read_mass(self, prim, body, colliders) -> None:
        """MassAPI with the schema's precedence: the body's mass wins; else each collider's
        mass, or its density (the collider's MassAPI density, else the body's, else its
        material's, else 1000 kg/m³) times its volume."""
        path = str(prim.GetPath())
        body_mass = self.positive(prim, "physics:mass")
        body_density = self.positive(prim, "physics:density")
        self.report_mass_frame(prim)
        if body_mass is not None:
            body["mass"] = body_mass * self.M
            return
        densities = []
        masses = []
        for collider_path, _, desc in colliders:
            collider = self.stage.GetPrimAtPath(collider_path)
            if collider_path != path:
                self.report_mass_frame(collider)
            mass = self.positive(collider, "physics:mass") if collider_path != path else None
            density = self.positive(collider, "physics:density") if collider_path != path else None
            if density is None:
                density = body_density
            if density is not None:
                density = density * self.M / self.L**3
            else:
                material = self.collider_material(desc)
                if isinstance(material, str):
                    material = self.materials[material]
                elif material is None:
                    material = self.materials.get("default", {})
                density = material.get("density", DEFAULT_DENSITY)
            masses.append(None if mass is None else mass * self.M)
            densities.append(density)
        if all(m is None for m in masses) and len(set(densities)) == 1:
            density = densities[0]
            material = self.material_of(body)
            if abs(material.get("density", DEFAULT_DENSITY) - density) > 1e-9 * density:
                inline = dict(material)
                inline["density"] = density
                body["material"] = inline
            return
        total = 0.0
        for (collider_path, type_name, desc), mass, density in zip(colliders, masses, densities, strict=False):
            if mass is not None:
                total += mass
                continue
            volume = self.volume(collider_path, type_name, desc)
            if volume is None:
                self.report.add(collider_path, "approximated", "no volume to weigh: counted as weightless")
                continue
            total += density * volume
        body["mass"] = total
        self.report.add(
            path,
            "approximated",
            f"its colliders differ in mass or density: the body weighs their sum, {total:.6g} kg, "
            "spread at one density over its shape",
        )

    def material_of(self, body) -> dict:
        material = body.get("material")
        if isinstance(material, dict):
            return material
        if isinstance(material, str):
            return self.materials.get(material, {})
        return self.materials.get("default", {"density": DEFAULT_DENSITY})

    def positive(self, prim, name):
        value = self.attribute(prim, name)
        if value is None or float(value) <= 0.0:
            return None
        return float(value)

    def report_mass_frame(self, prim) -> None:
        for name, what in (
            ("physics:centerOfMass", "centre of mass"),
            ("physics:diagonalInertia", "inertia"),
            ("physics:principalAxes", "principal axes"),
        ):
            value = self.attribute(prim, name)
            if value is None:
                continue
            if name == "physics:centerOfMass" and all(float(c) < -1e30 for c in value):
                continue  # the schema's "not set" sentinel
            if name == "physics:diagonalInertia" and all(float(c) == 0.0 for c in value):
                continue
            if name == "physics:principalAxes" and frames.is_identity(frames.quat(value)):
                continue
            self.report.add(
                prim.GetPath(),
                "approximated",
                f"{name} (its {what}): impulse computes the centre of mass and inertia from "
                "the shape (scaled to the mass)",
            )

    def volume(self, path, type_name, desc):
        """A collider's volume (m³), for weighing colliders of different densities."""
        L = self.L
        if type_name == "SphereShape":
            return 4.0 / 3.0 * math.pi * (desc.radius * L) ** 3
        if type_name == "CubeShape":
            hx, hy, hz = (float(c) * L for c in desc.halfExtents)
            return 8.0 * hx * hy * hz
        radius = getattr(desc, "radius", None)
        if radius is None and hasattr(desc, "topRadius"):
            radius = max(desc.topRadius, desc.bottomRadius)
        if type_name.startswith("Capsule"):
            r, h = radius * L, desc.halfHeight * L
            return math.pi * r * r * 2.0 * h + 4.0 / 3.0 * math.pi * r**3
        if type_name.startswith("Cylinder"):
            return math.pi * (radius * L) ** 2 * 2.0 * desc.halfHeight * L
        if type_name == "ConeShape":
            return math.pi * (radius * L) ** 2 * 2.0 * desc.halfHeight * L / 3.0
        if type_name == "MeshShape":
            prim = self.stage.GetPrimAtPath(path)
            mesh = UsdGeom.Mesh(prim)
            points = np.array(mesh.GetPointsAttr().Get(self.time), dtype=np.float64)
            points = points * np.array([float(c) for c in desc.meshScale]) * L
            counts = mesh.GetFaceVertexCountsAttr().Get(self.time)
            indices = mesh.GetFaceVertexIndicesAttr().Get(self.time)
            triangles = self.triangles(path, mesh, counts, indices, len(points))
            if triangles is None:
                return None
            a, b, c = (points[triangles[:, k]] for k in range(3))
            return abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0)
        return None

    # -- collision filtering ---------------------------------------------------------------

    def apply_filters(self) -> None:
        """Collision groups and filtered pairs as the scene's groups and masks.

        Bodies that collide with the same bodies form a class; with at most 32 classes each
        gets a bit, a body's ``groups`` is its class's bit and its ``mask`` the bits of the
        classes it collides with, which is exact. Bodies with impulse's own groups/mask keep
        them."""
        count = len(self.bodies)
        if not any(self.body_groups) and not self.filtered_pairs:
            return
        path_of = {bp.index: bp.path for bp in self.report.bodies}
        owners: dict[str, int] = {}
        for index in range(count):
            for member in self.body_colliders[index]:
                owners[member] = index
        blocked: list[set[int]] = [set() for _ in range(count)]
        for first, second in self.filtered_pairs:
            a, b = owners.get(first), owners.get(second)
            if a is None or b is None:
                self.report.add(first, "dropped", f"its filtered pair with {second}: not a simulated body or collider")
            elif a != b:
                blocked[a].add(b)
                blocked[b].add(a)

        def groups_collide(a: int, b: int) -> bool:
            if self.group_table is None:
                return True
            for ga in self.body_groups[a]:
                for gb in self.body_groups[b]:
                    if not self.group_table.IsCollisionEnabled(Sdf.Path(ga), Sdf.Path(gb)):
                        return False
            return True

        for index in range(count):
            if len(self.body_groups[index]) > 1:
                self.report.add(
                    path_of[index],
                    "note",
                    "its colliders are in several collision groups: it collides with a body "
                    "only when every pair of their groups does",
                )

        def row(a: int) -> tuple:
            return tuple(b != a and b not in blocked[a] and groups_collide(a, b) for b in range(count))

        classes: dict[tuple, int] = {}
        class_of = []
        rows = []
        for index in range(count):
            key = (frozenset(blocked[index]), self.body_groups[index])
            if key not in classes:
                classes[key] = len(classes)
            class_of.append(classes[key])
            rows.append(row(index))
        if len(classes) > 32:
            self.report.add(
                "/",
                "dropped",
                f"the collision groups and filtered pairs make {len(classes)} classes of bodies; "
                "a scene's 32 group bits hold 32: filtering dropped",
            )
            return
        for index in range(count):
            body = self.bodies[index]
            if "groups" in body or "mask" in body:
                continue
            mask = 0
            for other in range(count):
                if other != index and rows[index][other]:
                    mask |= 1 << class_of[other]
            # A class collides within itself unless its members block each other.
            same = [o for o in range(count) if class_of[o] == class_of[index] and o != index]
            if not same or any(rows[index][o] for o in same):
                mask |= 1 << class_of[index]
            body["groups"] = 1 << class_of[index]
            body["mask"] = mask

    # -- joints ----------------------------------------------------------------------------

    def read_joints(self, descriptors) -> list[dict]:
        # Filtered pairs on prims other than colliders (bodies, articulations).
        for prim in self.stage.Traverse():
            if prim.HasAPI(UsdPhysics.FilteredPairsAPI):
                targets = UsdPhysics.FilteredPairsAPI(prim).GetFilteredPairsRel().GetTargets()
                for target in targets:
                    self.filtered_pairs.append((str(prim.GetPath()), str(target)))
        for path, _ in descriptors.get("Articulation", []):
            self.report.add(
                path,
                "note",
                "an articulation root: impulse solves its joints as maximal-coordinate joints",
            )
        items = [
            (path, type_name, desc)
            for type_name in _JOINT_TYPES
            for path, desc in descriptors.get(type_name, [])
        ]
        items.sort(key=lambda item: self.order.get(item[0], len(self.order)))
        joints = []
        for path, type_name, desc in items:
            joint = self.read_joint(path, type_name, desc)
            if joint is not None:
                joints.append(joint)
                self.report.joints.append(path)
        return joints

    def joint_body(self, path: str):
        """The scene body index of a joint's body path, a static anchor body for the world (an
        empty path), and the offset of the body's frame from the prim's."""
        if path in self.body_paths:
            index = self.body_paths[path]
            mapping = self.report.bodies[index]
            offset_position = Gf.Vec3d(*mapping.offset_position) / self.L
            return index, offset_position, frames.from_xyzw(mapping.offset_orientation), None
        anchor = self.world_anchor()
        if not path:
            return anchor, Gf.Vec3d(0.0), Gf.Quatd(frames.IDENTITY), (Gf.Vec3d(0.0), Gf.Quatd(frames.IDENTITY))
        prim = self.stage.GetPrimAtPath(path)
        position, rotation, _ = self.world_pose(prim)
        return anchor, Gf.Vec3d(0.0), Gf.Quatd(frames.IDENTITY), (position, rotation)

    def world_anchor(self) -> int:
        if "__world__" not in self.body_paths:
            index = len(self.bodies)
            self.bodies.append(
                {
                    "name": "world",
                    "kind": "static",
                    "shape": {"type": "sphere", "radius": 0.001},
                    "position": [0.0, 0.0, 0.0],
                    # Its frame is the stage's world frame, so joint ends on the world keep
                    # the stage's coordinates (in stage units times metersPerUnit).
                    "orientation": frames.xyzw(self.A),
                    "groups": 0,
                    "mask": 0,
                }
            )
            self.body_paths["__world__"] = index
            self.report.bodies.append(
                BodyPrim(index, "", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), False)
            )
            self.body_groups.append(frozenset())
            self.body_colliders.append(set())
        return self.body_paths["__world__"]

    def read_joint(self, path, type_name, desc):
        prim = self.stage.GetPrimAtPath(path)
        self.mark(
            path,
            "physics:body0",
            "physics:body1",
            "physics:localPos0",
            "physics:localRot0",
            "physics:localPos1",
            "physics:localRot1",
            "physics:jointEnabled",
            "physics:collisionEnabled",
            "physics:breakForce",
            "physics:breakTorque",
            "physics:excludeFromArticulation",
            "physics:axis",
        )
        if not desc.jointEnabled:
            self.report.add(path, "dropped", "a joint with jointEnabled = false")
            return None
        if type_name == "CustomJoint":
            self.report.add(path, "dropped", "a custom joint type")
            return None
        body0, body1 = str(desc.body0), str(desc.body1)
        if not body0 and not body1:
            self.report.add(path, "dropped", "a joint without bodies")
            return None
        ends = []
        for body_path, local_position, local_rotation in (
            (body0, desc.localPose0Position, desc.localPose0Orientation),
            (body1, desc.localPose1Position, desc.localPose1Orientation),
        ):
            index, offset_position, offset_rotation, world = self.joint_body(body_path)
            position = Gf.Vec3d(*local_position)
            rotation = frames.quat(local_rotation)
            if world is not None:
                # The world, or a prim that is no body: its frame in the world.
                prim_position, prim_rotation = world
                position = prim_position + frames.rotate(prim_rotation, position)
                rotation = prim_rotation * rotation
            # Into the body's frame (which the offset moved from the prim's).
            inverse = offset_rotation.GetInverse()
            anchor = frames.rotate(inverse, position - offset_position)
            frame = inverse * rotation
            ends.append((index, anchor, frame))
        (a, anchor_a, frame_a), (b, anchor_b, frame_b) = ends
        if a == b:
            self.report.add(path, "dropped", "both ends on the same body")
            return None
        if self.bodies[a]["kind"] in ("static", "kinematic") and self.bodies[b]["kind"] in ("static", "kinematic"):
            self.report.add(path, "dropped", "a joint between two bodies that do not move")
            return None
        kind = {
            "FixedJoint": "fixed",
            "RevoluteJoint": "revolute",
            "PrismaticJoint": "prismatic",
            "SphericalJoint": "spherical",
            "DistanceJoint": "distance",
            "D6Joint": "generic",
        }[type_name]
        axis_token = str(getattr(desc, "axis", "X")).rsplit(".", 1)[-1]
        # The joint frames as a scene has them: x along the joint's axis.
        frame_a = frame_a * frames.x_to_axis(axis_token)
        frame_b = frame_b * frames.x_to_axis(axis_token)
        joint: dict = {"type": kind}
        name = self.attribute(prim, "impulse:name")
        if name is None:
            joint["name"] = path
        elif name:
            joint["name"] = name
        joint["body_a"], joint["body_b"] = a, b
        # World frames at the start: where the two ends are, and how they are turned.
        world_a = self.body_world(a, anchor_a, frame_a)
        world_b = self.body_world(b, anchor_b, frame_b)
        gap = (world_a[0] - world_b[0]).GetLength()
        if kind == "distance":
            joint["world_anchors"] = [list(world_a[0]), list(world_b[0])]
        elif gap <= 1e-6 * max(1.0, world_a[0].GetLength()):
            joint["anchor"] = [float(c) for c in world_a[0]]
        else:
            joint["anchor_a"] = [float(c) * self.L for c in anchor_a]
            joint["anchor_b"] = [float(c) * self.L for c in anchor_b]
            self.report.add(
                path,
                "note",
                f"its two frames start {gap:.4g} m apart: the joint pulls them together",
            )
        axis_a = frames.rotate(world_a[1], Gf.Vec3d(1.0, 0.0, 0.0))
        axis_b = frames.rotate(world_b[1], Gf.Vec3d(1.0, 0.0, 0.0))
        # The stage's joint coordinates at the start: the angle of frame B about frame A's x
        # (a scene's coordinates start at zero).
        self.joint_world = (world_a[0], frames.rotate(world_a[1], Gf.Vec3d(1.0, 0.0, 0.0)))
        self.joint_frame = world_a[1]
        # The scene's joint frame is the shortest turn from x to the axis; the stage's may be
        # rolled about the axis against it (a z-up stage's by −90°). Rolls of quarter turns
        # relabel the frame's y and z degrees of freedom.
        roll = frames.twist_angle(frames.shortest_arc(self.joint_world[1]).GetInverse() * world_a[1], (1.0, 0.0, 0.0))
        quarter = round(roll / (math.pi / 2.0))
        self.joint_roll = quarter % 4 if abs(roll - quarter * math.pi / 2.0) < 1e-4 else None
        relative = world_a[1].GetInverse() * world_b[1]
        start_angle = frames.twist_angle(relative, (1.0, 0.0, 0.0))
        if kind in ("revolute", "prismatic", "generic", "spherical"):
            if (axis_a - Gf.Vec3d(1.0, 0.0, 0.0)).GetLength() > 1e-7 or kind != "spherical":
                joint["axis"] = [float(c) for c in axis_a]
            if (axis_a - axis_b).GetLength() > 1e-6:
                self.report.add(
                    path,
                    "approximated",
                    "its two frames' axes differ at the start: the joint turns them together about body 0's",
                )
        if kind in ("fixed", "generic") and not frames.is_identity(relative, 1e-6):
            self.report.add(
                path,
                "approximated",
                "its two frames are turned against each other at the start: the joint holds the "
                "bodies as they start",
            )
        if kind == "revolute":
            self.revolute(path, prim, desc, joint, start_angle)
        elif kind == "prismatic":
            self.prismatic(path, prim, desc, joint)
        elif kind == "spherical":
            self.spherical(path, prim, desc)
        elif kind == "distance":
            self.distance(path, prim, desc, joint)
        elif kind == "generic":
            self.generic(path, prim, desc, joint)
        if desc.collisionEnabled:
            joint["collide_connected"] = True
        force_unit = self.M * self.L
        if math.isfinite(desc.breakForce) and desc.breakForce < 1e37:
            joint["break_force"] = float(desc.breakForce) * force_unit
        if math.isfinite(desc.breakTorque) and desc.breakTorque < 1e37:
            joint["break_torque"] = float(desc.breakTorque) * force_unit * self.L
        own = self.attribute(prim, "impulse:joint")
        if own:
            joint.update(json.loads(own))
        return joint

    def body_world(self, index, anchor, frame):
        """A body-frame point (stage units) and rotation in the scene's world (metres)."""
        body = self.bodies[index]
        position = Gf.Vec3d(*body["position"])
        rotation = frames.from_xyzw(body.get("orientation", [0.0, 0.0, 0.0, 1.0]))
        world = position + frames.rotate(rotation, anchor * self.L)
        return world, rotation * frame

    def drive_units(self, angular: bool) -> tuple[float, float]:
        """(position unit → scene, force unit → scene) of a drive or limit."""
        if angular:
            return math.pi / 180.0, self.M * self.L * self.L
        return self.L, self.M * self.L

    def limits(self, path, lower, upper, angular: bool, offset: float = 0.0):
        unit, _ = self.drive_units(angular)
        low = -math.inf if lower < -1e37 or not math.isfinite(lower) else lower * unit - offset
        high = math.inf if upper > 1e37 or not math.isfinite(upper) else upper * unit - offset
        if angular:
            clamped = (max(low, -math.pi), min(high, math.pi))
            if clamped != (low, high) and (math.isfinite(low) or math.isfinite(high)):
                self.report.add(path, "approximated", f"angle limits [{low:.4g}, {high:.4g}] rad clamped into [−π, π]")
            low, high = clamped
            if low <= -math.pi and high >= math.pi:
                return None
        elif not math.isfinite(low) and not math.isfinite(high):
            return None
        elif not (math.isfinite(low) and math.isfinite(high)):
            low = max(low, -UNLIMITED_DISTANCE)
            high = min(high, UNLIMITED_DISTANCE)
        if low > high:
            return "locked"
        return [low, high]

    def drive(self, path, prim, drive, angular: bool, offset: float, effective_mass: float | None):
        """A UsdPhysics drive as a scene's motor: force = stiffness·(target − x) +
        damping·(target velocity − v), capped at maxForce."""
        if drive is None or not drive.enabled:
            return None
        unit, force_unit = self.drive_units(angular)
        # Stiffness per unit of position (per degree for angular drives) and damping per
        # unit of velocity: per radian and per metre in the scene's units.
        stiffness = float(drive.stiffness) / unit
        damping = float(drive.damping) / unit
        max_force = float(drive.forceLimit)
        max_force = UNLIMITED_FORCE if not math.isfinite(max_force) or max_force > 1e37 else max_force * force_unit
        if not drive.acceleration and stiffness > 0.0:
            if effective_mass is None:
                effective_mass = 1.0
                self.report.add(path, "approximated", "a force drive without a moving body's mass: gains taken per unit mass")
            stiffness = stiffness * force_unit / effective_mass
            damping = damping * force_unit / effective_mass
            self.report.add(
                path,
                "approximated",
                f"a force drive: its gains are turned into a frequency and damping ratio at an "
                f"effective {'inertia' if angular else 'mass'} of {effective_mass:.6g} "
                f"{'kg·m²' if angular else 'kg'} (impulse's motors are set by frequency)",
            )
        target_velocity = float(drive.targetVelocity) * unit
        if stiffness > 0.0:
            omega = math.sqrt(stiffness)
            hertz = omega / (2.0 * math.pi)
            ratio = damping / (2.0 * omega)
            if target_velocity != 0.0:
                self.report.add(path, "dropped", "a drive with both stiffness and a target velocity: the target velocity")
            return {
                "position": float(drive.targetPosition) * unit - offset,
                "hertz": min(hertz, 1.0e6),
                "damping_ratio": min(ratio, 1.0e6),
                "max_force": max_force,
            }
        if damping > 0.0:
            self.report.add(
                path,
                "approximated",
                "a velocity drive (damping only): a velocity motor that reaches its target "
                "velocity within maxForce in a step",
            )
            return {"velocity": target_velocity, "max_force": max_force}
        return None

    def effective_mass(self, joint, angular: bool):
        """An estimate of the joint's effective mass (kg) or inertia about its axis (kg·m²),
        to turn a force drive's gains into a frequency: the moving bodies' in series, each
        body a box of its shape's extent at its mass, turning about the axis through the
        anchor. None when neither body moves."""
        anchor, axis = self.joint_world
        inverses = 0.0
        for index in (joint["body_a"], joint["body_b"]):
            body = self.bodies[index]
            if body["kind"] not in ("dynamic", "particle"):
                continue
            half = _half_extents(body["shape"])
            mass = body.get("mass")
            if mass is None:
                material = self.material_of(body)
                mass = material.get("density", DEFAULT_DENSITY) * 8.0 * half[0] * half[1] * half[2]
            if not angular:
                inverses += 1.0 / mass
                continue
            rotation = frames.from_xyzw(body.get("orientation", [0.0, 0.0, 0.0, 1.0]))
            local_axis = frames.rotate(rotation.GetInverse(), axis)
            gyration = sum(half[k] ** 2 * (1.0 - local_axis[k] ** 2) for k in range(3)) / 3.0
            lever = Gf.Vec3d(*body["position"]) - anchor
            distance2 = (lever - axis * Gf.Dot(lever, axis)).GetLength() ** 2
            inverses += 1.0 / (mass * (gyration + distance2))
        return 1.0 / inverses if inverses > 0.0 else None

    def revolute(self, path, prim, desc, joint, start_angle) -> None:
        self.mark(path, "physics:lowerLimit", "physics:upperLimit")
        if desc.limit.enabled:
            limits = self.limits(path, desc.limit.lower, desc.limit.upper, True, start_angle)
            if limits == "locked":
                self.report.add(path, "approximated", "lower limit above upper: the hinge is locked")
                joint["limits"] = [0.0, 0.0]
            elif limits is not None:
                joint["limits"] = limits
        self.read_drive(path, prim, desc.drive, joint, True, start_angle, "angular")

    def prismatic(self, path, prim, desc, joint) -> None:
        self.mark(path, "physics:lowerLimit", "physics:upperLimit")
        if desc.limit.enabled:
            limits = self.limits(path, desc.limit.lower, desc.limit.upper, False)
            if limits == "locked":
                joint["limits"] = [0.0, 0.0]
            elif limits is not None:
                joint["limits"] = limits
        self.read_drive(path, prim, desc.drive, joint, False, 0.0, "linear")

    def read_drive(self, path, prim, drive, joint, angular, offset, instance) -> None:
        for name in ("type", "maxForce", "targetPosition", "targetVelocity", "damping", "stiffness"):
            self.mark(path, f"drive:{instance}:physics:{name}")
        motor = self.drive(path, prim, drive, angular, offset, self.effective_mass(joint, angular))
        if motor is not None:
            joint["motor"] = motor

    def spherical(self, path, prim, desc) -> None:
        self.mark(path, "physics:coneAngle0Limit", "physics:coneAngle1Limit")
        # The parser's cone limit: its two angles (degrees) are the limit's lower and upper.
        cone = (float(desc.limit.lower), float(desc.limit.upper))
        if desc.limit.enabled and 0.0 <= min(cone) < 179.9:
            self.report.add(
                path,
                "dropped",
                f"its cone limit ({cone[0]:g}°, {cone[1]:g}°): impulse's spherical joints have no cone limit",
            )

    def distance(self, path, prim, desc, joint) -> None:
        self.mark(path, "physics:minDistance", "physics:maxDistance")
        low = float(desc.limit.lower) * self.L if desc.minEnabled else 0.0
        high = float(desc.limit.upper) * self.L if desc.maxEnabled else UNLIMITED_DISTANCE
        if not desc.maxEnabled:
            self.report.add(path, "note", f"no maximum distance: {UNLIMITED_DISTANCE:g} m")
        joint["limits"] = [max(low, 0.0), max(high, low, 0.0)]

    def scene_dof(self, path, token: str) -> tuple[str, float]:
        """The scene's degree of freedom of a stage's (``TransY``, ``RotZ``, …) and the sign
        between their coordinates, through the roll of the stage's joint frame."""
        axis = token[-1]
        if axis == "X" or self.joint_roll in (0, None):
            if axis != "X" and self.joint_roll is None:
                self.report.add(
                    path,
                    "approximated",
                    f"its frame is rolled about its axis by other than quarter turns: {token} is "
                    "taken about the scene frame's own axis",
                )
            return _DOF_NAMES[token], 1.0
        mapping = {
            1: {"Y": ("Z", 1.0), "Z": ("Y", -1.0)},
            2: {"Y": ("Y", -1.0), "Z": ("Z", -1.0)},
            3: {"Y": ("Z", -1.0), "Z": ("Y", 1.0)},
        }[self.joint_roll]
        letter, sign = mapping[axis]
        return _DOF_NAMES[token[:-1] + letter], sign

    def generic(self, path, prim, desc, joint) -> None:
        dofs = {name: "free" for name in _DOF_NAMES.values()}
        for pair in desc.jointLimits:
            dof, limit = pair.first, pair.second
            token = str(dof).rsplit(".", 1)[-1]
            usd_name = token[0].lower() + token[1:]
            self.mark(path, f"limit:{usd_name}:physics:low", f"limit:{usd_name}:physics:high")
            if token not in _DOF_NAMES:
                self.report.add(path, "dropped", f"its {token} limit (a D6 distance limit)")
                continue
            if not limit.enabled:
                continue
            angular = token.startswith("Rot")
            name, sign = self.scene_dof(path, token)
            limits = self.limits(path, limit.lower, limit.upper, angular)
            if limits == "locked":
                dofs[name] = "locked"
            elif limits is not None:
                dofs[name] = {"limits": sorted(sign * value for value in limits)}
        for pair in desc.jointDrives:
            dof, drive = pair.first, pair.second
            token = str(dof).rsplit(".", 1)[-1]
            usd_name = token[0].lower() + token[1:]
            for name in ("type", "maxForce", "targetPosition", "targetVelocity", "damping", "stiffness"):
                self.mark(path, f"drive:{usd_name}:physics:{name}")
            if token not in _DOF_NAMES:
                self.report.add(path, "dropped", f"its {token} drive")
                continue
            name, sign = self.scene_dof(path, token)
            angular = token.startswith("Rot")
            self.joint_world = (self.joint_world[0], frames.rotate(self.joint_frame, _DOF_AXES[token[-1]]))
            motor = self.drive(path, prim, drive, angular, 0.0, self.effective_mass(joint, angular))
            if motor is None:
                continue
            for field in ("velocity", "position"):
                if field in motor:
                    motor[field] = sign * motor[field]
            if dofs[name] == "locked":
                self.report.add(path, "dropped", f"a drive on its locked {token}")
                continue
            entry = dofs[name] if isinstance(dofs[name], dict) else {}
            entry["motor"] = motor
            dofs[name] = entry
        joint["dofs"] = dofs

    # -- what is left ----------------------------------------------------------------------

    def report_unmapped(self) -> None:
        """Every authored physics attribute nothing above mapped, by prim path."""
        for prim in self.stage.Traverse():
            path = str(prim.GetPath())
            for attribute in prim.GetAuthoredAttributes():
                name = attribute.GetName()
                if not name.startswith(_PHYSICS_NAMESPACES):
                    continue
                if (path, name) in self.handled:
                    continue
                if name.startswith("physics:") and not self.is_physics_prim(prim):
                    self.report.add(
                        path,
                        "dropped",
                        f"{name}: on a prim of type {prim.GetTypeName() or 'none'} without a physics "
                        "schema (a misspelt type or a missing API schema?)",
                    )
                    continue
                self.report.add(path, "dropped", f"{name} is not simulated")
            for schema in prim.GetAppliedSchemas():
                if schema.startswith("Physx") or schema.startswith("PhysicsArticulation"):
                    if schema in ("PhysxConvexDecompositionCollisionAPI",):
                        continue
                    if not any((path, a.GetName()) in self.handled for a in prim.GetAuthoredAttributes()):
                        self.report.add(path, "note", f"{schema} applied: PhysX's own settings, not read")

    def is_physics_prim(self, prim) -> bool:
        return bool(
            prim.HasAPI(UsdPhysics.RigidBodyAPI)
            or prim.HasAPI(UsdPhysics.CollisionAPI)
            or prim.HasAPI(UsdPhysics.MassAPI)
            or prim.HasAPI(UsdPhysics.MaterialAPI)
            or prim.IsA(UsdPhysics.Joint)
            or prim.IsA(UsdPhysics.Scene)
            or prim.IsA(UsdPhysics.CollisionGroup)
        )


def _close(a, b, tolerance: float = 1e-6) -> bool:
    """Whether two JSON values are equal, numbers to a relative ``tolerance``."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k], tolerance) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y, tolerance) for x, y in zip(a, b, strict=False))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return abs(a - b) <= tolerance * max(1.0, abs(a), abs(b))
    return a == b


def _single_precision(value):
    """Every float as the shortest decimal of its nearest f32, the precision a scene is read
    at: what impulse simulates is unchanged, and a scene's own numbers come back as written."""
    if isinstance(value, dict):
        return {key: _single_precision(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_single_precision(item) for item in value]
    if isinstance(value, float):
        if not math.isfinite(value) or abs(value) > 3.4e38:
            return value
        return float(str(np.float32(value)))
    return value


def _half_extents(shape: dict) -> list[float]:
    """The half extents (m) of a shape's bounding box in its body's frame (a mass estimate's)."""
    kind = shape["type"]
    if kind == "sphere":
        return [shape["radius"]] * 3
    if kind == "cuboid":
        return list(shape["half_extents"])
    if kind in ("capsule", "cylinder", "cone"):
        radius = shape["radius"]
        extra = radius if kind == "capsule" else 0.0
        return [radius, shape["half_height"] + extra, radius]
    points = shape.get("points") or shape.get("vertices")
    if points:
        array = np.abs(np.asarray(points, dtype=np.float64))
        return [float(c) for c in array.max(axis=0)]
    if kind == "compound":
        reach = max(
            max(_half_extents(part["shape"])) + max(abs(c) for c in part.get("position", [0, 0, 0]))
            for part in shape["parts"]
        )
        return [reach] * 3
    return [0.5, 0.5, 0.5]


class _RelativeCollider:
    """A collider descriptor whose world pose (the parser's for a collider without a body) is
    made relative to a static body's frame, as the parser gives a body's colliders'."""

    def __init__(self, desc, body_pose):
        self._desc = desc
        position, rotation, _ = body_pose
        inverse = rotation.GetInverse()
        self.localPos = frames.rotate(inverse, Gf.Vec3d(*desc.localPos) - position)
        self.localRot = inverse * frames.quat(desc.localRot)

    def __getattr__(self, name):
        return getattr(self._desc, name)
