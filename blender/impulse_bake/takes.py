"""Directable takes in Blender, free of any UI: goals set on objects as ``impulse.takes`` goal
dicts, the scene a search varies, the search run as ``python -m impulse.takes search`` in a
child process, and a take baked as keyframes through the same path as "Bake with impulse".

The searched scene is the baked one, written so that the scene file alone gives the bake's bits:
its ``dt`` is one simulation step (a frame's ``dt`` over the steps per frame), its ``steps``
the range's steps, and its ``solver`` the bake's settings (the preset's effort at that step,
the scene's friction and bounciness rules). ``impulse.World.from_scene(take.scene())`` stepped
``steps`` times is then the take's trajectory, and :class:`TakeBaker` keys exactly it. A
keyed throw's take starts at its release (:func:`release_frame`), with the animation's last
velocity as the thrown body's start.

Goals use the object's origin as its place (the body's ``position``) and Blender's axes, turned
into impulse's (y up) as the bake does (:mod:`.axes`).
"""

import hashlib
import json
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np

from . import axes, bake, scene_reader

#: The local axes an "ends face up" goal can name, in the object's own (Blender) frame.
FACE_AXES = {
    "POS_X": (1.0, 0.0, 0.0),
    "NEG_X": (-1.0, 0.0, 0.0),
    "POS_Y": (0.0, 1.0, 0.0),
    "NEG_Y": (0.0, -1.0, 0.0),
    "POS_Z": (0.0, 0.0, 1.0),
    "NEG_Z": (0.0, 0.0, -1.0),
}

#: Blender's world up (+Z) in impulse's axes.
UP = (0.0, 1.0, 0.0)

#: Files a search directory holds besides what ``impulse.takes.search`` writes: the request
#: (the scene and goals handed to the child process) and the child's output.
REQUEST_SCENE = "request-scene.json"
REQUEST_GOALS = "request-goals.json"
LOG_FILE = "search.log"


def _impulse_vector(v):
    """A Blender vector in impulse's axes, without negative zeros (so the JSON reads plainly)."""
    return [c + 0.0 for c in axes.vector_to_impulse(v)]


def empty_box(empty):
    """The world-space box of an Empty displayed as a Cube (its display size times its world
    matrix), as an impulse ``box`` region: the axis-aligned bounds in impulse's axes of its 8
    corners (exact for an Empty that is not rotated; a rotated one gives the box around it)."""
    size = float(empty.empty_display_size)
    corners = np.array(
        [
            _impulse_vector(empty.matrix_world @ _vector((sx * size, sy * size, sz * size)))
            for sx in (-1, 1)
            for sy in (-1, 1)
            for sz in (-1, 1)
        ]
    )
    return {"box": {"min": corners.min(axis=0).tolist(), "max": corners.max(axis=0).tolist()}}


def _vector(values):
    import mathutils

    return mathutils.Vector(values)


def is_region(obj):
    """Whether ``obj`` can be an "ends inside" region: an Empty displayed as a Cube."""
    return obj is not None and obj.type == "EMPTY" and obj.empty_display_type == "CUBE"


