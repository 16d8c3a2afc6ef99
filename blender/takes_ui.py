"""The "Takes" panels and operators: goals set on objects, a search run in the background, the
best takes listed with a still of each one's end, and "Bake take" (docs/blender.md, "Takes")."""

import os

import bpy
import bpy.utils.previews

from .impulse_bake import scene_reader
from .impulse_bake import takes as takes_logic

#: How often a running search's progress is looked at (s).
POLL_SECONDS = 0.5
#: How many of the best takes the panel lists.
LISTED = 20
#: How large the chosen take's still is drawn under the list (times a UI icon).
PREVIEW_SCALE = 6.0

#: The stills loaded as icons (``bpy.utils.previews``), keyed by the PNG's path; made in
#: :func:`register`.
_previews = None
#: The stills being drawn for the last search (an ``impulse_bake.takes.PreviewJob``).
_preview_job = None

_FACES = (
    ("NONE", "None", "No face goal"),
    ("POS_Z", "+Z", "The object's local +Z axis ends up (pointing along world +Z), at rest"),
    ("NEG_Z", "-Z", "The object's local -Z axis ends up, at rest"),
    ("POS_X", "+X", "The object's local +X axis ends up, at rest"),
    ("NEG_X", "-X", "The object's local -X axis ends up, at rest"),
    ("POS_Y", "+Y", "The object's local +Y axis ends up, at rest"),
    ("NEG_Y", "-Y", "The object's local -Y axis ends up, at rest"),
)


def _region_poll(_settings, obj):
    return takes_logic.is_region(obj)


def _body_poll(_settings, obj):
    return obj.rigid_body is not None


class ImpulseTakeGoals(bpy.types.PropertyGroup):
    """An object's goals for a takes search, and whether the search varies it."""

    vary: bpy.props.BoolProperty(
        name="Vary",
        description="A search may vary this object's start (position, rotation, velocity, spin)",
        default=True,
    )
    region: bpy.props.PointerProperty(
        name="Ends Inside",
        description="An Empty displayed as a Cube: the object's origin ends inside its box",
        type=bpy.types.Object,
        poll=_region_poll,
    )
    face_up: bpy.props.EnumProperty(
        name="Ends Face Up",
        description="The local axis that ends pointing up (world +Z) with the object at rest",
        items=_FACES,
        default="NONE",
    )
    face_tolerance: bpy.props.FloatProperty(
        name="Tolerance", description="Largest angle between the axis and up", default=10.0, min=0.1, max=90.0
    )
    rest_speed: bpy.props.FloatProperty(
        name="Rest Speed",
        description="At rest: speed (m/s) and spin (rad/s) at the end frame at most this",
        default=0.05,
        min=1e-4,
        soft_max=1.0,
    )
    hits: bpy.props.PointerProperty(
        name="Hits",
        description="Another rigid body the object touches at some frame",
        type=bpy.types.Object,
        poll=_body_poll,
    )


class ImpulseTake(bpy.types.PropertyGroup):
    """One listed take of the last search."""

    take_id: bpy.props.StringProperty(name="Take")
    met: bpy.props.BoolProperty(name="Met", description="Every goal is met")
    cost: bpy.props.FloatProperty(name="Cost", description="Sum of the goals' costs (0: every goal met)")
    perturbation: bpy.props.FloatProperty(
        name="Perturbation", description="Size of the variation (RMS in units of the scales): smaller is more plausible"
    )


class ImpulseTakesSettings(bpy.types.PropertyGroup):
    """The search's settings and its result, stored on the scene."""

    position: bpy.props.FloatProperty(
        name="Position", description="Scale of the start position offsets (m)", default=0.0, min=0.0, unit="LENGTH"
    )
    angle: bpy.props.FloatProperty(
        name="Angle", description="Scale of the start rotation offsets (degrees)", default=30.0, min=0.0, max=180.0
    )
    velocity: bpy.props.FloatProperty(
        name="Velocity", description="Scale of the start velocity offsets (m/s)", default=1.0, min=0.0
    )
    angular_velocity: bpy.props.FloatProperty(
        name="Spin", description="Scale of the start spin offsets (rad/s)", default=3.0, min=0.0
    )
    budget: bpy.props.IntProperty(name="Budget", description="Most takes to simulate", default=200, min=1)
    population: bpy.props.IntProperty(
        name="Per Generation", description="Takes per generation of the cross-entropy search", default=16, min=2
    )
    stop_after: bpy.props.IntProperty(
        name="Stop After", description="Stop once this many takes meet every goal", default=3, min=1
    )
    seed: bpy.props.IntProperty(name="Seed", description="Seed of the search's draws", default=0, min=0)
    workers: bpy.props.IntProperty(
        name="Workers", description="Worker processes; 0 uses every core", default=0, min=0, soft_max=64
    )
    directory: bpy.props.StringProperty(name="Results", description="The last search's directory", subtype="DIR_PATH")
    previews_note: bpy.props.StringProperty(
        name="Previews", description="Why the listed takes have no stills, when they have none"
    )
    search_note: bpy.props.StringProperty(
        name="Search", description="Why the last search failed (its child process's error), when it failed"
    )
    takes: bpy.props.CollectionProperty(type=ImpulseTake)
    active: bpy.props.IntProperty(name="Take", default=0)


