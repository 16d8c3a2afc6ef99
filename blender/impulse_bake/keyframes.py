"""Writing a bake as keyframes and removing it again: whole F-curves at once
(``keyframe_points.add`` and one ``foreach_set`` per curve), never one ``keyframe_insert`` per
frame.

The baked curves are the object's location and the rotation channel of its own rotation mode
(quaternion, Euler or axis-angle: the mode is left as the animator set it), in the F-curve group
:data:`GROUP`, which marks them as the bake's. An object whose transform the animator keyed (a
thrown object, animated and then simulated) keeps that animation: the bake goes into a copy of
its action, which names the original (:data:`ORIGINAL`), and freeing the bake puts the original
back. An action the bake made is marked :data:`MADE` and removed with the bake.

Blender 4.4 put an action's F-curves in channel bags of slots; older versions keep them in
``action.fcurves``. Both are handled.
"""

import numpy as np

#: The F-curve group of a bake's curves.
GROUP = "Impulse Bake"

#: Custom property of a bake's copy of an animated object's action: the original's name.
ORIGINAL = "impulse_original_action"

#: Custom property of an action a bake made.
MADE = "impulse_bake"

#: Custom property of a baked object: its own location and rotation channels at the start
#: frame as the animator set them (data path → values), put back when the bake is freed and
#: read as its start while it shows the bake's start unchanged. A take's bake keys a varied
#: start, so the bake's first key is not the animator's pose.
AUTHORED = "impulse_authored_start"

#: The channels a bake may write: (data path, number of components).
TRANSFORM_CHANNELS = (
    ("location", 3),
    ("rotation_quaternion", 4),
    ("rotation_euler", 3),
    ("rotation_axis_angle", 4),
)


def _channelbag(obj, create):
    """The F-curve owner of the object's action: the channel bag of its slot (Blender 4.4+)
    or the action (made when ``create``), or None."""
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
        action[MADE] = 1
        animation.action = action
    if not hasattr(action, "layers"):
        return action
    slot = animation.action_slot
    if slot is None:
        if not create:
            return None
        slot = action.slots.new(id_type="OBJECT", name=obj.name)
        animation.action_slot = slot
    from bpy_extras import anim_utils

    if create:
        return anim_utils.action_ensure_channelbag_for_slot(action, slot)
    return anim_utils.action_get_channelbag_for_slot(action, slot)


def _fcurve_collection(obj, create):
    """The F-curve collection of the object's action (made when ``create``), or None."""
    owner = _channelbag(obj, create)
    return None if owner is None else owner.fcurves


def baked_fcurves(obj):
    """The object's F-curves a bake wrote (those of the group :data:`GROUP`)."""
    fcurves = _fcurve_collection(obj, create=False)
    if fcurves is None:
        return []
    return [fc for fc in fcurves if fc.group is not None and fc.group.name == GROUP]


def is_baked(obj):
    return bool(baked_fcurves(obj)) or (
        obj.animation_data is not None
        and obj.animation_data.action is not None
        and ORIGINAL in obj.animation_data.action
    )


def animates_transform(obj):
    """Whether the animator keyed the object's location or rotation (F-curves not the
    bake's)."""
    return _animator_transform_curves(obj)


def _animator_transform_curves(obj):
    fcurves = _fcurve_collection(obj, create=False)
    if fcurves is None:
        return False
    paths = {path for path, _ in TRANSFORM_CHANNELS}
    return any(fc.data_path in paths and (fc.group is None or fc.group.name != GROUP) for fc in fcurves)


def _keep_the_animation(obj):
    """Before a bake writes on an object whose transform the animator keyed: give the object
    a copy of its action for the bake, the original kept (with a fake user) and named."""
    animation = obj.animation_data
    original = animation.action
    if ORIGINAL in original:
        return
    slot = getattr(animation, "action_slot", None)
    copy = original.copy()
    copy[ORIGINAL] = original.name
    copy["impulse_original_fake_user"] = int(original.use_fake_user)
    original.use_fake_user = True
    copy.name = f"{original.name} (impulse bake)"
    animation.action = copy
    if slot is not None and hasattr(copy, "slots"):
        animation.action_slot = copy.slots[slot.identifier]