def read_goals(scene, info):
    """The goals set on the objects of the scene's Rigid Body World (their ``impulse_takes``
    settings) as ``impulse.takes`` goal dicts, in object-name order, for the bodies of ``info``
    (a :class:`scene_reader.SceneInfo`). Raises :class:`scene_reader.UnsupportedScene` naming
    each object whose goal cannot be met as set, or when no object has a goal."""
    bodies = {b.object_name: b for b in info.bodies}
    goals, problems = [], []
    for obj in scene_reader.rigid_body_objects(scene):
        settings = getattr(obj, "impulse_takes", None)
        if settings is None or not has_goal(settings):
            continue
        body = bodies.get(obj.name)
        if body is None or not body.keyed:
            problems.append(f"{obj.name}: has goals but is not a moving body of the bake (an Active rigid body)")
            continue
        if settings.region is not None:
            if not is_region(settings.region):
                problems.append(f"{obj.name}: its region {settings.region.name} is not an Empty displayed as a Cube")
            else:
                goals.append(
                    {
                        "type": "ends_inside",
                        "name": f"{obj.name} ends inside {settings.region.name}",
                        "body": obj.name,
                        "region": empty_box(settings.region),
                    }
                )
        if settings.face_up != "NONE":
            goals.append(
                {
                    "type": "rests_with_axis_up",
                    "name": f"{obj.name} ends {settings.face_up} up",
                    "body": obj.name,
                    "axis": _impulse_vector(FACE_AXES[settings.face_up]),
                    "up": list(UP),
                    "tolerance_degrees": float(settings.face_tolerance),
                    "rest_speed": float(settings.rest_speed),
                }
            )
        if settings.hits is not None:
            if settings.hits.name not in bodies or settings.hits == obj:
                problems.append(
                    f"{obj.name}: the object it should hit, {settings.hits.name}, "
                    "is not another rigid body of the world"
                )
            else:
                goals.append(
                    {
                        "type": "touches",
                        "name": f"{obj.name} hits {settings.hits.name}",
                        "body": obj.name,
                        "other": settings.hits.name,
                    }
                )
    if problems:
        raise scene_reader.UnsupportedScene(problems)
    if not goals:
        raise scene_reader.UnsupportedScene(
            [f"{scene.name}: no object has a goal (set one in Physics > impulse Takes: Goals)"]
        )
    return goals


def has_goal(settings):
    """Whether an object's ``impulse_takes`` settings state any goal."""
    return settings.region is not None or settings.face_up != "NONE" or settings.hits is not None


def varied_bodies(scene, info):
    """Names of the moving bodies a search varies: those whose ``impulse_takes.vary`` is on."""
    names = []
    for body in info.bodies:
        if not body.keyed:
            continue
        obj = scene.objects.get(body.object_name)
        if obj is not None and getattr(obj, "impulse_takes", None) is not None and obj.impulse_takes.vary:
            names.append(body.object_name)
    return names


def release_frame(info):
    """The index (frames from the range's start) of the last animated frame of the keyed
    throws of ``info`` (a :class:`scene_reader.SceneInfo`): the bodies whose Animated or
    Dynamic flag is keyed, animated from the start frame and simulated after it to the end.
    None when no flag is keyed. Raises :class:`scene_reader.UnsupportedScene` naming each
    object that is not such a throw, throws released at different frames, and any other
    object animated in a scene with a throw (a take starts at the release, and a scene file
    keeps no animation from before it)."""
    switching = [b for b in info.bodies if b.animated is not None]
    if not switching:
        return None
    problems, releases = [], {}
    for body in switching:
        flags = body.animated
        last = 0
        while last + 1 < len(flags) and flags[last + 1]:
            last += 1
        if not flags[0] or any(flags[last + 1:]):
            problems.append(
                f"{body.object_name}: its Animated or Dynamic flag switches otherwise than a throw (animated from "
                "the start frame, then simulated to the end); takes vary scenes without other switches"
            )
        else:
            releases[body.object_name] = last
    if len(set(releases.values())) > 1:
        problems.append(
            "the keyed throws are released at different frames ("
            + ", ".join(f"{name} after frame {info.frame_start + last}" for name, last in sorted(releases.items()))
            + "); a take starts at one release"
        )
    for body in info.bodies:
        if body.animated is None and body.body.get("keyframes"):
            problems.append(
                f"{body.object_name}: animated in a scene with a keyed throw; a take starts at the release and "
                "keeps no other animation"
            )
    if problems:
        raise scene_reader.UnsupportedScene(problems)
    return next(iter(releases.values()))


