"""Blender's frame (z up) to impulse's (y up) and back.

The map is the proper rotation of −90° about x: a Blender vector (x, y, z) is the impulse
vector (x, z, −y). Quaternions rotate by conjugation with it, which maps their vector part the
same way. Every map here only permutes and negates components, so a pose survives the round trip
bit for bit.
"""

import numpy as np


def vector_to_impulse(v):
    """A Blender vector (x, y, z) as impulse's (x, z, −y), a list of 3 floats."""
    return [float(v[0]), float(v[2]), -float(v[1])]


def extents_to_impulse(v):
    """Non-negative extents along Blender's local x, y, z as extents along impulse's x, y, z."""
    return [float(v[0]), float(v[2]), float(v[1])]


def quaternion_to_impulse(q):
    """A Blender quaternion (w, x, y, z) as impulse's (x, y, z, w) in the y-up frame."""
    return [float(q[1]), float(q[3]), -float(q[2]), float(q[0])]


def positions_to_blender(positions):
    """impulse positions (..., 3) as Blender locations (..., 3): (x, y, z) → (x, −z, y)."""
    positions = np.asarray(positions)
    out = np.empty_like(positions)
    out[..., 0] = positions[..., 0]
    out[..., 1] = -positions[..., 2]
    out[..., 2] = positions[..., 1]
    return out


def orientations_to_blender(orientations):
    """impulse quaternions (..., 4) x y z w as Blender quaternions (..., 4) w x y z."""
    orientations = np.asarray(orientations)
    out = np.empty_like(orientations)
    out[..., 0] = orientations[..., 3]
    out[..., 1] = orientations[..., 0]
    out[..., 2] = -orientations[..., 2]
    out[..., 3] = orientations[..., 1]
    return out


def continuous_quaternions(quaternions):
    """Quaternions (F, N, 4) with signs chosen so that consecutive frames of a body have a
    non-negative dot product: q and −q are the same rotation, but Blender interpolates the
    components of keyframed quaternions, so a sign flip between frames would spin the object
    between them."""
    quaternions = np.array(quaternions, copy=True)
    if len(quaternions) < 2:
        return quaternions
    dots = np.einsum("fnk,fnk->fn", quaternions[1:], quaternions[:-1])
    flips = np.where(dots < 0, -1, 1).astype(np.int8)
    signs = np.cumprod(flips, axis=0)
    quaternions[1:] *= signs[..., None].astype(quaternions.dtype)
    return quaternions