def remove_baked_fcurves(obj):
    """Remove the curves a bake wrote on the object."""
    fcurves = _fcurve_collection(obj, create=False)
    for fcurve in baked_fcurves(obj):
        fcurves.remove(fcurve)


def remember_start(obj, start):
    """Record on the object its bake has just keyed: ``start`` (:func:`start_values`: its own
    channels at the start frame as read before the bake) and the bake's first keys, as
    :data:`AUTHORED`."""
    keyed = {}
    for fcurve in baked_fcurves(obj):
        keyed.setdefault(fcurve.data_path, {})[fcurve.array_index] = float(fcurve.keyframe_points[0].co[1])
    obj[AUTHORED] = {
        "channels": {path: [float(v) for v in values] for path, values in start.items()},
        "keyed": {path: [values[i] for i in sorted(values)] for path, values in keyed.items()},
    }


def _authored(obj):
    stored = obj.get(AUTHORED)
    if stored is None or "channels" not in stored:
        return None
    return {path: tuple(stored["channels"][path]) for path, _ in TRANSFORM_CHANNELS if path in stored["channels"]}


def authored_start(obj):
    """The object's channels as the animator set them (data path → values) when it carries a
    bake recorded by :func:`remember_start` and shows that bake's first keys unchanged; None
    otherwise, so that an edit (moved in the viewport, or keyed into the bake's curves) counts."""
    authored = _authored(obj)
    if authored is None or not baked_fcurves(obj):
        return None
    for path, values in obj[AUTHORED].get("keyed", {}).items():
        shown = getattr(obj, path)
        # Channels are float32, as the keys: the same value to float32 rounding.
        if any(abs(float(shown[i]) - v) > 1e-6 * max(1.0, abs(v)) for i, v in enumerate(values)):
            return None
    return authored


def free_bake(obj, frame):
    """Remove the object's bake: its curves (the object put back at its pose as the animator
    set it, :data:`AUTHORED`, else left at the curves' pose at ``frame``), the action copy (the
    animator's original back) or the action the bake made."""
    import bpy

    curves = baked_fcurves(obj)
    authored = _authored(obj)
    if authored is not None:
        del obj[AUTHORED]
        values = [(path, index, value) for path, channel in authored.items() for index, value in enumerate(channel)]
    else:
        values = [(fc.data_path, fc.array_index, fc.evaluate(frame)) for fc in curves]
    remove_baked_fcurves(obj)
    animation = obj.animation_data
    action = animation.action if animation is not None else None
    if action is not None and ORIGINAL in action:
        original = bpy.data.actions.get(action[ORIGINAL])
        if original is not None:
            original.use_fake_user = bool(action.get("impulse_original_fake_user", 0))
            slot = getattr(animation, "action_slot", None)
            animation.action = original
            if slot is not None and hasattr(original, "slots") and slot.identifier in original.slots:
                animation.action_slot = original.slots[slot.identifier]
        bpy.data.actions.remove(action)
        values = []  # the animation puts the object where it belongs
    elif action is not None and MADE in action:
        owner = _channelbag(obj, create=False)
        if owner is None or len(owner.fcurves) == 0:
            animation.action = None
            if action.users == 0:
                bpy.data.actions.remove(action)
            if len(animation.drivers) == 0 and len(animation.nla_tracks) == 0:
                obj.animation_data_clear()
    for path, index, value in values:
        getattr(obj, path)[index] = value


def _group(owner):
    group = owner.groups.get(GROUP)
    return owner.groups.new(GROUP) if group is None else group


def rotation_channel(obj, quaternions):
    """(data path, values (F, n)) of Blender quaternions (F, 4, w x y z) in the object's
    rotation mode: quaternions as they are, Euler angles kept continuous between frames
    (each frame's the closest to the previous'), or axis-angle (angle, x, y, z)."""
    import mathutils

    mode = obj.rotation_mode
    if mode == "QUATERNION":
        return "rotation_quaternion", np.asarray(quaternions)
    if mode == "AXIS_ANGLE":
        out = np.empty((len(quaternions), 4))
        for i, q in enumerate(quaternions):
            axis, angle = mathutils.Quaternion(q).to_axis_angle()
            out[i] = (angle, *axis)
        return "rotation_axis_angle", out
    if mode == "XYZ":
        return "rotation_euler", _euler_xyz(np.asarray(quaternions, dtype=np.float64))
    out = np.empty((len(quaternions), 3))
    previous = None
    for i, q in enumerate(quaternions):
        euler = mathutils.Quaternion(q).to_euler(mode, previous) if previous else mathutils.Quaternion(q).to_euler(mode)
        out[i] = euler
        previous = euler
    return "rotation_euler", out


