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
import time
import warnings

import numpy as np

from . import axes, keyframes, messages, scene_reader

#: Quality presets offered in the panel (impulse's ``Settings.preset`` names).
PRESETS = ("fast", "default", "precise")


def import_impulse():
    """The ``impulse`` package: the extension's bundled wheel (Blender installs it), or the
    copy a plain add-on unpacked beside itself. The first call in a session points impulse's
    decomposition cache at :func:`decomposition_cache_directory`, so that a moving Mesh shape
    split into convex parts once is read back in later sessions."""
    import impulse

    global _cache_set
    if not _cache_set:
        _cache_set = True
        try:
            impulse.set_decomposition_cache_dir(decomposition_cache_directory())
        except (OSError, ValueError, RuntimeError, ImportError):
            pass  # without a cache the split is only redone: time, not correctness
    return impulse


#: Whether :func:`import_impulse` has set the decomposition cache of this session.
_cache_set = False

#: The cache's folder in the add-on's user directory.
CACHE_FOLDER = "decompositions"


def decomposition_cache_directory():
    """The directory where impulse keeps the convex parts of moving Mesh shapes between
    sessions (one file per mesh and Mesh Detail; made when the first is written): the
    extension's user directory (``bpy.utils.extension_path_user``, kept when the extension is
    updated), or for the plain add-on Blender's user data files (``impulse/decompositions``
    under ``bpy.utils.user_resource("DATAFILES")``)."""
    import os

    import bpy

    package = __package__.rpartition(".")[0]  # the add-on's package, this one's parent
    if package.startswith("bl_ext."):
        return bpy.utils.extension_path_user(package, path=CACHE_FOLDER)
    return bpy.utils.user_resource("DATAFILES", path=os.path.join("impulse", CACHE_FOLDER))


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


def make_world(scene_dict, preset="default", substeps=0, frame_steps=0, split_overlap=0.0, collision_steps=4):
    """The impulse world of a scene dict (what :func:`scene_reader.read_scene` gives, its
    ``dt`` one frame) stepping :func:`steps_per_frame` times a frame, with the preset's solver
    settings at that step; returns (world, steps per frame). The scene's own ``sleep`` and
    ``gyroscopic`` stay (the defaults). ``split_overlap`` (m, 0 off): a step that leaves two
    moving objects overlapping by more is taken again in halves with contacts found again
    (impulse's ``Settings.split_overlap``, a setting of the scene, which presets keep).
    ``collision_steps`` (4 by default, 1 off): at most this many collision steps a step, each
    finding contacts again, where two objects move farther than their thickness against each
    other within it (impulse's ``Settings.collision_steps``, likewise the scene's)."""
    impulse = import_impulse()
    count = steps_per_frame(scene_dict["dt"], frame_steps)
    scene_dict = dict(scene_dict, dt=scene_dict["dt"] / count, steps=scene_dict.get("steps", 0) * count)
    settings = solver_settings(preset, substeps, scene_dict["dt"])
    if split_overlap > 0:
        scene_dict["solver"] = dict(scene_dict.get("solver", {}), split_overlap=float(split_overlap))
    scene_dict["solver"] = dict(scene_dict.get("solver", {}), collision_steps=int(collision_steps))
    return impulse.World.from_scene(scene_dict, settings=settings), count


def _slerp(q0, q1, s):
    """Spherical interpolation of unit quaternions (x y z w) the shorter way round."""
    q0, q1 = np.asarray(q0, dtype=np.float64), np.asarray(q1, dtype=np.float64)
    if np.dot(q0, q1) < 0:
        q1 = -q1
    cos = min(float(np.dot(q0, q1)), 1.0)
    angle = math.acos(cos)
    if angle < 1e-9:
        return q0
    return (math.sin((1 - s) * angle) * q0 + math.sin(s * angle) * q1) / math.sin(angle)