def _released(info, index, last):
    """Body ``index`` of ``info`` as the dynamic body it is from the release after frame index
    ``last``: at its animation's pose there, with the velocity and spin of its animation's
    last frame (m/s, rad/s, impulse's axes)."""
    body = dict(info.bodies[index].body, kind="dynamic")
    body.pop("keyframes", None)
    poses = info.bodies[index].poses
    (p0, q0), (p1, q1) = poses[max(last - 1, 0)], poses[last]
    body["position"], body["orientation"] = list(p1), list(q1)
    if last > 0:
        body["linear_velocity"] = [(b - a) / info.dt for a, b in zip(p0, p1, strict=True)]
        body["angular_velocity"] = (bake._rotation_vector(q0, q1) / info.dt).tolist()
    body.update(info.bodies[index].dynamics)
    return body


def search_scene(info, preset="default", substeps=0, frame_steps=0):
    """The scene dict a search varies, and the steps per frame: ``info.scene`` (a
    :class:`scene_reader.SceneInfo`'s) with one simulation step as ``dt``, the range's steps as
    ``steps`` and the bake's solver settings as ``solver``, so that
    ``impulse.World.from_scene`` of it steps exactly as :func:`bake.make_world` of ``info.scene``
    does.

    A scene with keyed throws (:func:`release_frame`) starts at the release instead: each
    thrown body dynamic at its animation's last pose with the animation's last velocity and
    spin (what a search varies like any start), the other bodies at their start, and
    ``steps`` those from the release to the end. Raises :class:`scene_reader.UnsupportedScene`
    for switches that are not such throws."""
    last = release_frame(info)
    count = bake.steps_per_frame(info.dt, frame_steps)
    dt = info.dt / count
    solver = bake.solver_settings(preset, substeps, dt).to_dict()
    # The scene's own solver fields (the combine rules) are not effort fields: the bake keeps
    # them over the preset's (impulse's Settings.with_effort_of), and so does this.
    solver.update(info.scene.get("solver", {}))
    scene = dict(info.scene, dt=dt, steps=info.steps * count, solver=solver)
    if last is not None:
        scene["bodies"] = [
            _released(info, i, last) if b.animated is not None else b.body for i, b in enumerate(info.bodies)
        ]
        scene["steps"] = (info.steps - last) * count
    return json.loads(json.dumps(scene)), count


def build_request(
    scene, variation, seed=0, population=16, preset="default", substeps=0, frame_steps=0, materials="blender",
    resolution=0,
):
    """A search's request for the scene as it is: ``{"scene", "goals", "variation", "seed",
    "population"}`` (:class:`SearchJob`). ``variation`` holds the scales ``position`` (m),
    ``angle`` (degrees), ``velocity`` (m/s) and ``angular_velocity`` (rad/s); the varied
    bodies are the objects whose ``impulse_takes.vary`` is on. The bake settings are those of
    "Bake with impulse". Raises :class:`scene_reader.UnsupportedScene` naming what is missing
    or wrong."""
    info = scene_reader.read_scene(scene, materials=materials, resolution=resolution)
    goals = read_goals(scene, info)
    searched, _ = search_scene(info, preset, substeps, frame_steps)
    bodies = varied_bodies(scene, info)
    if not bodies:
        raise scene_reader.UnsupportedScene([f"{scene.name}: no moving object has Vary on"])
    variation = dict(variation, bodies=bodies)
    if not any(variation[key] > 0.0 for key in ("position", "angle", "velocity", "angular_velocity")):
        raise scene_reader.UnsupportedScene([f"{scene.name}: every variation scale is 0: nothing would vary"])
    return {"scene": searched, "goals": goals, "variation": variation, "seed": int(seed), "population": int(population)}


def _canonical(value):
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def search_directory(blend_path, request):
    """The directory of a search: ``<blend name>_takes/<16 hex digits of the request>`` beside
    the .blend, or under the system's temporary directory for an unsaved file. One request
    (scene, goals, variation, seed, population) always maps to one directory, so running it
    again resumes it."""
    digest = hashlib.sha256(_canonical(request).encode()).hexdigest()[:16]
    if blend_path:
        stem = os.path.splitext(os.path.basename(blend_path))[0]
        base = os.path.join(os.path.dirname(os.path.abspath(blend_path)), f"{stem}_takes")
    else:
        base = os.path.join(tempfile.gettempdir(), "impulse-takes")
    return os.path.join(base, digest)


