"""A scene written as a UsdPhysics stage (the reverse of ``stage_to_scene``)."""

from __future__ import annotations

import json
import math
import os
import re

from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics, UsdShade

from . import _frames as frames

_DOF_TOKENS = {
    "linear_x": "transX",
    "linear_y": "transY",
    "linear_z": "transZ",
    "angular_x": "rotX",
    "angular_y": "rotY",
    "angular_z": "rotZ",
}
_KINDS = {
    "fixed": UsdPhysics.FixedJoint,
    "revolute": UsdPhysics.RevoluteJoint,
    "prismatic": UsdPhysics.PrismaticJoint,
    "spherical": UsdPhysics.SphericalJoint,
    "distance": UsdPhysics.DistanceJoint,
    "generic": UsdPhysics.Joint,
}
#: The half side (m) of the square a half-space is drawn as (the physics plane is infinite).
PLANE_HALF_SIDE = 50.0


def scene_to_stage(scene: dict | str | os.PathLike, out: str | os.PathLike) -> Usd.Stage:
    """Writes a scene (a dict of docs/scene-format.md, or a ``.json`` file) as a UsdPhysics
    stage at ``out`` (``.usda``, ``.usdc``), y up, in metres and kilograms, and returns it.

    Under ``/World``: a ``PhysicsScene`` (gravity), the physics materials under
    ``/World/Materials``, one prim per body named after it (an ``Xform`` with
    ``PhysicsRigidBodyAPI`` and ``PhysicsMassAPI`` for a moving body, with its collider as the
    child ``collider``; the collider itself for a static body), and the joints under
    ``/World/Joints``. What UsdPhysics has no attribute for (the solver settings, time step,
    roughness, damping, locked axes, collision bit masks, joint springs, a rounded or thin
    shape's exact form, …) is kept in ``impulse:`` attributes, so ``stage_to_scene`` gives the
    scene back. A kinematic body's keyframes are time samples of its transform, on time codes
    of ``1/dt`` per second. docs/usd.md lists the mapping.

    Raises ``ValueError`` for a scene this cannot write (a mesh given by file is kept as an
    ``impulse:shape`` attribute naming the file, absolute, and drawn as an empty mesh).
    """
    scene = _load(scene)
    out = os.fspath(out)
    stage = Usd.Stage.CreateNew(out)
    if stage is None:
        raise ValueError(f"{out}: cannot create a stage there")
    _Writer(stage, scene, os.path.dirname(os.path.abspath(out))).write()
    stage.GetRootLayer().Save()
    return stage


def _load(scene):
    if isinstance(scene, dict):
        return scene
    path = os.fspath(scene)
    with open(path, encoding="utf-8") as file:
        loaded = json.load(file)
    # Mesh files are relative to the scene file's directory.
    absolute_files(loaded, os.path.dirname(os.path.abspath(path)))
    return loaded


def absolute_files(scene: dict, directory: str) -> None:
    """Makes the mesh files of a scene's ``trimesh`` shapes absolute, from ``directory``."""
    for body in scene.get("bodies", []):
        _absolute_files(body.get("shape", {}), os.path.abspath(directory))


def _absolute_files(shape: dict, base: str) -> None:
    if shape.get("type") == "trimesh" and "file" in shape and not os.path.isabs(shape["file"]):
        shape["file"] = os.path.join(base, shape["file"])
    for part in shape.get("parts", []):
        _absolute_files(part.get("shape", {}), base)


def identifier(name: str, used: set[str]) -> str:
    """A prim name for a scene name: characters other than ASCII letters, digits and ``_``
    become ``_``, a leading digit gets a ``_`` in front, repeats get ``_2``, ``_3``, …"""
    base = re.sub(r"[^A-Za-z0-9_]", "_", name) or "_"
    if base[0].isdigit():
        base = "_" + base
    candidate, number = base, 2
    while candidate in used:
        candidate, number = f"{base}_{number}", number + 1
    used.add(candidate)
    return candidate


