"""A stage's simulation written back as a layer of time samples over it."""

from __future__ import annotations

import os

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics

from . import _frames as frames
from ._read import open_stage, stage_to_scene
from ._report import Report

#: The names of the baked transform ops: their own suffix, so they never clash in type with
#: a prim's authored ops (a ``float3`` translate against a ``double3`` one).
TRANSLATE_OP = "xformOp:translate:impulse"
ORIENT_OP = "xformOp:orient:impulse"
SCALE_OP = "xformOp:scale:impulse"
TRANSFORM_OP = "xformOp:transform:impulse"


def bake(
    source: str | os.PathLike | Usd.Stage,
    out: str | os.PathLike,
    *,
    steps: int | None = None,
    every: int | None = None,
    settings=None,
) -> Report:
    """Simulates a UsdPhysics stage with impulse and writes the motion as a layer over it.

    The layer at ``out`` (``.usda`` or ``.usdc``) has the input stage's root layer as its
    sublayer, the same ``upAxis``, ``metersPerUnit``, ``kilogramsPerUnit``,
    ``timeCodesPerSecond`` and ``framesPerSecond``, and on every prim of a moving body an
    ``over`` with time-sampled ``xformOp:translate:impulse`` (stage units),
    ``xformOp:orient:impulse`` (a ``quatf``) and, for a scaled prim,
    ``xformOp:scale:impulse``, with an ``xformOpOrder`` of just those, so the prim's own ops
    are replaced and not composed with; a prim whose local transform would shear is given one
    ``xformOp:transform:impulse`` matrix instead. Opening ``out`` plays the simulation.

    Samples sit on the stage's time codes: step k at ``startTimeCode + k·dt·timeCodesPerSecond``,
    every ``every``-th step (default: one sample per time code when the time step divides
    the frame, else every step) and the last. ``steps`` as in ``stage_to_scene``;
    ``settings`` replaces the solver settings (a preset name or ``impulse.Settings``, as
    ``World.from_scene``). Returns the reader's report.

    Raises what ``stage_to_scene`` and ``impulse.World.from_scene`` raise (``SceneError`` for
    a stage whose scene impulse refuses, naming the body's prim path), and ``StepError`` for
    a failed step.
    """
    import impulse

    stage = open_stage(source)
    _check_source(stage)
    scene, report = stage_to_scene(stage, steps=steps)
    world = (
        impulse.World.from_scene(scene)
        if settings is None
        else impulse.World.from_scene(scene, settings=settings)
    )
    dt = float(world.dt)
    count = int(scene.get("steps", 600))
    if every is None:
        per_code = 1.0 / (dt * report.time_codes_per_second)
        every = round(per_code) if abs(per_code - round(per_code)) < 1e-4 and per_code >= 1 else 1
    trajectory = world.simulate(count, every=max(1, int(every)))
    write_layer(stage, out, report, trajectory.steps, trajectory.positions, trajectory.orientations, dt)
    return report