def _rotation_vector(q0, q1):
    """The rotation vector (axis × angle, rad) of q1 · q0⁻¹, quaternions x y z w."""
    x0, y0, z0, w0 = -q0[0], -q0[1], -q0[2], q0[3]
    x1, y1, z1, w1 = q1
    d = np.array(
        [
            w1 * x0 + x1 * w0 + y1 * z0 - z1 * y0,
            w1 * y0 - x1 * z0 + y1 * w0 + z1 * x0,
            w1 * z0 + x1 * y0 - y1 * x0 + z1 * w0,
            w1 * w0 - x1 * x0 - y1 * y0 - z1 * z0,
        ]
    )
    if d[3] < 0:
        d = -d
    sine = float(np.linalg.norm(d[:3]))
    if sine < 1e-12:
        return np.zeros(3)
    return d[:3] / sine * 2.0 * math.atan2(sine, d[3])


class Baker:
    """One bake of a scene's Rigid Body World: reads it as it is at the start frame, builds
    the impulse world, steps it frame by frame on :meth:`advance` (``frame_steps`` steps a
    frame, 0: :func:`steps_per_frame`; ``substeps`` per step, 0: the preset's) and writes
    keyframes for the bodies simulated at some frame on :meth:`write`. Nothing in the file
    changes before :meth:`write`: a bake refused or dropped leaves the previous one as it was.

    A body whose "Animated" or "Dynamic" flag switches during the range is swapped between a
    kinematic and a dynamic body at the frame it switches (removed and inserted again): it
    leaves its animation with the animation's linear and angular velocity at that frame, and
    snaps to its animation when it becomes animated again (then driven step by step).

    Raises :class:`scene_reader.UnsupportedScene` from the constructor, with every problem of
    the scene in the animator's terms, when the scene cannot be represented. ``materials``:
    one of :data:`scene_reader.MATERIAL_RULES`; ``resolution``: a moving Mesh's decomposition
    resolution, 0 the engine's default (:func:`shapes.build`); ``split_overlap`` (m, 0 off): split
    steps; ``collision_steps`` (4 by default, 1 off): collision steps (:func:`make_world`).
    """

    def __init__(
        self,
        scene,
        preset="default",
        substeps=0,
        frame_steps=0,
        materials="blender",
        resolution=0,
        split_overlap=0.0,
        collision_steps=4,
    ):
        self.scene = scene
        self.info = scene_reader.read_scene(scene, materials=materials, resolution=resolution)
        impulse = import_impulse()
        self.impulse = impulse
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", UserWarning)
                self.world, self.frame_steps = make_world(
                    self.info.scene, preset, substeps, frame_steps, split_overlap, collision_steps
                )
            # The engine's notes (none for what the reader writes today) in the panel's terms.
            self.info.notes += [messages.translate(str(w.message), self.info) for w in caught]
        except impulse.SceneError as error:

            def build(scene_dict):
                make_world(scene_dict, preset, substeps, frame_steps, split_overlap, collision_steps)

            raise scene_reader.UnsupportedScene(messages.every_problem(self.info, error, build)) from error
        bodies = self.info.bodies
        self.handles = [self.world.handle_of(i) for i in range(len(bodies))]
        self.keyed = [i for i, b in enumerate(bodies) if b.keyed]
        self.switching = [i for i in self.keyed if bodies[i].animated is not None]
        self.kinematic_now = {i: bodies[i].kind == "kinematic" for i in self.switching}
        self.driven = set()
        # The channels as the animator set them, recorded on the keyed objects by write(): a
        # subclass may key another start (a take's), and Free puts these back.
        self.authored = {i: bodies[i].start for i in self.keyed}
        self._rows()
        self.positions = [self.world.positions[self.rows].copy()]
        self.orientations = [self.world.orientations[self.rows].copy()]
        self.simulation_seconds = 0.0
        self.write_seconds = 0.0

    @property
    def dynamic(self):
        """Indices (in ``info.bodies``) of the bodies the bake keys."""
        return self.keyed

    def _rows(self):
        self.rows = [self.world.index_of(self.handles[i]) for i in self.keyed]

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

    def _swap(self, index, to_kinematic, frame):
        """Replace body ``index`` by a kinematic (at its animation's pose at ``frame``) or a
        dynamic one (at its pose, with its velocities)."""
        impulse, world = self.impulse, self.world
        info = self.info.bodies[index]
        row = world.index_of(self.handles[index])
        position = world.positions[row].tolist()
        orientation = world.orientations[row].tolist()
        linear = world.linear_velocities[row].tolist()
        angular = world.angular_velocities[row].tolist()
        world.remove(self.handles[index])
        shape = impulse.Shape.from_dict(info.body["shape"])
        props = {
            "name": info.object_name,
            "friction": info.body["material"]["friction"],
            "restitution": info.body["material"]["restitution"],
        }
        if to_kinematic:
            position, orientation = info.poses[frame]
            builder = impulse.BodyBuilder.kinematic(shape, translation=position, rotation=orientation, **props)
            self.driven.add(index)
        else:
            builder = impulse.BodyBuilder.dynamic(
                shape,
                translation=position,
                rotation=orientation,
                linear_velocity=linear,
                angular_velocity=angular,
                **info.dynamics,
                **props,
            )
            self.driven.discard(index)
        self.handles[index] = world.insert(builder)
        self.kinematic_now[index] = to_kinematic
        self._rows()

    def _drive(self, frame, step):
        """Put every driven kinematic body at its animation's pose at ``step`` of
        ``self.frame_steps`` after ``frame`` and give it the velocity that reaches the next."""
        world, count = self.world, self.frame_steps
        h = self.info.dt / count
        positions, orientations = world.positions.copy(), world.orientations.copy()
        linear, angular = world.linear_velocities.copy(), world.angular_velocities.copy()
        for index in self.driven:
            poses = self.info.bodies[index].poses
            (p0, q0), (p1, q1) = poses[frame], poses[min(frame + 1, len(poses) - 1)]
            p0, p1 = np.asarray(p0), np.asarray(p1)
            a, b = step / count, (step + 1) / count
            row = world.index_of(self.handles[index])
            qa, qb = _slerp(q0, q1, a), _slerp(q0, q1, b)
            positions[row] = p0 + (p1 - p0) * a
            orientations[row] = qa
            linear[row] = (p1 - p0) / self.info.dt
            angular[row] = _rotation_vector(qa, qb) / h
        world.positions, world.orientations = positions, orientations
        world.linear_velocities, world.angular_velocities = linear, angular

    def advance(self, max_frames=None, max_seconds=None):
        """Simulate up to ``max_frames`` more frames, stopping early after ``max_seconds`` of
        wall time (at least one frame). Returns the frames now done."""
        start = time.perf_counter()
        left = self.total_frames - self.frames_done
        if max_frames is not None:
            left = min(left, max_frames)
        for _ in range(left):
            frame = self.frames_done - 1
            for index in self.switching:
                wanted = self.info.bodies[index].animated[frame + 1]
                if wanted != self.kinematic_now[index]:
                    self._swap(index, wanted, frame)
            if self.driven:
                for step in range(self.frame_steps):
                    self._drive(frame, step)
                    self.world.step(1)
            else:
                self.world.step(self.frame_steps)
            self.positions.append(self.world.positions[self.rows].copy())
            self.orientations.append(self.world.orientations[self.rows].copy())
            if max_seconds is not None and time.perf_counter() - start >= max_seconds:
                break
        self.simulation_seconds += time.perf_counter() - start
        return self.frames_done

    def write(self):
        """Key every keyed body's object at the frames done (location and rotation in the
        object's rotation mode, in its parent's space, whole F-curves in the group
        :data:`keyframes.GROUP`), replacing an earlier bake, remove an earlier bake from the
        objects this one does not key, and turn Blender's own rigid body world off so that the
        keyframes are what plays. Each keyed object records its own start channels as the
        animator set them (:func:`keyframes.remember_start`), which Free puts back. Returns
        the number of keyed objects."""
        start = time.perf_counter()
        frames = np.arange(self.frames_done, dtype=np.float32) + self.info.frame_start
        locations = axes.positions_to_blender(np.stack(self.positions))
        quaternions = axes.continuous_quaternions(axes.orientations_to_blender(np.stack(self.orientations)))
        objects = self.scene.objects
        keyed_names = set()
        for column, index in enumerate(self.keyed):
            info = self.info.bodies[index]
            obj = objects[info.object_name]
            keyed_names.add(obj.name)
            location, rotation = _object_space(info, locations[:, column], quaternions[:, column])
            keyframes.write_fcurves(obj, frames, location, rotation, info.start)
            keyframes.remember_start(obj, self.authored[index])
        for obj in scene_reader.rigid_body_objects(self.scene):
            if obj.name not in keyed_names and keyframes.is_baked(obj):
                keyframes.free_bake(obj, self.info.frame_start)
        self.scene.rigidbody_world.enabled = False
        self.scene.frame_set(self.scene.frame_current)
        self.write_seconds = time.perf_counter() - start
        return len(self.keyed)


