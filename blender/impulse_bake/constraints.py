"""Blender rigid body constraints as impulse joints (the scene format's ``joints`` entries,
docs/scene-format.md, "Joints"), without any UI.

What maps to what (Blender's constraint frame is the constraint object's world matrix at the
first frame, placed on both bodies, as Blender does):

- ``FIXED`` → ``fixed``; ``POINT`` → ``spherical``; both at the object's world location;
- ``HINGE`` → ``revolute`` about the object's local Z axis; "Z Angle" limits (``use_limit_ang_z``)
  become the hinge's limits negated and swapped, [−upper, −lower]: Bullet's hinge angle
  (``btHingeConstraint::getHingeAngle``) is B's rotation relative to A clockwise about the axis,
  impulse's counter-clockwise;
- ``SLIDER`` → ``prismatic`` along the object's local X axis, with the "X" limits
  (``use_limit_lin_x``, m, B's position relative to A's);
- ``PISTON`` → ``generic`` along and about the local X axis: ``linear_x`` and ``angular_x`` free
  or limited, the other four locked;
- ``GENERIC`` and ``GENERIC_SPRING`` → ``generic`` with its x axis the object's local X; each of
  the six degrees of freedom is free without its ``use_limit_*``, locked when its limits are
  both 0, and limited otherwise (Bullet's rule: lower > upper is free). ``GENERIC_SPRING``'s
  linear springs become springs of the frequency and damping ratio a stiffness k (N/m) and
  damping c (N·s/m) give on the two bodies' reduced mass m: f = √(k/m)/2π, ζ = c/(2√(k·m)),
  rest position 0 (Bullet's equilibrium is the pose at the first frame);
- ``MOTOR`` → ``generic`` with every degree of freedom free and velocity motors on ``linear_x``
  and ``angular_x`` (``use_motor_lin``, ``use_motor_ang``);
- ``disable_collisions`` → ``collide_connected`` = not it; ``object1``/``object2`` → body A/B;
- Breaking: Bullet breaks a constraint when one of its rows' impulse in one Bullet substep reaches
  ``breaking_threshold`` (N·s). impulse's strength is a force (N) and torque (N·m) measured over
  a window (s), so the threshold becomes force = torque = threshold / h over a window of h,
  with h = time_scale / (fps · substeps_per_frame), Bullet's substep (s): a steady load breaks
  the joint at threshold / h as in Bullet, and a blow when its impulse reaches the threshold,
  however many of impulse's shorter substeps carry it. A motor's "max impulse" converts to a
  force the same way.

Settings impulse cannot follow (a disabled constraint, solver-iteration overrides, angular
springs, a generic frame whose y and z axes impulse cannot reproduce, a constraint on a body
that is not simulated) are reported as warnings naming the constraint object, never silently
dropped.
"""

import math

import mathutils

from . import axes

#: Limits closer than this (m or rad) to 0 count as 0 (a locked degree of freedom).
ZERO_LIMIT = 1e-9

#: Degree-of-freedom names of the scene format with Blender's suffix of its settings.
DOFS = (
    ("linear_x", "lin_x"),
    ("linear_y", "lin_y"),
    ("linear_z", "lin_z"),
    ("angular_x", "ang_x"),
    ("angular_y", "ang_y"),
    ("angular_z", "ang_z"),
)


def bullet_substep(scene):
    """Bullet's substep (s) in Blender's Rigid Body World: time_scale / (fps ·
    substeps_per_frame)."""
    world = scene.rigidbody_world
    fps = scene.render.fps / scene.render.fps_base
    return world.time_scale / (fps * max(int(world.substeps_per_frame), 1))


def _axis(matrix, column):
    """The constraint object's local axis ``column`` (0 x, 1 y, 2 z) in impulse's world frame,
    unit length."""
    rotation = matrix.to_quaternion()
    local = mathutils.Vector([1.0 if i == column else 0.0 for i in range(3)])
    return axes.vector_to_impulse(rotation @ local)


