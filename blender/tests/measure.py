"""Reading poses back from Blender and measuring E from them (shared by the tests and
scripts/blender-compare.py).

E is measured from poses only, the same way for impulse's bake and Blender's own: the objects'
world poses at a frame are put into an impulse world of the same scene, whose ``quality()``
gives the largest overlap of any two bodies (Parry's contact query), the largest distance any
dynamic body moved from its initial position (drift) and the top body's sink.
"""

import numpy as np
from impulse_bake import axes, bake


def poses_at(scene, names, frame):
    """World positions (N, 3) and quaternions (N, 4, x y z w) in impulse's frame of the named
    objects at ``frame``."""
    scene.frame_set(frame)
    positions = np.empty((len(names), 3), dtype=np.float64)
    orientations = np.empty((len(names), 4), dtype=np.float64)
    for i, name in enumerate(names):
        location, rotation, _ = scene.objects[name].matrix_world.decompose()
        positions[i] = axes.vector_to_impulse(location)
        orientations[i] = axes.quaternion_to_impulse(rotation)
    return positions, orientations


def error_at_end(info, positions, orientations, static_scene):
    """E (m) of poses (N, 3) and (N, 4) of the bodies of ``info`` (a ``SceneInfo``) at the end:
    for a scene meant to stay at rest the largest of overlap, drift and top sink; else the
    overlap. Also returns the quality dict."""
    world, _ = bake.make_world(info.scene)
    initial = world.positions.copy()
    world.positions = positions
    world.orientations = orientations
    quality = world.quality(initial)
    error = quality["max_overlap_m"]
    if static_scene:
        error = max(error, quality["max_drift_m"] or 0.0, quality["top_sink_m"] or 0.0)
    return error, quality