class _Writer:
    def __init__(self, stage: Usd.Stage, scene: dict, directory: str):
        self.stage = stage
        self.scene = scene
        self.directory = directory
        self.dt = float(scene.get("dt", 1.0 / 60.0))
        rate = 1.0 / self.dt
        self.rate = float(round(rate)) if abs(rate - round(rate)) < 1e-4 * rate else rate
        self.body_paths: list[str] = []
        self.body_scales: list[Gf.Vec3d] = []

    def write(self) -> None:
        stage, scene = self.stage, self.scene
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
        UsdGeom.SetStageMetersPerUnit(stage, 1.0)
        UsdPhysics.SetStageKilogramsPerUnit(stage, 1.0)
        stage.SetTimeCodesPerSecond(self.rate)
        stage.SetFramesPerSecond(self.rate)
        stage.SetStartTimeCode(0.0)
        stage.SetEndTimeCode(float(scene.get("steps", 600)) * self.dt * self.rate)
        world = UsdGeom.Xform.Define(stage, "/World")
        stage.SetDefaultPrim(world.GetPrim())
        self.write_physics_scene()
        self.write_materials()
        used: set[str] = {"physicsScene", "Materials", "Joints"}
        for index, body in enumerate(scene["bodies"]):
            name = identifier(body.get("name") or f"body_{index}", used)
            self.write_body(index, body, f"/World/{name}")
        for index, joint in enumerate(scene.get("joints", [])):
            self.write_joint(index, joint)

    # -- scene and materials ---------------------------------------------------------------

    def write_physics_scene(self) -> None:
        scene = self.scene
        physics = UsdPhysics.Scene.Define(self.stage, "/World/physicsScene")
        gravity = Gf.Vec3d(*scene.get("gravity", [0.0, -9.81, 0.0]))
        magnitude = gravity.GetLength()
        physics.CreateGravityMagnitudeAttr(magnitude)
        physics.CreateGravityDirectionAttr(
            Gf.Vec3f(gravity / magnitude) if magnitude > 0 else Gf.Vec3f(0.0, -1.0, 0.0)
        )
        prim = physics.GetPrim()
        _set(prim, "impulse:dt", Sdf.ValueTypeNames.Float, self.dt)
        _set(prim, "impulse:steps", Sdf.ValueTypeNames.Int64, int(scene.get("steps", 600)))
        if "name" in scene:
            _set(prim, "impulse:name", Sdf.ValueTypeNames.String, scene["name"])
        if scene.get("seed"):
            _set(prim, "impulse:seed", Sdf.ValueTypeNames.UInt64, int(scene["seed"]))
        if scene.get("solver"):
            _set(prim, "impulse:solver", Sdf.ValueTypeNames.String, json.dumps(scene["solver"]))

    def write_materials(self) -> None:
        self.material_paths: dict[str, str] = {}
        materials = self.scene.get("materials", {})
        if not materials:
            return
        UsdGeom.Scope.Define(self.stage, "/World/Materials")
        used: set[str] = set()
        for name, material in materials.items():
            path = f"/World/Materials/{identifier(name, used)}"
            self.write_material(path, material, name)
            self.material_paths[name] = path

    def write_material(self, path: str, material: dict, name: str) -> None:
        prim = UsdShade.Material.Define(self.stage, path).GetPrim()
        api = UsdPhysics.MaterialAPI.Apply(prim)
        friction = float(material.get("friction", 0.5))
        api.CreateStaticFrictionAttr(friction)
        api.CreateDynamicFrictionAttr(friction)
        api.CreateRestitutionAttr(float(material.get("restitution", 0.0)))
        api.CreateDensityAttr(float(material.get("density", 1000.0)))
        _set(prim, "impulse:name", Sdf.ValueTypeNames.String, name)
        if "roughness" in material:
            _set(prim, "impulse:roughness", Sdf.ValueTypeNames.Float, material["roughness"])
        if "impact_perturbation" in material:
            _set(prim, "impulse:impactPerturbation", Sdf.ValueTypeNames.Float, material["impact_perturbation"])

    # -- bodies ----------------------------------------------------------------------------

    def write_body(self, index: int, body: dict, path: str) -> None:
        kind = body["kind"]
        shape = body["shape"]
        position = body.get("position", [0.0, 0.0, 0.0])
        orientation = body.get("orientation", [0.0, 0.0, 0.0, 1.0])
        if kind == "static" and shape["type"] != "compound":
            # A static body is its collider: a collider without a rigid body.
            xform = UsdGeom.Xform.Define(self.stage, path)
            body_prim = xform.GetPrim()
            _place(xform, position, orientation)
            collider = self.write_shape(f"{path}/collider", shape, static=True)
            owner = collider
        else:
            xform = UsdGeom.Xform.Define(self.stage, path)
            body_prim = xform.GetPrim()
            _place(xform, position, orientation)
            rigid = UsdPhysics.RigidBodyAPI.Apply(body_prim)
            if kind == "static":
                # A static compound: one body of several colliders, a disabled rigid body.
                rigid.CreateRigidBodyEnabledAttr(False)
            if kind == "kinematic":
                rigid.CreateKinematicEnabledAttr(True)
            if any(body.get("linear_velocity", [0, 0, 0])):
                rigid.CreateVelocityAttr(Gf.Vec3f(*body["linear_velocity"]))
            if any(body.get("angular_velocity", [0, 0, 0])):
                degrees = [math.degrees(c) for c in body["angular_velocity"]]
                rigid.CreateAngularVelocityAttr(Gf.Vec3f(*degrees))
            if "mass" in body:
                UsdPhysics.MassAPI.Apply(body_prim).CreateMassAttr(float(body["mass"]))
            if kind == "particle":
                _set(body_prim, "impulse:kind", Sdf.ValueTypeNames.Token, "particle")
            self.write_shape(f"{path}/collider", shape, static=kind == "static")
            owner = body_prim
            if body.get("keyframes"):
                self.write_keyframes(xform, body)
        self.body_paths.append(str(owner.GetPath()))
        # Joint frames are in the body prim's space, which a static collider's scale scales.
        self.body_scales.append(_own_scale(owner))
        _set(owner, "impulse:name", Sdf.ValueTypeNames.String, body.get("name", ""))
        self.write_material_binding(index, body, path)
        for field, name, value_type in (
            ("linear_damping", "impulse:linearDamping", Sdf.ValueTypeNames.Float),
            ("angular_damping", "impulse:angularDamping", Sdf.ValueTypeNames.Float),
            ("lock_rotation", "impulse:lockRotation", Sdf.ValueTypeNames.Bool),
            ("groups", "impulse:groups", Sdf.ValueTypeNames.UInt),
            ("mask", "impulse:mask", Sdf.ValueTypeNames.UInt),
        ):
            if field in body:
                _set(owner, name, value_type, body[field])
        for field, name in (("locked_axes", "impulse:lockedAxes"), ("roughness_draws", "impulse:roughnessDraws")):
            if body.get(field):
                _set(owner, name, Sdf.ValueTypeNames.String, json.dumps(body[field]))
        _ = body_prim

    def write_keyframes(self, xform: UsdGeom.Xform, body: dict) -> None:
        translate, orient = xform.GetOrderedXformOps()[:2]
        for keyframe in body["keyframes"]:
            code = Usd.TimeCode(float(keyframe["t"]) * self.rate)
            translate.Set(Gf.Vec3d(*keyframe["position"]), code)
            orient.Set(_quatf(keyframe.get("orientation", [0.0, 0.0, 0.0, 1.0])), code)
        start = Usd.TimeCode(0.0)
        translate.Set(Gf.Vec3d(*body.get("position", [0.0, 0.0, 0.0])), start)
        orient.Set(_quatf(body.get("orientation", [0.0, 0.0, 0.0, 1.0])), start)

    def write_material_binding(self, index: int, body: dict, path: str) -> None:
        material = body.get("material", "default")
        colliders = [p for p in Usd.PrimRange(self.stage.GetPrimAtPath(path)) if p.HasAPI(UsdPhysics.CollisionAPI)]
        if isinstance(material, dict):
            target = f"{path}/material"
            self.write_material(target, material, "")
            _set(self.stage.GetPrimAtPath(target), "impulse:inline", Sdf.ValueTypeNames.Bool, True)
        elif material in self.material_paths:
            target = self.material_paths[material]
        else:
            return  # the built-in default: no binding
        shade = UsdShade.Material(self.stage.GetPrimAtPath(target))
        for collider in colliders:
            binding = UsdShade.MaterialBindingAPI.Apply(collider)
            binding.Bind(shade, UsdShade.Tokens.weakerThanDescendants, "physics")

    def write_shape(self, path: str, shape: dict, static: bool) -> Usd.Prim:
        kind = shape["type"]
        exact = None  # the shape itself, where the prim only approximates it
        if kind == "compound":
            scope = UsdGeom.Xform.Define(self.stage, path)
            for number, part in enumerate(shape["parts"]):
                child = UsdGeom.Xform.Define(self.stage, f"{path}/part_{number}")
                _place(child, part.get("position", [0.0, 0.0, 0.0]), part.get("orientation", [0.0, 0.0, 0.0, 1.0]))
                self.write_shape(f"{path}/part_{number}/collider", part["shape"], static)
            _set(scope.GetPrim(), "impulse:shape", Sdf.ValueTypeNames.String, json.dumps(shape))
            return scope.GetPrim()
        inner = shape
        flat = kind == "cuboid" and 0.0 in [float(c) for c in shape["half_extents"]]
        if "border_radius" in shape or "thickness" in shape or flat:
            exact = shape
            inner = {k: v for k, v in shape.items() if k not in ("border_radius", "thickness")}
            kind = inner["type"]
        if kind == "sphere":
            prim = UsdGeom.Sphere.Define(self.stage, path)
            prim.CreateRadiusAttr(float(inner["radius"]))
        elif kind == "cuboid":
            prim = UsdGeom.Cube.Define(self.stage, path)
            prim.CreateSizeAttr(2.0)
            prim.AddScaleOp().Set(Gf.Vec3f(*inner["half_extents"]))
        elif kind in ("capsule", "cylinder", "cone"):
            schema = {"capsule": UsdGeom.Capsule, "cylinder": UsdGeom.Cylinder, "cone": UsdGeom.Cone}[kind]
            prim = schema.Define(self.stage, path)
            prim.CreateRadiusAttr(float(inner["radius"]))
            prim.CreateHeightAttr(2.0 * float(inner["half_height"]))
            prim.CreateAxisAttr(UsdGeom.Tokens.y)
        elif kind == "half_space":
            prim = UsdGeom.Plane.Define(self.stage, path)
            prim.CreateAxisAttr(UsdGeom.Tokens.y)
            prim.CreateWidthAttr(2.0 * PLANE_HALF_SIDE)
            prim.CreateLengthAttr(2.0 * PLANE_HALF_SIDE)
            normal = Gf.Vec3d(*inner["normal"]).GetNormalized()
            if (normal - Gf.Vec3d(0.0, 1.0, 0.0)).GetLength() > 0.0:
                turn = Gf.Rotation(Gf.Vec3d(0.0, 1.0, 0.0), normal).GetQuat()
                prim.AddOrientOp().Set(Gf.Quatf(turn))
        elif kind == "convex_hull":
            prim = UsdGeom.Mesh.Define(self.stage, path)
            points = [list(map(float, p)) for p in inner["points"]]
            prim.CreatePointsAttr([Gf.Vec3f(*p) for p in points])
            counts, indices = _hull_faces(points)
            prim.CreateFaceVertexCountsAttr(counts)
            prim.CreateFaceVertexIndicesAttr(indices)
            prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            UsdPhysics.MeshCollisionAPI.Apply(prim.GetPrim()).CreateApproximationAttr(UsdPhysics.Tokens.convexHull)
        elif kind == "trimesh" and "vertices" in inner:
            prim = UsdGeom.Mesh.Define(self.stage, path)
            prim.CreatePointsAttr([Gf.Vec3f(*map(float, p)) for p in inner["vertices"]])
            prim.CreateFaceVertexCountsAttr([3] * len(inner["indices"]))
            prim.CreateFaceVertexIndicesAttr([int(i) for t in inner["indices"] for i in t])
            prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            if inner.get("two_sided"):
                prim.CreateDoubleSidedAttr(True)
            approximation = UsdPhysics.Tokens.none if static else UsdPhysics.Tokens.convexDecomposition
            UsdPhysics.MeshCollisionAPI.Apply(prim.GetPrim()).CreateApproximationAttr(approximation)
            if inner.get("decomposition"):
                _set(prim.GetPrim(), "impulse:decomposition", Sdf.ValueTypeNames.String, json.dumps(inner["decomposition"]))
        elif kind in ("trimesh", "heightfield"):
            prim = UsdGeom.Mesh.Define(self.stage, path)
            if kind == "heightfield":
                vertices, counts, indices = _heightfield_mesh(inner)
                prim.CreatePointsAttr(vertices)
                prim.CreateFaceVertexCountsAttr(counts)
                prim.CreateFaceVertexIndicesAttr(indices)
            prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            UsdPhysics.MeshCollisionAPI.Apply(prim.GetPrim()).CreateApproximationAttr(UsdPhysics.Tokens.none)
            exact = shape
        else:
            raise ValueError(f"a {kind!r} shape has no USD form")
        UsdPhysics.CollisionAPI.Apply(prim.GetPrim())
        if exact is not None:
            _set(prim.GetPrim(), "impulse:shape", Sdf.ValueTypeNames.String, json.dumps(exact))
        return prim.GetPrim()

    # -- joints ----------------------------------------------------------------------------

    def body_pose(self, index: int) -> tuple[Gf.Vec3d, Gf.Quatd]:
        body = self.scene["bodies"][index]
        return Gf.Vec3d(*body.get("position", [0.0, 0.0, 0.0])), frames.from_xyzw(
            body.get("orientation", [0.0, 0.0, 0.0, 1.0])
        )

    def body_index(self, name) -> int:
        if isinstance(name, int):
            return name
        for index, body in enumerate(self.scene["bodies"]):
            if body.get("name") == name:
                return index
        raise ValueError(f"a joint names no body {name!r}")

    def write_joint(self, number: int, joint: dict) -> None:
        if number == 0:
            UsdGeom.Scope.Define(self.stage, "/World/Joints")
        used = getattr(self, "_joint_names", set())
        self._joint_names = used
        name = identifier(joint.get("name") or f"joint_{number}", used)
        schema = _KINDS[joint["type"]]
        usd_joint = schema.Define(self.stage, f"/World/Joints/{name}")
        prim = usd_joint.GetPrim()
        a, b = self.body_index(joint["body_a"]), self.body_index(joint["body_b"])
        usd_joint.CreateBody0Rel().SetTargets([self.body_paths[a]])
        usd_joint.CreateBody1Rel().SetTargets([self.body_paths[b]])
        pose_a, pose_b = self.body_pose(a), self.body_pose(b)
        # Anchors in each body's frame, as the scene places them.
        if "anchor" in joint:
            anchor_a = frames.rotate(pose_a[1].GetInverse(), Gf.Vec3d(*joint["anchor"]) - pose_a[0])
            anchor_b = frames.rotate(pose_b[1].GetInverse(), Gf.Vec3d(*joint["anchor"]) - pose_b[0])
        elif "world_anchors" in joint:
            first, second = (Gf.Vec3d(*p) for p in joint["world_anchors"])
            anchor_a = frames.rotate(pose_a[1].GetInverse(), first - pose_a[0])
            anchor_b = frames.rotate(pose_b[1].GetInverse(), second - pose_b[0])
        else:
            anchor_a = Gf.Vec3d(*joint.get("anchor_a", [0.0, 0.0, 0.0]))
            anchor_b = Gf.Vec3d(*joint.get("anchor_b", [0.0, 0.0, 0.0]))
        # Frames: x along the axis, the shortest turn from x (the scene's rule).
        if "axis_a" in joint:
            axis_a, axis_b = Gf.Vec3d(*joint["axis_a"]), Gf.Vec3d(*joint["axis_b"])
            frame_a, frame_b = _shortest_arc(axis_a), _shortest_arc(axis_b)
        else:
            world_axis = Gf.Vec3d(*joint.get("axis", [1.0, 0.0, 0.0]))
            world_frame = _shortest_arc(world_axis)
            frame_a = pose_a[1].GetInverse() * world_frame
            frame_b = pose_b[1].GetInverse() * world_frame
        scale_a, scale_b = self.body_scales[a], self.body_scales[b]
        usd_joint.CreateLocalPos0Attr(Gf.Vec3f(*(anchor_a[i] / scale_a[i] for i in range(3))))
        usd_joint.CreateLocalRot0Attr(Gf.Quatf(frame_a.GetNormalized()))
        usd_joint.CreateLocalPos1Attr(Gf.Vec3f(*(anchor_b[i] / scale_b[i] for i in range(3))))
        usd_joint.CreateLocalRot1Attr(Gf.Quatf(frame_b.GetNormalized()))
        usd_joint.CreateCollisionEnabledAttr(bool(joint.get("collide_connected", False)))
        if "break_force" in joint:
            usd_joint.CreateBreakForceAttr(float(joint["break_force"]))
        if "break_torque" in joint:
            usd_joint.CreateBreakTorqueAttr(float(joint["break_torque"]))
        kind = joint["type"]
        if kind in ("revolute", "prismatic"):
            usd_joint.CreateAxisAttr(UsdPhysics.Tokens.x)
            angular = kind == "revolute"
            unit = 180.0 / math.pi if angular else 1.0
            if "limits" in joint:
                usd_joint.CreateLowerLimitAttr(float(joint["limits"][0]) * unit)
                usd_joint.CreateUpperLimitAttr(float(joint["limits"][1]) * unit)
            if "motor" in joint:
                _drive(prim, "angular" if angular else "linear", joint["motor"], angular)
        elif kind == "distance":
            low, high = joint.get("limits", [0.0, 0.0])
            usd_joint.CreateMinDistanceAttr(float(low))
            usd_joint.CreateMaxDistanceAttr(float(high))
        elif kind == "generic":
            for dof, token in _DOF_TOKENS.items():
                setting = joint.get("dofs", {}).get(dof, "locked")
                angular = dof.startswith("angular")
                unit = 180.0 / math.pi if angular else 1.0
                if setting == "locked":
                    limit = UsdPhysics.LimitAPI.Apply(prim, token)
                    limit.CreateLowAttr(1.0)
                    limit.CreateHighAttr(-1.0)
                    continue
                if setting == "free":
                    continue
                if "limits" in setting:
                    limit = UsdPhysics.LimitAPI.Apply(prim, token)
                    limit.CreateLowAttr(float(setting["limits"][0]) * unit)
                    limit.CreateHighAttr(float(setting["limits"][1]) * unit)
                if "motor" in setting:
                    _drive(prim, token, setting["motor"], angular)
        # What the schema has no attribute for.
        own = {key: joint[key] for key in ("spring", "stiffness", "break_window") if key in joint}
        if kind not in ("generic",) and joint.get("dofs"):
            own["dofs"] = joint["dofs"]
        if own:
            _set(prim, "impulse:joint", Sdf.ValueTypeNames.String, json.dumps(own))
        _set(prim, "impulse:name", Sdf.ValueTypeNames.String, joint.get("name", ""))