def _request(scene):
    bake_settings, settings = scene.impulse_bake, scene.impulse_takes
    variation = {
        "position": settings.position,
        "angle": settings.angle,
        "velocity": settings.velocity,
        "angular_velocity": settings.angular_velocity,
    }
    return takes_logic.build_request(
        scene,
        variation,
        seed=settings.seed,
        population=settings.population,
        preset=bake_settings.preset,
        substeps=bake_settings.substeps,
        frame_steps=bake_settings.steps_per_frame,
        materials=bake_settings.materials,
        resolution=bake_settings.mesh_resolution,
    )


def _list_takes(settings, found):
    settings.takes.clear()
    for take in found.best(LISTED):
        item = settings.takes.add()
        item.take_id = take.take_id
        item.met = take.met
        item.cost = -1.0 if take.cost is None else take.cost
        item.perturbation = take.perturbation
    settings.active = 0


def _draw_previews(settings, found, wait):
    """Starts drawing the listed takes' stills (``impulse render`` in a background thread);
    with ``wait``, returns when they are drawn. Without the ``impulse`` command the list has
    no stills and ``settings.previews_note`` says why. Returns the job, or None."""
    global _preview_job
    command = takes_logic.impulse_command()
    if command is None:
        settings.previews_note = "No stills: the impulse command is not found (set IMPULSE_CLI or put it on PATH)"
        return None
    settings.previews_note = ""
    _preview_job = takes_logic.PreviewJob(found, [item.take_id for item in settings.takes], command)
    if wait:
        _preview_job.wait()
        settings.previews_note = _preview_job.problem()
    elif not bpy.app.timers.is_registered(_redraw_while_drawing):
        bpy.app.timers.register(_redraw_while_drawing, first_interval=POLL_SECONDS)
    return _preview_job


def _redraw_while_drawing():
    """Timer: redraws the Properties editors while stills are being drawn, so each appears
    when it is ready; ends with the job, noting on the scenes listing its takes why stills
    are missing, if any are."""
    job = _preview_job
    running = job is not None and job.running()
    if job is not None and not running:
        for scene in bpy.data.scenes:
            settings = getattr(scene, "impulse_takes", None)
            if settings is not None and _same_path(settings.directory, job.directory):
                settings.previews_note = job.problem()
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "PROPERTIES":
                area.tag_redraw()
    return POLL_SECONDS if running else None


def _same_path(a, b):
    return bool(a) and os.path.realpath(bpy.path.abspath(a)) == os.path.realpath(b)


def preview(directory, take_id):
    """The ``bpy.types.ImagePreview`` of take ``take_id``'s still (the end of the take) in the
    search in ``directory``, loaded on first use; None when there is none (yet)."""
    if _previews is None or not directory:
        return None
    path = takes_logic.preview_path(bpy.path.abspath(directory), take_id)
    found = _previews.get(path)
    if found is None and os.path.exists(path):
        found = _previews.load(path, path, "IMAGE")
    return found


def preview_icon(directory, take_id):
    """The icon id of take ``take_id``'s still for the UI; 0 when there is none (yet), and
    always without a UI (Blender run in the background makes no icons)."""
    found = preview(directory, take_id)
    return 0 if found is None else found.icon_id