def write_layer(stage, out, report: Report, step_numbers, positions, orientations, dt) -> None:
    """Writes the baked layer: ``positions`` (F, N, 3) m and ``orientations`` (F, N, 4) x y z w
    of the scene's bodies at ``step_numbers`` (F,), each step ``dt`` seconds."""
    out = os.fspath(out)
    _check_source(stage)
    root = stage.GetRootLayer()
    layer = Sdf.Layer.CreateNew(out)
    if layer is None:
        raise ValueError(f"{out}: cannot create a layer there")
    layer.subLayerPaths.append(_relative_path(root, out))
    baked = Usd.Stage.Open(layer)
    UsdGeom.SetStageUpAxis(baked, report.up_axis)
    UsdGeom.SetStageMetersPerUnit(baked, report.meters_per_unit)
    if UsdPhysics.StageHasAuthoredKilogramsPerUnit(stage):
        UsdPhysics.SetStageKilogramsPerUnit(baked, report.kilograms_per_unit)
    tcps = report.time_codes_per_second
    baked.SetTimeCodesPerSecond(tcps)
    baked.SetFramesPerSecond(stage.GetFramesPerSecond())
    # A step of a whole fraction of a frame (1/60 s at 60 per second, stored as the f32
    # 0.016666668) puts whole frames on whole time codes, not on 120.0000096.
    per_code = 1.0 / (dt * tcps)
    step_code = 1.0 / round(per_code) if abs(per_code - round(per_code)) < 1e-4 * per_code else dt * tcps
    codes = [round(report.start_time_code + float(k) * step_code, 9) for k in step_numbers]
    baked.SetStartTimeCode(report.start_time_code)
    baked.SetEndTimeCode(codes[-1] if codes else report.start_time_code)
    if root.defaultPrim:
        layer.defaultPrim = root.defaultPrim

    L = report.meters_per_unit
    inverse_up = np.array(frames.xyzw(frames.up_rotation(report.up_axis).GetInverse()))
    start_cache = UsdGeom.XformCache(
        Usd.TimeCode(report.start_time_code) if stage.HasAuthoredTimeCodeRange() else Usd.TimeCode.Default()
    )
    moving = [b for b in report.bodies if b.moves and b.path]
    moving_paths = {b.path: b for b in moving}
    positions = np.asarray(positions, dtype=np.float64)
    orientations = np.asarray(orientations, dtype=np.float64)
    worlds: dict[str, np.ndarray] = {}

    def world_matrices(body) -> np.ndarray:
        """The body prim's world matrices (F, 4, 4; row vectors, stage units and axes) at the
        written frames: the body's poses less its offset, turned back into the stage's frame,
        times the prim's scale."""
        if body.path not in worlds:
            prim = baked.GetPrimAtPath(body.path)
            scale = np.array(frames.rigid_from_matrix(start_cache.GetLocalToWorldTransform(prim))[2])
            offset = np.array(body.offset_orientation, dtype=np.float64)
            offset_inverse = offset * np.array([-1.0, -1.0, -1.0, 1.0])
            prim_rotation = frames.quat_multiply(orientations[:, body.index], offset_inverse)
            prim_position = positions[:, body.index] - frames.quat_rotate(
                prim_rotation, np.array(body.offset_position, dtype=np.float64)
            )
            stage_rotation = frames.quat_multiply(inverse_up, prim_rotation)
            stage_position = frames.quat_rotate(inverse_up, prim_position) / L
            matrices = np.zeros((len(stage_rotation), 4, 4))
            # Row vectors: a point p maps to p·S·R + t, so the rows are the scaled rows of Rᵀ.
            matrices[:, :3, :3] = scale[None, :, None] * np.transpose(frames.quat_matrix(stage_rotation), (0, 2, 1))
            matrices[:, 3, :3] = stage_position
            matrices[:, 3, 3] = 1.0
            worlds[body.path] = matrices
        return worlds[body.path]

    def moving_ancestor(prim):
        parent = prim.GetParent()
        while parent and not parent.IsPseudoRoot():
            if str(parent.GetPath()) in moving_paths:
                return parent
            parent = parent.GetParent()
        return None

    for body in moving:
        prim = baked.GetPrimAtPath(body.path)
        if prim.IsInstanceProxy():
            report.add(
                body.path,
                "dropped",
                "the bake cannot write over a prim inside an instance: its motion is not written "
                "(make its instanceable ancestor not instanceable)",
            )
            continue
        xformable = UsdGeom.Xformable(prim)
        resets = bool(xformable) and xformable.GetResetXformStack()
        parent = prim.GetParent()
        ancestor = None if resets else moving_ancestor(prim)
        static_parent = np.array(
            Gf.Matrix4d(1.0) if resets or parent.IsPseudoRoot() else start_cache.GetLocalToWorldTransform(parent)
        )
        if ancestor is None:
            parent_worlds = static_parent[None]
        else:
            # What lies between the moving ancestor and the parent moves with the ancestor.
            ancestor_start = np.array(start_cache.GetLocalToWorldTransform(ancestor))
            between = static_parent @ np.linalg.inv(ancestor_start)
            parent_worlds = between[None] @ world_matrices(moving_paths[str(ancestor.GetPath())])
        local = world_matrices(body) @ np.linalg.inv(parent_worlds)
        # One change notice for all of a prim's samples, not one per sample.
        with Sdf.ChangeBlock():
            _author(prim, local, codes, resets)
    layer.Save()


def _check_source(stage) -> None:
    """The baked layer sublayers the stage's file: it must have one, saved."""
    root = stage.GetRootLayer()
    if root.anonymous or not root.realPath:
        raise ValueError("the stage has no file to sublayer: save it (stage.Export(path)) and bake the file")
    if root.dirty:
        raise ValueError(f"{root.realPath}: the stage has unsaved changes, which the baked layer would not see: save it first")


def _author(prim, local: np.ndarray, codes, resets) -> None:
    """Authors one prim's baked ops from its local matrices (F, 4, 4): translate, orient and
    scale when every sample's rows are the scaled rows of a rotation, else a matrix."""
    xformable = UsdGeom.Xformable(prim)
    order = ["!resetXformStack!"] if resets else []
    decomposed = frames.trs_from_matrices(local)
    if decomposed is None:
        attribute = prim.CreateAttribute(TRANSFORM_OP, Sdf.ValueTypeNames.Matrix4d, custom=False)
        for code, matrix in zip(codes, local, strict=True):
            attribute.Set(Gf.Matrix4d(matrix.tolist()), Usd.TimeCode(code))
        order.append(TRANSFORM_OP)
    else:
        translations, rotations, scale = decomposed
        # Each sample in the hemisphere of the one before, so that tools interpolating
        # quaternions component by component turn the short way.
        for k in range(1, len(rotations)):
            if np.dot(rotations[k], rotations[k - 1]) < 0.0:
                rotations[k] = -rotations[k]
        translate = prim.CreateAttribute(TRANSLATE_OP, Sdf.ValueTypeNames.Double3, custom=False)
        orient = prim.CreateAttribute(ORIENT_OP, Sdf.ValueTypeNames.Quatf, custom=False)
        for code, position, (x, y, z, w) in zip(codes, translations.tolist(), rotations.tolist(), strict=True):
            time = Usd.TimeCode(code)
            translate.Set(Gf.Vec3d(*position), time)
            orient.Set(Gf.Quatf(w, x, y, z), time)
        order += [TRANSLATE_OP, ORIENT_OP]
        if np.max(np.abs(scale - 1.0)) > 1e-9:
            prim.CreateAttribute(SCALE_OP, Sdf.ValueTypeNames.Float3, custom=False).Set(Gf.Vec3f(*scale.tolist()))
            order.append(SCALE_OP)
    xformable.GetXformOpOrderAttr().Set(order)


def _relative_path(root: Sdf.Layer, out: str) -> str:
    """The input's root layer as the baked layer's sublayer path: relative to the baked file
    when both are files, else the layer's identifier."""
    source = root.realPath
    if not source:
        return root.identifier
    relative = os.path.relpath(source, os.path.dirname(os.path.abspath(out)) or ".")
    return relative.replace(os.sep, "/")