def _limit(constraint, suffix):
    """(lower, upper) of ``use_limit_<suffix>``, or None when the limit is off."""
    if not getattr(constraint, f"use_limit_{suffix}"):
        return None
    return (
        float(getattr(constraint, f"limit_{suffix}_lower")),
        float(getattr(constraint, f"limit_{suffix}_upper")),
    )


def _dof_mode(limits):
    """A scene-format degree of freedom from Bullet's limits: free without limits or with
    lower > upper, locked at (0, 0), else limited."""
    if limits is None or limits[0] > limits[1]:
        return "free"
    if abs(limits[0]) <= ZERO_LIMIT and abs(limits[1]) <= ZERO_LIMIT:
        return "locked"
    return {"limits": [limits[0], limits[1]]}


def _reduced_mass(masses):
    """The effective mass (kg) of a row between two bodies: m_a·m_b/(m_a + m_b), a static
    body's mass counting as infinite."""
    finite = [m for m in masses if m is not None]
    if not finite:
        return None
    if len(finite) == 1:
        return finite[0]
    return finite[0] * finite[1] / (finite[0] + finite[1])


def _frame_twisted(matrix):
    """Whether the constraint object's frame differs from the one impulse builds from its X
    axis alone (the shortest rotation from x to it) by a turn about X: then impulse's y and z
    axes are not Blender's."""
    x_axis = mathutils.Vector(_axis(matrix, 0))
    y_axis = mathutils.Vector(_axis(matrix, 1))
    built = mathutils.Vector((1.0, 0.0, 0.0)).rotation_difference(x_axis)
    return (built @ mathutils.Vector((0.0, 1.0, 0.0)) - y_axis).length > 1e-4


def _generic_dofs(constraint, name, warnings, masses):
    dofs = {}
    for dof, suffix in DOFS:
        dofs[dof] = _dof_mode(_limit(constraint, suffix))
    if constraint.type == "GENERIC_SPRING":
        if constraint.spring_type == "SPRING1":
            warnings.append(
                f"{name}: Blender 2.7 springs (SPRING1) damp differently; their damping is read "
                "as SPRING2's damping coefficient (N·s/m)"
            )
        mass = _reduced_mass(masses)
        for dof, suffix in DOFS:
            axis_suffix = suffix.replace("lin_", "")
            if not getattr(constraint, f"use_spring_{axis_suffix}", False):
                continue
            if dof.startswith("angular"):
                warnings.append(f"{name}: the angular spring on {dof} is not supported (dropped)")
                continue
            stiffness = float(getattr(constraint, f"spring_stiffness_{axis_suffix}"))
            damping = float(getattr(constraint, f"spring_damping_{axis_suffix}"))
            if dofs[dof] == "locked" or stiffness <= 0 or mass is None:
                warnings.append(f"{name}: the spring on {dof} acts on a locked axis or has no stiffness (dropped)")
                continue
            spring = {
                "hertz": math.sqrt(stiffness / mass) / (2 * math.pi),
                "damping_ratio": max(damping, 0.0) / (2 * math.sqrt(stiffness * mass)),
                "rest": 0.0,
            }
            if dofs[dof] == "free":
                dofs[dof] = {"spring": spring}
            else:
                dofs[dof]["spring"] = spring
    return dofs


def _motor_dofs(constraint, substep):
    dofs = {dof: "free" for dof, _ in DOFS}
    if constraint.use_motor_lin:
        dofs["linear_x"] = {
            "motor": {
                "velocity": float(constraint.motor_lin_target_velocity),
                "max_force": float(constraint.motor_lin_max_impulse) / substep,
            }
        }
    if constraint.use_motor_ang:
        dofs["angular_x"] = {
            "motor": {
                "velocity": float(constraint.motor_ang_target_velocity),
                "max_force": float(constraint.motor_ang_max_impulse) / substep,
            }
        }
    return dofs


