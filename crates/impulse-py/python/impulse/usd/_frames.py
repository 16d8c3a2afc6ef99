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

import numpy as np
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


# Arrays of quaternions (…, 4) as x y z w, for whole trajectories at once.


def quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The products a·b of quaternions (…, 4), x y z w."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
    av, aw = a[..., :3], a[..., 3:]
    bv, bw = b[..., :3], b[..., 3:]
    vector = aw * bv + bw * av + np.cross(av, bv)
    scalar = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([vector, scalar], axis=-1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors (…, 3) turned by unit quaternions (…, 4), x y z w."""
    q = np.asarray(q, dtype=np.float64)
    u, w = q[..., :3], q[..., 3:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrices (…, 3, 3) of quaternions (…, 4), x y z w, normalised first
    (column vectors: R·v)."""
    q = np.asarray(q, dtype=np.float64)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def matrix_quat(r: np.ndarray) -> np.ndarray:
    """Unit quaternions (…, 4), x y z w, of rotation matrices (…, 3, 3) (column vectors), by
    the largest of the four diagonal combinations (Shepperd's method)."""
    r = np.asarray(r, dtype=np.float64)
    trace = r[..., 0, 0] + r[..., 1, 1] + r[..., 2, 2]
    candidates = np.stack([trace, r[..., 0, 0], r[..., 1, 1], r[..., 2, 2]], axis=-1)
    pick = np.argmax(candidates, axis=-1)
    q = np.empty(r.shape[:-2] + (4,))
    for case in range(4):
        mask = pick == case
        m = r[mask]
        if case == 0:
            s = np.sqrt(1.0 + m[:, 0, 0] + m[:, 1, 1] + m[:, 2, 2]) * 2.0
            values = [(m[:, 2, 1] - m[:, 1, 2]) / s, (m[:, 0, 2] - m[:, 2, 0]) / s, (m[:, 1, 0] - m[:, 0, 1]) / s, 0.25 * s]
        elif case == 1:
            s = np.sqrt(1.0 + m[:, 0, 0] - m[:, 1, 1] - m[:, 2, 2]) * 2.0
            values = [0.25 * s, (m[:, 0, 1] + m[:, 1, 0]) / s, (m[:, 0, 2] + m[:, 2, 0]) / s, (m[:, 2, 1] - m[:, 1, 2]) / s]
        elif case == 2:
            s = np.sqrt(1.0 + m[:, 1, 1] - m[:, 0, 0] - m[:, 2, 2]) * 2.0
            values = [(m[:, 0, 1] + m[:, 1, 0]) / s, 0.25 * s, (m[:, 1, 2] + m[:, 2, 1]) / s, (m[:, 0, 2] - m[:, 2, 0]) / s]
        else:
            s = np.sqrt(1.0 + m[:, 2, 2] - m[:, 0, 0] - m[:, 1, 1]) * 2.0
            values = [(m[:, 0, 2] + m[:, 2, 0]) / s, (m[:, 1, 2] + m[:, 2, 1]) / s, 0.25 * s, (m[:, 1, 0] - m[:, 0, 1]) / s]
        q[mask] = np.stack(values, axis=-1)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def trs_from_matrices(matrices: np.ndarray, tolerance: float = 1e-6):
    """Local matrices (F, 4, 4; row vectors) as translate (F, 3), orient (F, 4, x y z w) and one
    scale (3,), scale first: when every matrix's rows are the scaled rows of a rotation, by the
    same scale. None when any is no such product (a shear, a reflection, a changing scale) to
    ``tolerance`` (relative)."""
    linear = matrices[:, :3, :3]
    scale = np.linalg.norm(linear, axis=-1)  # (F, 3): the rows' lengths
    if np.min(scale) <= 0.0 or np.max(np.abs(scale - scale[0])) > tolerance * np.max(scale):
        return None
    rows = linear / scale[:, :, None]
    error = np.abs(rows @ np.transpose(rows, (0, 2, 1)) - np.eye(3)).max()
    if error > tolerance or np.min(np.linalg.det(rows)) <= 0.0:
        return None
    # Row vectors: p·Rᵀ is R·p, so the rows form Rᵀ.
    rotations = matrix_quat(np.transpose(rows, (0, 2, 1)))
    return matrices[:, 3, :3].copy(), rotations, scale[0]