def _object_space(info, locations, quaternions):
    """World poses (F, 3) and (F, 4, w x y z) of a body as its object's location and rotation:
    in its parent's space and divided by its own Scale (a mirrored object's negative scale
    moves into its rotation otherwise). As they are for an object without a parent whose world
    scale is its Scale."""
    if info.parent_space is None and all(
        abs(a - b) <= 1e-9 + 1e-6 * abs(b) for a, b in zip(info.scale, info.basis_scale, strict=True)
    ):
        return locations, quaternions
    import mathutils

    scale = mathutils.Matrix.Diagonal((*info.scale, 1.0))
    unscale = mathutils.Matrix.Diagonal([1.0 / s for s in info.basis_scale])
    out_locations = np.empty_like(locations)
    out_quaternions = np.empty_like(quaternions)
    identity = mathutils.Matrix.Identity(4)
    for frame in range(len(locations)):
        world = (
            mathutils.Matrix.Translation(locations[frame])
            @ mathutils.Quaternion(quaternions[frame]).to_matrix().to_4x4()
            @ scale
        )
        if info.parent_space is not None:
            space = info.parent_space[min(frame, len(info.parent_space) - 1)]
        else:
            space = identity
        basis = space.inverted_safe() @ world
        out_locations[frame] = basis.translation
        out_quaternions[frame] = (basis.to_3x3() @ unscale).to_quaternion()
    return out_locations, axes.continuous_quaternions(out_quaternions[:, None])[:, 0]


def bake_scene(
    scene, preset="default", substeps=0, frame_steps=0, materials="blender", resolution=0, split_overlap=0.0, collision_steps=4
):
    """Bake the scene's Rigid Body World with impulse at once; returns the :class:`Baker`
    (its ``simulation_seconds`` and ``write_seconds`` are the two parts' wall times)."""
    baker = Baker(scene, preset, substeps, frame_steps, materials, resolution, split_overlap, collision_steps)
    baker.advance()
    baker.write()
    return baker


def free_bake(scene):
    """Remove impulse's bake from every object of the scene's Rigid Body World (each object
    back at the start pose the animator set, also after a take's bake, which starts elsewhere;
    an animated object's own animation back) and tick the
    Rigid Body World again, so that Blender's own simulation plays. Returns the number of
    objects freed."""
    objects = scene_reader.rigid_body_objects(scene)
    frame = int(scene.rigidbody_world.point_cache.frame_start)
    freed = 0
    for obj in objects:
        if keyframes.is_baked(obj):
            keyframes.free_bake(obj, frame)
            freed += 1
    scene.rigidbody_world.enabled = True
    scene.frame_set(scene.frame_current)
    return freed
