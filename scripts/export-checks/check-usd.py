"""Checks a `.usda` written by `impulse run --out` with OpenUSD itself (the `usd-core` wheel):
the stage opens, passes every registered UsdValidation validator, has metres and y up, time codes
per second = 1/dt, one Xform per body with a shape child, and its translate and orient samples
at every written step equal the CSV trajectory of the same run.

Usage: python check-usd.py STAGE.usda TRAJECTORY.csv SCENE.json
"""

import sys

from pxr import Usd, UsdGeom, UsdValidation

from trajectory import Trajectory, body_kinds, body_names, close, same_rotation

TOLERANCE = 1e-6
SHAPES = {"Sphere", "Cube", "Capsule", "Mesh", "Cylinder", "Cone"}


def main(usda, csv_path, scene_path):
    trajectory = Trajectory(csv_path)
    names = body_names(scene_path)
    kinds = body_kinds(scene_path)
    stage = Usd.Stage.Open(usda)
    problems = []

    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(stage)
    for error in errors:
        problems.append(f"validator: {error.GetErrorAsString()}")

    if UsdGeom.GetStageMetersPerUnit(stage) != 1.0:
        problems.append(f"metersPerUnit {UsdGeom.GetStageMetersPerUnit(stage)}")
    if UsdGeom.GetStageUpAxis(stage) != UsdGeom.Tokens.y:
        problems.append(f"upAxis {UsdGeom.GetStageUpAxis(stage)}")
    fps = stage.GetTimeCodesPerSecond()
    if abs(fps * trajectory.dt() - 1.0) > 1e-5:
        problems.append(f"timeCodesPerSecond {fps} for dt {trajectory.dt()}")
    if (stage.GetStartTimeCode(), stage.GetEndTimeCode()) != (
        trajectory.steps[0],
        trajectory.steps[-1],
    ):
        problems.append(
            f"time codes {stage.GetStartTimeCode()}..{stage.GetEndTimeCode()}, "
            f"written steps {trajectory.steps[0]}..{trajectory.steps[-1]}"
        )

    world = stage.GetDefaultPrim()
    bodies = [p for p in world.GetChildren() if p.IsA(UsdGeom.Xform)]
    if len(bodies) != trajectory.bodies:
        problems.append(f"{len(bodies)} body Xforms, {trajectory.bodies} bodies")
    compared = 0
    for prim in bodies:
        index = prim.GetCustomDataByKey("bodyIndex")
        name = prim.GetCustomDataByKey("name")
        if name != names[index]:
            problems.append(f"{prim.GetPath()}: name {name!r}, scene says {names[index]!r}")
        shapes = [c.GetTypeName() for c in prim.GetChildren()]
        if len(shapes) != 1 or shapes[0] not in SHAPES:
            problems.append(f"{prim.GetPath()}: shape children {shapes}")
        xform = UsdGeom.Xformable(prim)
        ops = {op.GetOpName(): op for op in xform.GetOrderedXformOps()}
        translate = ops["xformOp:translate"].GetAttr()
        orient = ops["xformOp:orient"].GetAttr()
        samples = translate.GetTimeSamples()
        if kinds[index] != "static" and len(trajectory.steps) > 1:
            if samples != [float(s) for s in trajectory.steps]:
                problems.append(f"{prim.GetPath()}: {len(samples)} translate samples")
        for step in trajectory.steps:
            position, rotation = trajectory.frames[step][index]
            t = translate.Get(step)
            q = orient.Get(step)
            quaternion = (*q.GetImaginary(), q.GetReal())
            if not close(t, position, TOLERANCE) or not same_rotation(quaternion, rotation, TOLERANCE):
                problems.append(
                    f"{prim.GetPath()} at {step}: {tuple(t)} {quaternion}, "
                    f"CSV {position} {rotation}"
                )
            compared += 1
    for problem in problems[:20]:
        print(f"  {problem}")
    print(
        f"{usda}: {len(validators)} USD validators, {len(errors)} errors; "
        f"{len(bodies)} bodies, {compared} poses compared with the CSV, "
        f"{len(problems)} problems"
    )
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    sys.exit(main(*sys.argv[1:]))