def _euler_xyz(quaternions):
    """Quaternions (F, 4, w x y z) as Blender's XYZ Euler angles (F, 3; R = Rz·Ry·Rx), each
    angle unwrapped between frames (no 2π jumps), all frames at once."""
    w, x, y, z = quaternions.T
    r00 = 1.0 - 2.0 * (y * y + z * z)
    r10 = 2.0 * (x * y + w * z)
    r20 = 2.0 * (x * z - w * y)
    r21 = 2.0 * (y * z + w * x)
    r22 = 1.0 - 2.0 * (x * x + y * y)
    angles = np.stack(
        [np.arctan2(r21, r22), np.arctan2(-r20, np.hypot(r00, r10)), np.arctan2(r10, r00)], axis=1
    )
    return np.unwrap(angles, axis=0)


def start_values(obj):
    """The object's own location and rotation channels (data path → values), for
    :func:`write_fcurves`'s ``start``."""
    return {path: tuple(getattr(obj, path)) for path, _ in TRANSFORM_CHANNELS}


def _match_start(path, values, start):
    """``values`` (F, n) of channel ``path`` with the first frame exactly the object's own
    ``start`` value and the rest continuous with it: quaternions negated together when the
    start has the other sign, Euler angles shifted together by whole turns."""
    values = np.array(values, dtype=np.float64, copy=True)
    first = np.asarray(start, dtype=np.float64)
    if path == "rotation_quaternion" and np.dot(values[0], first) < 0:
        values = -values
    elif path == "rotation_euler":
        values += 2.0 * np.pi * np.round((first - values[0]) / (2.0 * np.pi))
    values[0] = first
    return values


def write_fcurves(obj, frames, locations, quaternions, start=None):
    """Key the object's location and rotation at ``frames`` (F,) with ``locations`` (F, 3) and
    ``quaternions`` (F, 4, w x y z; written in the object's rotation mode), replacing an earlier
    bake's curves and keeping the animator's own (:func:`_keep_the_animation`). ``start`` maps
    the channels' data paths to the object's own values at the first frame, keyed there
    exactly as they were (:func:`start_values`): a re-bake of an unchanged scene then reads the
    same start, where the pose's round trip through a matrix would move it by rounding.

    Each curve gets its F points in one ``keyframe_points.add`` and its (frame, value) pairs in
    one ``foreach_set("co", ...)``; points are linear so that the pose between two frames is
    their interpolation, not a Bézier overshoot.
    """
    remove_baked_fcurves(obj)
    if _animator_transform_curves(obj):
        _keep_the_animation(obj)
        fcurves = _fcurve_collection(obj, create=False)
        paths = {path for path, _ in TRANSFORM_CHANNELS}
        for fcurve in [fc for fc in fcurves if fc.data_path in paths]:
            fcurves.remove(fcurve)
    owner = _channelbag(obj, create=True)
    fcurves = owner.fcurves
    group = _group(owner)
    frames = np.asarray(frames, dtype=np.float32)
    count = len(frames)
    co = np.empty((count, 2), dtype=np.float32)
    co[:, 0] = frames
    linear = None
    rotation_path, rotations = rotation_channel(obj, quaternions)
    if start is not None and count > 0:
        locations = _match_start("location", locations, start["location"])
        rotations = _match_start(rotation_path, rotations, start[rotation_path])
    for path, values in (("location", locations), (rotation_path, rotations)):
        values = np.asarray(values)
        for index in range(values.shape[1]):
            fcurve = fcurves.find(path, index=index)
            if fcurve is not None:
                fcurves.remove(fcurve)
            fcurve = fcurves.new(path, index=index)
            fcurve.group = group
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
