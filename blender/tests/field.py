"""Scenes built the way Blender's interface builds them: the factory startup file, primitives
added with ``bpy.ops.mesh.primitive_*_add``, rigid bodies with ``bpy.ops.rigidbody.object_add``
(its default shape, Convex Hull) and then only the settings a tutorial changes. Shared by the
field tests (test_field.py, test_bake_loop.py)."""

import bpy


def startup(frames, keep_cube=False):
    """The factory startup file (a cube, a camera, a light), the default cube deleted unless
    ``keep_cube``, the scene's and the Rigid Body World's range 1..``frames`` once a rigid body
    exists (:func:`rigid`)."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy.context.scene
    if not keep_cube:
        bpy.data.objects.remove(bpy.data.objects["Cube"])
    scene.frame_start = 1
    scene.frame_end = frames
    scene.frame_set(1)
    return scene


def select(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def add(primitive, name, **options):
    """A mesh primitive added as the Add menu adds it, renamed ``name``."""
    getattr(bpy.ops.mesh, f"primitive_{primitive}_add")(**options)
    obj = bpy.context.object
    obj.name = name
    obj.data.name = name
    return obj


def rigid(obj, kind="ACTIVE"):
    """Physics › Rigid Body on the object (Blender makes the Rigid Body World with the first);
    the world's cache range follows the scene's."""
    select(obj)
    bpy.ops.rigidbody.object_add(type=kind)
    scene = bpy.context.scene
    cache = scene.rigidbody_world.point_cache
    cache.frame_start, cache.frame_end = scene.frame_start, scene.frame_end
    return obj


def ground(name="Ground", size=20.0, top=0.0):
    """A passive ground slab (a scaled cube, default shape) whose top face is at z = ``top``."""
    obj = add("cube", name, size=1.0, location=(0.0, 0.0, top - 0.25))
    obj.scale = (size, size, 0.5)
    bpy.context.view_layer.update()
    return rigid(obj, "PASSIVE")


def key(obj, path, frame, value, interpolation="LINEAR"):
    """Set ``path`` of ``obj`` (a data path like "location" or "rigid_body.kinematic") to
    ``value`` at ``frame`` and key it (the I key / right-click › Insert Keyframe)."""
    owner, attribute = obj, path
    if "." in path:
        first, attribute = path.split(".")
        owner = getattr(obj, first)
    setattr(owner, attribute, value)
    obj.keyframe_insert(path, frame=frame)
    if interpolation:
        _set_interpolation(obj, path, interpolation)


def _set_interpolation(obj, path, interpolation):
    from impulse_bake import keyframes

    for fcurve in keyframes._fcurve_collection(obj, create=False):
        if fcurve.data_path == path:
            for point in fcurve.keyframe_points:
                point.interpolation = interpolation


def world_at(scene, obj, frame):
    """The object's world matrix at ``frame`` as the viewport shows it."""
    scene.frame_set(frame)
    return obj.matrix_world.copy()


def world_vertices(scene, obj, frame):
    """The object's mesh vertices in world space at ``frame``."""
    matrix = world_at(scene, obj, frame)
    return [matrix @ v.co for v in obj.data.vertices]
