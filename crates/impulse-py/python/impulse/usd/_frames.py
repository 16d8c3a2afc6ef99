"""Units, axes and rigid frames between a stage and a scene.

A stage measures lengths in its ``metersPerUnit`` and masses in its ``kilogramsPerUnit``, and
has y or z up; a scene is SI with y up. The stage's frame turns into the scene's by the
rotation ``UP`` (identity for a y-up stage, −90° about x for a z-up one: (x, y, z) →
(x, z, −y)). World quantities (positions, orientations, velocities, gravity) turn with it;
quantities in a body's own frame (shape sizes, anchors, axes) only change units.

Quaternions are ``Gf.Quatd`` here and ``[x, y, z, w]`` lists in scenes.
"""

from __future__ import annotations

import math

from pxr import Gf

IDENTITY = Gf.Quatd(1.0, 0.0, 0.0, 0.0)


def up_rotation(up_axis: str) -> Gf.Quatd:
    """The rotation taking the stage's frame to the scene's (y up)."""
    if up_axis == "Z":
        half = math.sqrt(0.5)
        return Gf.Quatd(half, -half, 0.0, 0.0)
    return Gf.Quatd(IDENTITY)


def quat(q: object) -> Gf.Quatd:
    """A ``Gf.Quatd`` from a ``Gf.Quatf``, ``Gf.Quath`` or ``Gf.Quatd``."""
    imaginary = q.GetImaginary()
    return Gf.Quatd(float(q.GetReal()), float(imaginary[0]), float(imaginary[1]), float(imaginary[2]))


def from_xyzw(values) -> Gf.Quatd:
    """A ``Gf.Quatd`` from a scene's ``[x, y, z, w]``."""
    x, y, z, w = (float(value) for value in values)
    return Gf.Quatd(w, x, y, z)


def xyzw(q: Gf.Quatd) -> list[float]:
    """A scene's ``[x, y, z, w]`` of a quaternion, as it is (a scene's numbers come back to
    the bit; impulse normalises when it builds the world)."""
    imaginary = q.GetImaginary()
    return [float(imaginary[0]), float(imaginary[1]), float(imaginary[2]), float(q.GetReal())]


def rotate(q: Gf.Quatd, v) -> Gf.Vec3d:
    """``v`` turned by ``q``."""
    return Gf.Vec3d(q.Transform(Gf.Vec3d(*(float(c) for c in v))))


def is_identity(q: Gf.Quatd, tolerance: float = 0.0) -> bool:
    """Whether ``q`` is the identity rotation (either sign), to ``tolerance``."""
    imaginary = q.GetImaginary()
    return max(abs(c) for c in imaginary) <= tolerance and abs(abs(q.GetReal()) - 1.0) <= tolerance


def axis_rotation(axis: str) -> Gf.Quatd:
    """The rotation taking local y to the stage axis token ``axis`` (``"X"``, ``"Y"``, ``"Z"``):
    the frame in which a capsule, cylinder or cone along ``axis`` lies along y as a scene's do."""
    half = math.sqrt(0.5)
    if axis == "X":
        return Gf.Quatd(half, 0.0, 0.0, -half)  # −90° about z: y → x
    if axis == "Z":
        return Gf.Quatd(half, half, 0.0, 0.0)  # +90° about x: y → z
    return Gf.Quatd(IDENTITY)


def x_to_axis(axis: str) -> Gf.Quatd:
    """The rotation taking local x to the stage axis token ``axis``: a joint frame whose x is
    the joint's axis, as a scene's joint frames are."""
    half = math.sqrt(0.5)
    if axis == "Y":
        return Gf.Quatd(half, 0.0, 0.0, half)  # +90° about z: x → y
    if axis == "Z":
        return Gf.Quatd(half, 0.0, -half, 0.0)  # −90° about y: x → z
    return Gf.Quatd(IDENTITY)


def axis_vector(axis: str) -> Gf.Vec3d:
    """The unit vector of an axis token."""
    return Gf.Vec3d(*(1.0 if name == axis else 0.0 for name in "XYZ"))