def _drive(prim: Usd.Prim, instance: str, motor: dict, angular: bool) -> None:
    """A scene's motor as a UsdPhysics drive of acceleration type: a position motor's frequency
    f and damping ratio ζ are the stiffness (2πf)² and damping 2ζ·2πf per unit of
    position (per degree for angles); a velocity motor is a drive without stiffness."""
    drive = UsdPhysics.DriveAPI.Apply(prim, instance)
    drive.CreateTypeAttr(UsdPhysics.Tokens.acceleration)
    unit = math.pi / 180.0 if angular else 1.0
    drive.CreateMaxForceAttr(float(motor["max_force"]))
    if "position" in motor:
        omega = 2.0 * math.pi * float(motor.get("hertz", 5.0))
        drive.CreateStiffnessAttr(omega * omega * unit)
        drive.CreateDampingAttr(2.0 * float(motor.get("damping_ratio", 1.0)) * omega * unit)
        drive.CreateTargetPositionAttr(float(motor["position"]) / unit)
    else:
        # A rigid velocity motor: as stiff a damping as the force limit allows.
        drive.CreateDampingAttr(1.0e6 * unit)
        drive.CreateTargetVelocityAttr(float(motor.get("velocity", 0.0)) / unit)


def _shortest_arc(axis: Gf.Vec3d) -> Gf.Quatd:
    """The shortest rotation taking x to ``axis`` (identity for a zero axis): the scene's rule
    for a joint frame given by its axis."""
    length = axis.GetLength()
    if length == 0.0:
        return Gf.Quatd(frames.IDENTITY)
    return Gf.Rotation(Gf.Vec3d(1.0, 0.0, 0.0), axis / length).GetQuat()


