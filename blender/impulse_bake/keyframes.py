"""Writing a bake as keyframes: whole F-curves at once (``keyframe_points.add`` and one
``foreach_set`` per curve), never one ``keyframe_insert`` per frame.

Blender 4.4 put an action's F-curves in channel bags of slots; older versions keep them in
``action.fcurves``. Both are handled.
"""

import numpy as np

#: The channels a bake writes: (data path, number of components).
BAKED_CHANNELS = (("location", 3), ("rotation_quaternion", 4))


def _fcurve_collection(obj, create):
    """The F-curve collection of the object's action (made when ``create``), or None."""
    import bpy

    animation = obj.animation_data
    if animation is None:
        if not create:
            return None
        animation = obj.animation_data_create()
    action = animation.action
    if action is None:
        if not create:
            return None
        action = bpy.data.actions.new(f"{obj.name}Action")
        animation.action = action
    if not hasattr(action, "layers"):
        return action.fcurves
    slot = animation.action_slot
    if slot is None:
        if not create:
            return None
        slot = action.slots.new(id_type="OBJECT", name=obj.name)
        animation.action_slot = slot
    from bpy_extras import anim_utils

    if create:
        return anim_utils.action_ensure_channelbag_for_slot(action, slot).fcurves
    channelbag = anim_utils.action_get_channelbag_for_slot(action, slot)
    return None if channelbag is None else channelbag.fcurves


def remove_baked_fcurves(obj):
    """Remove the object's location and quaternion F-curves (what a bake writes)."""
    fcurves = _fcurve_collection(obj, create=False)
    if fcurves is None:
        return
    for path, count in BAKED_CHANNELS:
        for index in range(count):
            fcurve = fcurves.find(path, index=index)
            if fcurve is not None:
                fcurves.remove(fcurve)


def write_fcurves(obj, frames, locations, quaternions):
    """Key the object's location and rotation quaternion at ``frames`` (F,) with
    ``locations`` (F, 3) and ``quaternions`` (F, 4, w x y z), replacing those curves.

    Each curve gets its F points in one ``keyframe_points.add`` and its (frame, value) pairs in
    one ``foreach_set("co", ...)``; points are linear so that the pose between two frames is
    their interpolation, not a Bézier overshoot.
    """
    obj.rotation_mode = "QUATERNION"
    fcurves = _fcurve_collection(obj, create=True)
    frames = np.asarray(frames, dtype=np.float32)
    count = len(frames)
    co = np.empty((count, 2), dtype=np.float32)
    co[:, 0] = frames
    linear = None
    for path, values in (("location", locations), ("rotation_quaternion", quaternions)):
        values = np.asarray(values)
        for index in range(values.shape[1]):
            fcurve = fcurves.find(path, index=index)
            if fcurve is not None:
                fcurves.remove(fcurve)
            fcurve = fcurves.new(path, index=index)
            points = fcurve.keyframe_points
            points.add(count)
            co[:, 1] = values[:, index]
            points.foreach_set("co", co.ravel())
            if linear is None:
                linear = np.full(count, _linear_code(points[0]), dtype=np.int32)
            points.foreach_set("interpolation", linear)
            fcurve.update()


_LINEAR = None


def _linear_code(point):
    """The integer of the 'LINEAR' interpolation enum item (foreach_set takes enum values as
    their integers)."""
    global _LINEAR
    if _LINEAR is None:
        items = point.bl_rna.properties["interpolation"].enum_items
        _LINEAR = items["LINEAR"].value
    return _LINEAR