def python_executable():
    """The Python interpreter to run the search with: ``sys.executable``, which is Blender's
    bundled Python in Blender (2.91 and later) and the environment's Python for the ``bpy``
    module. Raises RuntimeError when it is not a Python interpreter."""
    executable = sys.executable
    if not executable or not os.path.basename(executable).lower().startswith("python"):
        raise RuntimeError(
            f"impulse takes run the search with a Python interpreter, and sys.executable is "
            f"{executable!r}: run Blender 2.91 or later, or search from a shell with "
            "python -m impulse.takes search"
        )
    return executable


class SearchJob:
    """One search running in a child process (``python -m impulse.takes search`` on the local
    process pool), started on construction.

    ``request`` holds the search's inputs: ``scene`` (the :func:`search_scene` dict), ``goals``,
    ``variation`` (an ``impulse.takes.Variation`` dict), ``seed``, ``population``; ``budget``,
    ``stop_after`` and ``workers`` (0: every core) only limit the run. The child writes its
    takes to ``directory`` (:func:`search_directory`) a generation at a time and its messages
    to ``search.log`` there; it and its workers share the bake's decomposition cache
    (:func:`bake.decomposition_cache_directory`, through ``IMPULSE_DECOMPOSITION_CACHE``).
    """

    def __init__(self, directory, request, budget, stop_after=1, workers=0):
        self.directory = directory
        self.budget = int(budget)
        self.cancelled = False
        os.makedirs(directory, exist_ok=True)
        scene_path = os.path.join(directory, REQUEST_SCENE)
        goals_path = os.path.join(directory, REQUEST_GOALS)
        with open(scene_path, "w", encoding="utf-8") as file:
            json.dump(request["scene"], file)
        with open(goals_path, "w", encoding="utf-8") as file:
            json.dump(
                {"goals": request["goals"], "steps": request["scene"]["steps"], "variation": request["variation"]},
                file,
                indent=1,
            )
        command = [
            python_executable(),
            "-m",
            "impulse.takes",
            "search",
            scene_path,
            "--goals",
            goals_path,
            "--budget",
            str(self.budget),
            "--out",
            directory,
            "--seed",
            str(int(request["seed"])),
            "--population",
            str(int(request["population"])),
            "--stop-after",
            str(int(stop_after)),
            "--no-progress",
        ]
        if workers > 0:
            command += ["--workers", str(int(workers))]
        impulse = bake.import_impulse()
        # The child finds impulse where this process did (an installed wheel, or the plain
        # add-on's vendor/ directory).
        package_root = os.path.dirname(os.path.dirname(os.path.abspath(impulse.__file__)))
        environment = dict(os.environ)
        environment["PYTHONPATH"] = os.pathsep.join(
            p for p in (package_root, environment.get("PYTHONPATH")) if p
        )
        # The child and its workers read and keep the bake's convex parts of moving meshes.
        try:
            environment["IMPULSE_DECOMPOSITION_CACHE"] = bake.decomposition_cache_directory()
        except (OSError, ValueError, RuntimeError):
            pass  # without a cache the split is only redone: time, not correctness
        self._log = open(os.path.join(directory, LOG_FILE), "w", encoding="utf-8")  # noqa: SIM115
        self.process = subprocess.Popen(
            command, stdout=self._log, stderr=subprocess.STDOUT, env=environment, cwd=directory
        )

    def takes_done(self):
        """Takes run so far (the rows the child has written; it writes after each generation)."""
        path = os.path.join(self.directory, "takes.parquet")
        if not os.path.exists(path):
            return 0
        try:
            import pyarrow.parquet as pq

            return pq.read_metadata(path).num_rows
        except (OSError, ValueError):
            return 0  # being replaced this instant
        except ImportError:
            return 0  # no working pyarrow here: the child fails the same way, and says so

    def running(self):
        return self.process.poll() is None

    def wait(self):
        """Blocks until the child ends; returns :meth:`finish`."""
        self.process.wait()
        return self.finish()

    def cancel(self):
        """Stops the child; the takes of its finished generations stay in the directory (a
        search run again with the same settings resumes them)."""
        if self.running():
            self.cancelled = True
            self.process.terminate()
            self.process.wait()
        self._log.close()

    def failure(self):
        """Why the ended child failed, in one line, or None when it ran its search: exit code
        0 (a take meets every goal), or 1 with its closing summary (``N takes, M meet every
        goal``) in ``search.log`` (none does; an uncaught exception also exits 1, without it).
        The line is the child's last message (``error: …`` or the exception), with what to
        install when it is pyarrow failing with this Python's NumPy."""
        code = self.process.returncode
        if code is None or self.cancelled:
            return None
        try:
            with open(os.path.join(self.directory, LOG_FILE), encoding="utf-8", errors="replace") as file:
                log = file.read()
        except OSError:
            log = ""
        lines = [line.strip() for line in log.splitlines() if line.strip()]
        if code == 0 or (code == 1 and any(line.endswith(" meet every goal") for line in lines)):
            return None
        errors = [line for line in lines if line.startswith("error: ")]
        if errors and "Traceback (most recent call last)" not in log:
            message = errors[-1][len("error: "):]
        else:
            message = lines[-1] if lines else "no message"
        message = f"the search failed (exit code {code}): {message}"
        if "numpy" in message.lower():
            message += "; " + pyarrow_advice()
        return f"{message} (search.log in {self.directory})"

    def finish(self):
        """The ``impulse.takes.Takes`` of the ended (or cancelled) search. Raises RuntimeError
        with :meth:`failure` when the child failed (an error, an exception, a crash) or when
        pyarrow cannot be imported here to read the table, FileNotFoundError when it was
        cancelled before any take was written."""
        self._log.close()
        failure = self.failure()
        if failure is not None:
            raise RuntimeError(failure)
        from impulse.takes import load

        try:
            return load(self.directory)
        except ImportError as error:  # pyarrow missing or failing here, though the child ran
            raise RuntimeError(f"cannot read the takes in {self.directory}: {error}; {pyarrow_advice()}") from error


