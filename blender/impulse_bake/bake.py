"""Simulating a read scene with impulse and writing the result, in chunks so that a modal
operator can report progress and stop early (the frames done are kept).

Usage without UI::

    baker = Baker(bpy.context.scene, preset="default")
    while not baker.done:
        baker.advance(max_frames=25)
    baker.write()

or :func:`bake_scene` for all of it at once.
"""

import math
import re
import time

import numpy as np

from . import axes, keyframes, scene_reader

#: Quality presets offered in the panel (impulse's ``Settings.preset`` names).
PRESETS = ("fast", "default", "precise")


def import_impulse():
    """The ``impulse`` package: the extension's bundled wheel (Blender installs it), or the
    copy a plain add-on unpacked beside itself."""
    import impulse

    return impulse


#: The step the presets were tuned at (s): 60 steps a second (docs/solvers.md).
PRESET_STEP = 1.0 / 60.0


def steps_per_frame(frame_dt, requested=0):
    """Steps per frame of ``frame_dt`` (s): ``requested`` when > 0, else as many as keep a
    step within the presets' 1/60 s (3 at 24 fps, 1 at 60 fps). Contacts are found once per
    step: at 24 fps one step a frame let balls dropped onto balls pass 0.2 m into each other
    before their contact was found (the bowl scene), at 3 steps a frame 0.3 mm."""
    if requested > 0:
        return int(requested)
    return max(1, math.ceil(frame_dt / PRESET_STEP - 1e-9))


def preset_substeps(preset, dt):
    """Substeps per step of ``dt`` (s) that keep the preset's substep length: its substep count
    times dt / (1/60), rounded up (the soft contacts' stiffness, and so a stack's sag, depends
    on the substep length)."""
    impulse = import_impulse()
    count = impulse.Settings.preset(preset).substeps
    return max(1, math.ceil(count * dt / PRESET_STEP - 1e-9))


def solver_settings(preset="default", substeps=0, dt=PRESET_STEP):
    """impulse's ``Settings`` of ``preset`` for steps of ``dt`` (s): ``substeps`` per step
    when > 0, else :func:`preset_substeps`."""
    impulse = import_impulse()
    settings = impulse.Settings.preset(preset)
    count = int(substeps) if substeps > 0 else preset_substeps(preset, dt)
    return settings.replace(substeps=count)


def make_world(scene_dict, preset="default", substeps=0, frame_steps=0):
    """The impulse world of a scene dict (what :func:`scene_reader.read_scene` gives, its
    ``dt`` one frame) stepping :func:`steps_per_frame` times a frame, with the preset's solver
    settings at that step; returns (world, steps per frame). The scene's own ``sleep`` and
    ``gyroscopic`` stay (the defaults)."""
    impulse = import_impulse()
    count = steps_per_frame(scene_dict["dt"], frame_steps)
    scene_dict = dict(scene_dict, dt=scene_dict["dt"] / count, steps=scene_dict.get("steps", 0) * count)
    settings = solver_settings(preset, substeps, scene_dict["dt"])
    return impulse.World.from_scene(scene_dict, settings=settings), count


def _name_the_body(message, info):
    """impulse's scene error (``bodies[3].shape.points: ...``, ``joints[0].limits: ...``) led
    by the body's or the constraint's object name."""
    joint = re.search(r"joints\[(\d+)\]", message)
    joints = info.scene.get("joints", [])
    if joint is not None and int(joint.group(1)) < len(joints):
        return f"{joints[int(joint.group(1))]['name']}: {message}"
    found = re.search(r"bodies\[(\d+)\]", message)
    if found is None or int(found.group(1)) >= len(info.bodies):
        return f"{info.scene.get('name', 'scene')}: {message}"
    return f"{info.bodies[int(found.group(1))].object_name}: {message}"


class Baker:
    """One bake of a scene's Rigid Body World: reads it (undoing an earlier bake first),
    builds the impulse world, steps it frame by frame on :meth:`advance` (``frame_steps``
    steps a frame, 0: :func:`steps_per_frame`; ``substeps`` per step, 0: the preset's) and
    writes keyframes for the dynamic bodies on :meth:`write`.

    Raises :class:`scene_reader.UnsupportedScene` from the constructor when the scene cannot
    be represented (before anything is changed but the earlier bake's removal).
    """

    def __init__(self, scene, preset="default", substeps=0, frame_steps=0):
        self.scene = scene
        objects = scene_reader.rigid_body_objects(scene)
        scene_reader.restore_rest_poses(objects)
        self.info = scene_reader.read_scene(scene)
        try:
            self.world, self.frame_steps = make_world(self.info.scene, preset, substeps, frame_steps)
        except import_impulse().SceneError as error:
            raise scene_reader.UnsupportedScene([_name_the_body(str(error), self.info)]) from error
        self.dynamic = [i for i, b in enumerate(self.info.bodies) if b.kind == "dynamic"]
        self.positions = [self.world.positions[self.dynamic].copy()]
        self.orientations = [self.world.orientations[self.dynamic].copy()]
        self.simulation_seconds = 0.0
        self.write_seconds = 0.0

    @property
    def total_frames(self):
        """Frames of the range, the first (initial) one included."""
        return self.info.steps + 1

    @property
    def frames_done(self):
        return len(self.positions)

    @property
    def done(self):
        return self.frames_done >= self.total_frames

    def advance(self, max_frames=None, max_seconds=None):
        """Simulate up to ``max_frames`` more frames, stopping early after ``max_seconds`` of
        wall time (at least one frame). Returns the frames now done."""
        start = time.perf_counter()
        left = self.total_frames - self.frames_done
        if max_frames is not None:
            left = min(left, max_frames)
        for _ in range(left):
            self.world.step(self.frame_steps)
            self.positions.append(self.world.positions[self.dynamic].copy())
            self.orientations.append(self.world.orientations[self.dynamic].copy())
            if max_seconds is not None and time.perf_counter() - start >= max_seconds:
                break
        self.simulation_seconds += time.perf_counter() - start
        return self.frames_done

    def write(self):
        """Key every dynamic body's object at the frames done (location and rotation
        quaternion, whole F-curves), remember each object's pose from before the bake so that
        the next bake replaces this one, and turn Blender's own rigid body world off so that
        the keyframes are what plays. Returns the number of keyed objects."""
        start = time.perf_counter()
        frames = np.arange(self.frames_done, dtype=np.float32) + self.info.frame_start
        locations = axes.positions_to_blender(np.stack(self.positions))
        quaternions = axes.continuous_quaternions(axes.orientations_to_blender(np.stack(self.orientations)))
        objects = self.scene.objects
        for column, index in enumerate(self.dynamic):
            obj = objects[self.info.bodies[index].object_name]
            obj[scene_reader.REST_PROPERTY] = {
                "rotation_mode": obj.rotation_mode,
                "location": tuple(obj.location),
                "rotation_quaternion": tuple(obj.rotation_quaternion),
                "rotation_euler": tuple(obj.rotation_euler),
                "rotation_axis_angle": tuple(obj.rotation_axis_angle),
            }
            keyframes.write_fcurves(obj, frames, locations[:, column], quaternions[:, column])
        self.scene.rigidbody_world.enabled = False
        self.write_seconds = time.perf_counter() - start
        return len(self.dynamic)


def bake_scene(scene, preset="default", substeps=0, frame_steps=0):
    """Bake the scene's Rigid Body World with impulse at once; returns the :class:`Baker`
    (its ``simulation_seconds`` and ``write_seconds`` are the two parts' wall times)."""
    baker = Baker(scene, preset, substeps, frame_steps)
    baker.advance()
    baker.write()
    return baker