def twist_angle(q: Gf.Quatd, axis) -> float:
    """The angle (rad) of ``q``'s twist about the unit ``axis`` (swing-twist decomposition), in
    (−π, π]."""
    imaginary = q.GetImaginary()
    along = imaginary[0] * axis[0] + imaginary[1] * axis[1] + imaginary[2] * axis[2]
    angle = 2.0 * math.atan2(along, q.GetReal())
    return wrap_angle(angle)


def wrap_angle(angle: float) -> float:
    """``angle`` (rad) wrapped into (−π, π]."""
    wrapped = math.remainder(angle, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def rigid_from_matrix(matrix: Gf.Matrix4d) -> tuple[Gf.Vec3d, Gf.Quatd, Gf.Vec3d, bool]:
    """Translation, rotation and scale of a world matrix (row vectors, USD's convention), and
    whether it has shear (a scale along axes turned against the rotation's)."""
    transform = Gf.Transform(matrix)
    scale = Gf.Vec3d(transform.GetScale())
    pivot = transform.GetPivotOrientation().GetQuat()
    uniform = max(abs(scale[i] - scale[0]) for i in range(3)) <= 1e-9 * max(1.0, abs(scale[0]))
    shear = not uniform and not is_identity(pivot, 1e-9)
    rotation = Gf.Quatd(transform.GetRotation().GetQuat())
    if rotation.GetReal() < 0.0:
        rotation = Gf.Quatd(-rotation.GetReal(), -rotation.GetImaginary())
    return Gf.Vec3d(transform.GetTranslation()), rotation, scale, shear


def matrix_from_rigid(position, rotation: Gf.Quatd, scale=(1.0, 1.0, 1.0)) -> Gf.Matrix4d:
    """The matrix (row vectors) of scale, then rotation, then translation."""
    scale_matrix = Gf.Matrix4d(1.0).SetScale(Gf.Vec3d(*scale))
    rigid = Gf.Matrix4d(1.0).SetRotateOnly(Gf.Rotation(rotation))
    rigid.SetTranslateOnly(Gf.Vec3d(*position))
    return scale_matrix * rigid


def trs_from_matrix(matrix: Gf.Matrix4d, tolerance: float = 1e-6):
    """A local matrix (row vectors) as translate, orient and scale ops, scale first: its rows
    are the scaled rows of a rotation. None when it is no such product (a shear, a
    reflection) to ``tolerance`` (relative)."""
    rows = [Gf.Vec3d(matrix[i][0], matrix[i][1], matrix[i][2]) for i in range(3)]
    scale = [row.GetLength() for row in rows]
    if min(scale) <= 0.0:
        return None
    rotation = Gf.Matrix3d(*(c / scale[i] for i in range(3) for c in rows[i]))
    product = rotation * rotation.GetTranspose()
    identity = Gf.Matrix3d(1.0)
    error = max(abs(product[i][j] - identity[i][j]) for i in range(3) for j in range(3))
    if error > tolerance or rotation.GetDeterminant() <= 0.0:
        return None
    quaternion = Gf.Quatd(rotation.ExtractRotation().GetQuat())
    translation = Gf.Vec3d(matrix[3][0], matrix[3][1], matrix[3][2])
    return translation, quaternion, Gf.Vec3d(*scale)


def shortest_arc(axis) -> Gf.Quatd:
    """The rotation taking x to the unit ``axis`` as impulse builds a joint frame from an axis
    (glam's ``Quat::from_rotation_arc``: for −x, half a turn about y)."""
    axis = Gf.Vec3d(*axis)
    dot = axis[0]
    if dot > 1.0 - 1e-6:
        return Gf.Quatd(IDENTITY)
    if dot < -1.0 + 1e-6:
        return Gf.Quatd(0.0, 0.0, 1.0, 0.0)
    cross = Gf.Cross(Gf.Vec3d(1.0, 0.0, 0.0), axis)
    return Gf.Quatd(1.0 + dot, cross).GetNormalized()