def pyarrow_advice():
    """What to install for the search's table in this Python: pyarrow 19 and later need NumPy
    2, and Blender 5.0 ships NumPy 1.26, with which pyarrow 18 works."""
    import numpy

    wanted = "'pyarrow<19'" if int(numpy.__version__.split(".")[0]) < 2 else "--upgrade pyarrow"
    return (
        f"install a pyarrow for this Python's NumPy {numpy.__version__}: "
        f"{python_executable()} -m pip install {wanted}"
    )


class TakeBaker(bake.Baker):
    """A :class:`bake.Baker` that simulates take ``take_id`` of ``takes`` (an
    ``impulse.takes.Takes``) instead of the scene as read: the scene is read and checked as for
    "Bake with impulse", the search must have been run on this very scene and settings (its
    ``scene.json``), and the world is ``impulse.World.from_scene(take.scene())``, stepped the
    same steps per frame. With keyed throws the take starts at their release
    (:func:`search_scene`): the frames before it key the throws' animation and the other
    bodies at their start. Raises :class:`scene_reader.UnsupportedScene` when the scene or the
    bake settings changed since the search, KeyError for an unknown take."""

    def __init__(
        self, scene, takes, take_id, preset="default", substeps=0, frame_steps=0, materials="blender", resolution=0
    ):
        take = takes[take_id]
        super().__init__(scene, preset, substeps, frame_steps, materials, resolution)
        searched, count = search_scene(self.info, preset, substeps, frame_steps)
        if _canonical(searched) != _canonical(takes.base_scene):
            raise scene_reader.UnsupportedScene(
                [
                    f"{scene.name}: the scene or the bake settings changed since take {take.take_id} was "
                    "searched; search again"
                ]
            )
        self.take = take
        self.frame_steps = count
        bodies = self.info.bodies
        # A varied body's first key is its varied start, not the object's own channels
        # (bake.Baker keys those at the first frame to keep an unchanged re-bake's bits); a
        # throw's first key is its animation's, as the object's channels are.
        for index in takes.variation.body_indices(takes.base_scene):
            if bodies[index].animated is None:
                bodies[index].start = None
        with warnings.catch_warnings():
            # The engine's notes on the scene were the bake's own (bake.Baker), said once.
            warnings.simplefilter("ignore", UserWarning)
            self.world = self.impulse.World.from_scene(take.scene())
        self.handles = [self.world.handle_of(i) for i in range(len(bodies))]
        self._rows()
        # The take's world has no switches: a throw is dynamic in it from its release on.
        self.switching, self.driven = [], set()
        # Until the release (none without a throw), the throws follow their animation and the
        # other bodies wait at their start; the take's world is the frame of the release.
        self.positions, self.orientations = [], []
        for frame in range(release_frame(self.info) or 0):
            poses = [bodies[i].poses[frame] if bodies[i].animated is not None else None for i in self.keyed]
            self.positions.append(
                np.array([p[0] if p else bodies[i].body["position"] for i, p in zip(self.keyed, poses, strict=True)])
            )
            self.orientations.append(
                np.array([p[1] if p else bodies[i].body["orientation"] for i, p in zip(self.keyed, poses, strict=True)])
            )
        self.positions.append(self.world.positions[self.rows].copy())
        self.orientations.append(self.world.orientations[self.rows].copy())