class IMPULSE_OT_takes_search(bpy.types.Operator):
    """Search for takes that meet the objects' goals: simulate varied starts of the Rigid Body
    World with impulse in a background process (every core), keeping the best takes. Esc stops
    it, keeping the takes found so far"""

    bl_idname = "impulse.takes_search"
    bl_label = "Search Takes"
    bl_options = {"REGISTER"}  # noqa: RUF012  (Blender reads it as a class attribute)

    _job = None
    _timer = None

    @classmethod
    def poll(cls, context):
        world = context.scene.rigidbody_world if context.scene else None
        return world is not None and world.collection is not None and IMPULSE_OT_takes_search._job is None

    def _fail(self, settings, message):
        """Reports ``message`` and keeps it in the panel (``search_note``) until the next search."""
        settings.search_note = message
        self.report({"ERROR"}, f"impulse: {message}")

    def _start(self, context):
        scene = context.scene
        settings = scene.impulse_takes
        settings.search_note = ""
        try:
            request = _request(scene)
            directory = takes_logic.search_directory(bpy.data.filepath, request)
            job = takes_logic.SearchJob(directory, request, settings.budget, settings.stop_after, settings.workers)
        except scene_reader.UnsupportedScene as error:
            self._fail(settings, "no search: " + "; ".join(error.problems))
            return None
        except (ValueError, RuntimeError, ImportError, OSError) as error:
            self._fail(settings, str(error))
            return None
        return job

    def _done(self, context, job, wait_for_previews):
        """Lists the ended search's best takes and starts their stills: drawn before returning
        when ``wait_for_previews`` (run from a script), else in the background (the panel)."""
        settings = context.scene.impulse_takes
        try:
            found = job.finish()
        except (RuntimeError, OSError, ValueError, ImportError) as error:
            # The takes listed before stay, with the directory they are read from.
            self._fail(settings, str(error))
            return {"CANCELLED"}
        settings.directory = job.directory
        _list_takes(settings, found)
        _draw_previews(settings, found, wait=wait_for_previews)
        met = len(found.met())
        self.report({"INFO"}, f"impulse: {len(found)} takes, {met} meet every goal ({settings.directory})")
        return {"FINISHED"}

    def execute(self, context):
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        job.process.wait()
        return self._done(context, job, wait_for_previews=True)

    def invoke(self, context, event):
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        IMPULSE_OT_takes_search._job = job
        window_manager = context.window_manager
        window_manager.progress_begin(0, job.budget)
        IMPULSE_OT_takes_search._timer = window_manager.event_timer_add(POLL_SECONDS, window=context.window)
        window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _end_modal(self, context):
        window_manager = context.window_manager
        window_manager.event_timer_remove(IMPULSE_OT_takes_search._timer)
        window_manager.progress_end()
        context.workspace.status_text_set(None)
        IMPULSE_OT_takes_search._job = None
        IMPULSE_OT_takes_search._timer = None

    def modal(self, context, event):
        job = IMPULSE_OT_takes_search._job
        if event.type == "ESC":
            job.cancel()
            self._end_modal(context)
            return self._done(context, job, wait_for_previews=False) if job.takes_done() else {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        done = job.takes_done()
        context.window_manager.progress_update(done)
        context.workspace.status_text_set(f"impulse: {done}/{job.budget} takes (Esc stops, keeping them)")
        if job.running():
            return {"RUNNING_MODAL"}
        self._end_modal(context)
        return self._done(context, job, wait_for_previews=False)


class IMPULSE_OT_bake_take(bpy.types.Operator):
    """Bake the chosen take as keyframes, as "Bake with impulse" bakes the scene: the take's
    varied start simulated with the same settings (replacing an earlier bake)"""

    bl_idname = "impulse.bake_take"
    bl_label = "Bake Take"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012  (Blender reads it as a class attribute)

    take_id: bpy.props.StringProperty(name="Take", description="The take's id; empty: the one chosen in the list")

    @classmethod
    def poll(cls, context):
        settings = context.scene.impulse_takes if context.scene else None
        return settings is not None and len(settings.takes) > 0

    def execute(self, context):
        from impulse.takes import load

        scene = context.scene
        settings, bake_settings = scene.impulse_takes, scene.impulse_bake
        take_id = self.take_id or settings.takes[min(settings.active, len(settings.takes) - 1)].take_id
        try:
            found = load(bpy.path.abspath(settings.directory))
            baker = takes_logic.bake_take(
                scene,
                found,
                take_id,
                bake_settings.preset,
                bake_settings.substeps,
                bake_settings.steps_per_frame,
                bake_settings.materials,
                bake_settings.mesh_resolution,
            )
        except scene_reader.UnsupportedScene as error:
            self.report({"ERROR"}, "impulse: not baked (the earlier bake is kept): " + "; ".join(error.problems))
            return {"CANCELLED"}
        except (KeyError, ValueError, RuntimeError, OSError) as error:
            self.report({"ERROR"}, f"impulse: not baked: {error}")
            return {"CANCELLED"}
        self.report(
            {"INFO"}, f"impulse: baked take {take_id}: {baker.frames_done} frames of {len(baker.dynamic)} objects"
        )
        return {"FINISHED"}


#: Characters a line of a note in the panel holds (a label does not wrap; it is cut).
NOTE_WIDTH = 60


def _wrapped(column, text, icon):
    """``text`` as labels of :data:`NOTE_WIDTH` characters at most, the first with ``icon``."""
    import textwrap

    for index, line in enumerate(textwrap.wrap(text, NOTE_WIDTH, break_on_hyphens=False) or [""]):
        column.label(text=line, icon=icon if index == 0 else "BLANK1")


class IMPULSE_UL_takes(bpy.types.UIList):
    """The listed takes: the still of its end, id, every goal met, cost, perturbation."""

    def draw_item(self, _context, layout, data, item, _icon, _active_data, _active_property, _index=0, _flt_flag=0):
        row = layout.row(align=True)
        icon = preview_icon(data.directory, item.take_id)
        if icon:
            row.label(text="", icon_value=icon)
        row.label(text=item.take_id, icon="CHECKMARK" if item.met else "X")
        row.label(text="failed" if item.cost < 0 else f"cost {item.cost:.3g}")
        row.label(text=f"pert. {item.perturbation:.2f}")


class SCENE_PT_impulse_takes(bpy.types.Panel):
    """Takes: the search settings, the best takes and Bake Take, under the Rigid Body World."""

    bl_label = "impulse Takes"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "scene"
    bl_parent_id = "SCENE_PT_rigid_body_world"
    bl_options = {"DEFAULT_CLOSED"}  # noqa: RUF012  (Blender reads it as a class attribute)

    @classmethod
    def poll(cls, context):
        return context.scene.rigidbody_world is not None

    def draw(self, context):
        settings = context.scene.impulse_takes
        layout = self.layout
        column = layout.column(heading="Vary")
        for name in ("position", "angle", "velocity", "angular_velocity"):
            column.prop(settings, name)
        column = layout.column()
        for name in ("budget", "population", "stop_after", "seed", "workers"):
            column.prop(settings, name)
        column.operator(IMPULSE_OT_takes_search.bl_idname, icon="VIEWZOOM")
        if settings.search_note:
            _wrapped(layout.column(align=True), settings.search_note, "ERROR")
        if settings.directory:
            column.label(text=settings.directory)
        layout.template_list("IMPULSE_UL_takes", "", settings, "takes", settings, "active", rows=4)
        if settings.previews_note:
            _wrapped(layout.column(align=True), settings.previews_note, "INFO")
        if 0 <= settings.active < len(settings.takes):
            # Blender's UI draws no GIF animation: the chosen take's still is its last frame.
            icon = preview_icon(settings.directory, settings.takes[settings.active].take_id)
            if icon:
                layout.template_icon(icon_value=icon, scale=PREVIEW_SCALE)
        layout.operator(IMPULSE_OT_bake_take.bl_idname, icon="PHYSICS")


class PHYSICS_PT_impulse_take_goals(bpy.types.Panel):
    """An object's goals for a takes search, in its Physics properties."""

    bl_label = "impulse Takes: Goals"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "physics"
    bl_options = {"DEFAULT_CLOSED"}  # noqa: RUF012  (Blender reads it as a class attribute)

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.rigid_body is not None and context.scene.rigidbody_world is not None

    def draw(self, context):
        goals = context.object.impulse_takes
        column = self.layout.column()
        column.prop(goals, "vary")
        column.prop(goals, "region")
        column.prop(goals, "face_up")
        if goals.face_up != "NONE":
            column.prop(goals, "face_tolerance")
            column.prop(goals, "rest_speed")
        column.prop(goals, "hits")


_classes = (
    ImpulseTakeGoals,
    ImpulseTake,
    ImpulseTakesSettings,
    IMPULSE_OT_takes_search,
    IMPULSE_OT_bake_take,
    IMPULSE_UL_takes,
    SCENE_PT_impulse_takes,
    PHYSICS_PT_impulse_take_goals,
)


def register():
    global _previews
    _previews = bpy.utils.previews.new()
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.impulse_takes = bpy.props.PointerProperty(type=ImpulseTakeGoals)
    bpy.types.Scene.impulse_takes = bpy.props.PointerProperty(type=ImpulseTakesSettings)


def unregister():
    global _previews, _preview_job
    if bpy.app.timers.is_registered(_redraw_while_drawing):
        bpy.app.timers.unregister(_redraw_while_drawing)
    if _previews is not None:
        bpy.utils.previews.remove(_previews)
    _previews, _preview_job = None, None
    del bpy.types.Scene.impulse_takes
    del bpy.types.Object.impulse_takes
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