def read_constraints(scene, bodies, masses):
    """The scene's Rigid Body World constraints as scene-format joints.

    ``bodies`` maps an object name to its impulse body kind (``"dynamic"``, ``"static"``,
    ``"kinematic"``) for the bodies read; ``masses`` maps a dynamic body's object name to its
    mass (kg). Returns (joints, warnings): the list of joint dicts, sorted by constraint object
    name, and one message per setting impulse does not follow, each starting with the
    constraint object's name. Constraint objects are read at the scene's current frame.
    """
    world = scene.rigidbody_world
    collection = world.constraints
    if collection is None:
        return [], []
    substep = bullet_substep(scene)
    joints, warnings = [], []
    objects = {o.name: o for o in collection.all_objects if o.rigid_body_constraint is not None}
    for name in sorted(objects):
        obj = objects[name]
        constraint = obj.rigid_body_constraint
        if not constraint.enabled:
            warnings.append(f"{name}: the constraint is disabled (not exported)")
            continue
        ends = [constraint.object1, constraint.object2]
        if any(end is None or end.name not in bodies for end in ends):
            warnings.append(f"{name}: the constraint needs two objects of the Rigid Body World (not exported)")
            continue
        if all(bodies[end.name] != "dynamic" for end in ends):
            warnings.append(f"{name}: neither object is dynamic (not exported)")
            continue
        if constraint.use_override_solver_iterations:
            warnings.append(f"{name}: the solver iterations override is ignored")
        matrix = obj.matrix_world
        joint = {
            "name": name,
            "body_a": ends[0].name,
            "body_b": ends[1].name,
            "anchor": axes.vector_to_impulse(matrix.to_translation()),
            "collide_connected": not constraint.disable_collisions,
        }
        kind = constraint.type
        if kind == "FIXED":
            joint["type"] = "fixed"
        elif kind == "POINT":
            joint["type"] = "spherical"
        elif kind == "HINGE":
            joint["type"] = "revolute"
            joint["axis"] = _axis(matrix, 2)
            limits = _limit(constraint, "ang_z")
            if limits is not None and limits[0] <= limits[1]:
                joint["limits"] = [-limits[1], -limits[0]]
        elif kind == "SLIDER":
            joint["type"] = "prismatic"
            joint["axis"] = _axis(matrix, 0)
            limits = _limit(constraint, "lin_x")
            if limits is not None and limits[0] <= limits[1]:
                joint["limits"] = list(limits)
        elif kind == "PISTON":
            joint["type"] = "generic"
            joint["axis"] = _axis(matrix, 0)
            joint["dofs"] = {
                "linear_x": _dof_mode(_limit(constraint, "lin_x")),
                "angular_x": _dof_mode(_limit(constraint, "ang_x")),
            }
        elif kind in ("GENERIC", "GENERIC_SPRING"):
            joint["type"] = "generic"
            joint["axis"] = _axis(matrix, 0)
            end_masses = [masses.get(end.name) for end in ends]
            joint["dofs"] = _generic_dofs(constraint, name, warnings, end_masses)
            modes = joint["dofs"]
            if _frame_twisted(matrix) and (
                modes["linear_y"] != modes["linear_z"] or modes["angular_y"] != modes["angular_z"]
            ):
                warnings.append(
                    f"{name}: the object's frame is turned about its X axis: impulse places the "
                    "y and z limits about the shortest rotation from x to it, not the object's Y "
                    "and Z"
                )
        elif kind == "MOTOR":
            joint["type"] = "generic"
            joint["axis"] = _axis(matrix, 0)
            joint["dofs"] = _motor_dofs(constraint, substep)
        else:
            warnings.append(f"{name}: the {kind.lower()} constraint type is not supported")
            continue
        if constraint.use_breaking:
            strength = float(constraint.breaking_threshold) / substep
            joint["break_force"] = strength
            joint["break_torque"] = strength
            joint["break_window"] = substep
        joints.append(joint)
    return joints, warnings