def bake_take(scene, takes, take_id, preset="default", substeps=0, frame_steps=0, materials="blender", resolution=0):
    """Bake take ``take_id`` of ``takes`` (a search of this scene) as keyframes at once;
    returns the :class:`TakeBaker`."""
    baker = TakeBaker(scene, takes, take_id, preset, substeps, frame_steps, materials, resolution)
    baker.advance()
    baker.write()
    return baker


#: Where the still previews go in a search directory: the contact sheet's folder
#: (``impulse.takes.sheet`` keeps its GIFs there), as ``<take_id>.png``.
PREVIEWS_DIR = "previews"
#: The stills' size in pixels (width, height).
PREVIEW_SIZE = (128, 96)


def impulse_command():
    """The ``impulse`` command that draws previews: ``$IMPULSE_CLI``, else ``impulse`` on
    ``PATH``; None when neither names one."""
    import shutil

    named = os.environ.get("IMPULSE_CLI")
    if named:
        return named if os.path.exists(named) else shutil.which(named)
    return shutil.which("impulse")


def preview_path(directory, take_id):
    """The still of take ``take_id`` of the search in ``directory`` (it may not exist yet)."""
    return os.path.join(directory, PREVIEWS_DIR, f"{take_id}.png")


class PreviewJob:
    """Stills of takes' end states, drawn by ``impulse render`` in a background thread, one take
    after another (the UI stays usable; Blender's UI cannot animate a GIF, so the panel shows
    the last frame of what the contact sheet's GIF animates), framed as the contact sheet's
    ``goals`` camera frames its previews: on the moving bodies the goals name, where the goals
    read them (:func:`camera_arguments`).

    Each still is the take's scene (``take.scene()``, written beside it as
    ``previews/<take_id>.json``) simulated the search's ``steps`` with ``impulse render --out``
    and its last frame moved to :func:`preview_path` whole (``os.replace``), so a reader never
    sees half a file. Takes whose still exists are not drawn again. ``command`` is the
    ``impulse`` command (:func:`impulse_command`); a failed render is kept in ``errors``
    (take id → message, bodies named as in Blender) and the others go on; ``count`` is the
    number of stills it draws.
    """

    def __init__(self, takes, take_ids, command, size=PREVIEW_SIZE):
        import threading

        self.directory = takes.root
        self.command = command
        self.size = size
        self.steps = int(takes.manifest["steps"])
        self.preset = takes.manifest.get("preset")
        from impulse.takes._sheet import goal_views

        self.views = goal_views(takes.manifest.get("goals"))
        self.errors = {}
        self._todo = [
            takes[take_id]
            for take_id in take_ids
            if takes[take_id].status == "completed" and not os.path.exists(preview_path(self.directory, take_id))
        ]
        self.count = len(self._todo)
        os.makedirs(os.path.join(self.directory, PREVIEWS_DIR), exist_ok=True)
        self._thread = threading.Thread(target=self._draw_all, name="impulse take previews", daemon=True)
        self._thread.start()

    def _draw_all(self):
        for take in self._todo:
            try:
                self._draw(take)
            except (OSError, RuntimeError, ValueError) as error:
                self.errors[take.take_id] = str(error)

    def _draw(self, take):
        folder = os.path.join(self.directory, PREVIEWS_DIR)
        scene = os.path.join(folder, f"{take.take_id}.json")
        take.write_scene(scene)
        names = [body.get("name") for body in take.scene()["bodies"]]
        with tempfile.TemporaryDirectory(dir=folder) as frames:
            arguments = [self.command, "render", scene, "--out", frames, "--steps", str(self.steps)]
            arguments += ["--every", str(max(self.steps, 1)), "--size", "{}x{}".format(*self.size), "--quiet"]
            if self.preset:
                arguments += ["--preset", self.preset]
            arguments += camera_arguments(take.scene(), self.steps, self.views, self.size, self.preset)
            arguments += region_arguments(self.views)
            done = subprocess.run(arguments, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                said = done.stderr.strip().removeprefix("error: ") or f"exit code {done.returncode}"
                raise RuntimeError(f"impulse render of take {take.take_id} failed: {_named_bodies(said, names)}")
            os.replace(os.path.join(frames, f"frame_{self.steps:05d}.png"), preview_path(self.directory, take.take_id))

    def running(self):
        return self._thread.is_alive()

    def problem(self):
        """Why stills are missing, for the panel: the number not drawn and the first reason;
        empty when every still was drawn (or while none failed yet)."""
        errors = dict(self.errors)
        if not errors:
            return ""
        return f"No still for {len(errors)} of {self.count} takes: {next(iter(errors.values()))}"

    def wait(self):
        """Blocks until every still is drawn (or failed); returns ``errors``."""
        self._thread.join()
        return self.errors


def region_arguments(views):
    """``impulse render``'s ``--region`` flags outlining the goals' regions in magenta, as the
    contact sheet's previews do (``views`` from ``impulse.takes``' ``goal_views``)."""
    from impulse.takes._sheet import region_arguments as sheet_regions

    return sheet_regions(views)


def camera_arguments(scene, steps, views, size, preset=None):
    """``impulse render``'s ``--camera-eye``, ``--camera-target`` (m, impulse's axes) and
    ``--fov`` (degrees) that frame the moving bodies the goals look at in ``scene`` stepped ``steps`` times
    (``impulse.takes``' ``goals`` camera, the contact sheet's; ``views`` from its
    ``goal_views``), for a ``size`` (W, H) image; no flags (``impulse render``'s own view of
    the moving bodies at the start) when the goals look at no moving body."""
    from impulse.takes._sheet import goal_camera

    framed = goal_camera(scene, steps, views, size, preset)
    if framed is None:
        return []
    eye, target, fov = framed
    return [
        "--camera-eye",
        ",".join(f"{v:.9g}" for v in eye),
        "--camera-target",
        ",".join(f"{v:.9g}" for v in target),
        "--fov",
        f"{fov:.9g}",
    ]


def _named_bodies(message, names):
    """``message`` with the engine's ``body N`` named by the body's object name, where it has one."""
    import re

    def name(found):
        index = int(found.group(1))
        return f'body "{names[index]}"' if index < len(names) and names[index] else found.group(0)

    return re.sub(r"\bbody (\d+)", name, message)