def _place(xform: UsdGeom.Xformable, position, orientation) -> None:
    xform.AddTranslateOp().Set(Gf.Vec3d(*(float(c) for c in position)))
    xform.AddOrientOp().Set(_quatf(orientation))


def _quatf(xyzw) -> Gf.Quatf:
    x, y, z, w = (float(c) for c in xyzw)
    return Gf.Quatf(w, x, y, z)


def _own_scale(prim: Usd.Prim) -> Gf.Vec3d:
    xformable = UsdGeom.Xformable(prim)
    for op in xformable.GetOrderedXformOps() if xformable else []:
        if op.GetOpType() == UsdGeom.XformOp.TypeScale:
            return Gf.Vec3d(*op.Get())
    return Gf.Vec3d(1.0, 1.0, 1.0)


def _set(prim: Usd.Prim, name: str, value_type, value) -> None:
    prim.CreateAttribute(name, value_type, custom=True).Set(value)


def _hull_faces(points: list[list[float]]) -> tuple[list[int], list[int]]:
    """The triangles of the points' convex hull (SciPy's Qhull) with outward normals; without
    SciPy, or for coplanar points, one polygon of the points in turn about their centre."""
    try:
        import numpy as np
        from scipy.spatial import ConvexHull

        array = np.asarray(points, dtype=np.float64)
        hull = ConvexHull(array)
        centre = array[hull.vertices].mean(axis=0)
        triangles = []
        for simplex in hull.simplices:
            a, b, c = array[simplex]
            if np.dot(np.cross(b - a, c - a), a - centre) < 0.0:
                simplex = simplex[::-1]
            triangles.extend(int(i) for i in simplex)
        return [3] * (len(triangles) // 3), triangles
    except Exception:
        return [len(points)], list(range(len(points)))


def _heightfield_mesh(shape: dict):
    heights = shape["heights"]
    sx, sy, sz = (float(c) for c in shape["scale"])
    rows, columns = len(heights), len(heights[0])
    vertices = []
    for i in range(rows):
        for j in range(columns):
            x = -sx / 2 + j * sx / (columns - 1)
            z = -sz / 2 + i * sz / (rows - 1)
            vertices.append(Gf.Vec3f(x, float(heights[i][j]) * sy, z))
    indices = []
    for i in range(rows - 1):
        for j in range(columns - 1):
            a, b = i * columns + j, i * columns + j + 1
            c, d = a + columns, b + columns
            indices += [a, c, b, b, c, d]
    return vertices, [3] * (len(indices) // 3), indices
