"""The operator "Bake with impulse", its settings and its panels."""

import bpy

from .impulse_bake import bake, scene_reader

#: Frames a modal bake simulates between two looks at the event queue, at most, and the wall
#: time it spends doing so (s): short enough that the interface answers, long enough that the
#: bake is not slowed by redrawing.
CHUNK_FRAMES = 50
CHUNK_SECONDS = 0.1


class ImpulseBakeSettings(bpy.types.PropertyGroup):
    """The panel's settings, stored on the scene."""

    preset: bpy.props.EnumProperty(
        name="Quality",
        description="impulse's solver preset: more substeps cost more and hold stacks better",
        items=(
            ("fast", "Fast",
             "The soft step at 480 substeps a second, without impact sweeps, contacts kept within 2 cm: cheapest"),
            ("default", "Default", "The soft step at 1,200 substeps a second"),
            ("precise", "Precise", "The soft step at 2,880 substeps a second: slowest"),
        ),
        default="default",
    )
    substeps: bpy.props.IntProperty(
        name="Substeps",
        description="Substeps per step; 0 takes the preset's rate of substeps a second",
        default=0,
        min=0,
        soft_max=200,
    )
    materials: bpy.props.EnumProperty(
        name="Materials",
        description="How two objects' Friction and Bounciness combine",
        items=(
            ("blender", "Blender", "Friction multiplied as Blender (Bullet) does; Bounciness the larger of the two"),
            ("impulse", "impulse", "impulse's own rules: the geometric mean of the frictions, the larger Bounciness"),
        ),
        default="blender",
    )
    mesh_resolution: bpy.props.IntProperty(
        name="Mesh Detail",
        description=(
            "Voxels along the longest side when a moving object's Mesh shape is split into convex parts; "
            "0 takes impulse's default (64). A hole or wall thinner than about one voxel is closed"
        ),
        default=0,
        min=0,
        max=512,
    )
    steps_per_frame: bpy.props.IntProperty(
        name="Steps per Frame",
        description="Simulation steps per frame (contacts are found once a step); 0 keeps a step within 1/60 s",
        default=0,
        min=0,
        soft_max=16,
    )
    split_overlap: bpy.props.FloatProperty(
        name="Split Steps",
        description=(
            "A step that leaves two moving objects overlapping by more than this is taken again in halves, "
            "with contacts found again (at most four pieces); 0 is off. Thin or fast objects at one step a frame"
        ),
        default=0.0,
        min=0.0,
        soft_max=0.01,
        precision=4,
        subtype="DISTANCE",
        unit="LENGTH",
    )
    collision_steps: bpy.props.IntProperty(
        name="Collision Steps",
        description=(
            "At most this many collision steps a step, each finding contacts again, where two objects move "
            "farther than their thickness against each other within it (eight times as many where one is thinner "
            "than 5 mm, a card); 1 is off. Fast or thin objects stay right at one step a frame"
        ),
        default=4,
        min=1,
        soft_max=8,
    )


def _bake_report(baker, cancelled):
    state = "cancelled at" if cancelled else "baked"
    return (
        f"impulse: {state} {baker.frames_done}/{baker.total_frames} frames of "
        f"{len(baker.dynamic)} objects (simulation {baker.simulation_seconds:.2f} s, "
        f"keyframes {baker.write_seconds:.2f} s)"
    )


class IMPULSE_OT_bake(bpy.types.Operator):
    """Simulate the Rigid Body World with impulse and write keyframes on its active objects
    (replacing an earlier bake; Blender's own simulation is then turned off). A refused or
    cancelled bake leaves the earlier bake as it was"""

    bl_idname = "impulse.bake"
    bl_label = "Bake with impulse"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012  (Blender reads it as a class attribute)

    _baker = None
    _timer = None

    @classmethod
    def poll(cls, context):
        world = context.scene.rigidbody_world if context.scene else None
        return world is not None and world.collection is not None

    def _start(self, context):
        settings = context.scene.impulse_bake
        try:
            baker = bake.Baker(
                context.scene,
                settings.preset,
                settings.substeps,
                settings.steps_per_frame,
                settings.materials,
                settings.mesh_resolution,
                settings.split_overlap,
                settings.collision_steps,
            )
        except scene_reader.UnsupportedScene as error:
            self.report({"ERROR"}, "impulse: not baked (the earlier bake is kept): " + "; ".join(error.problems))
            return None
        except (ValueError, RuntimeError, ImportError) as error:
            # impulse's SceneError / WorldError / StepError, or a missing package.
            self.report({"ERROR"}, f"impulse: {error}")
            return None
        for warning in baker.info.warnings:
            self.report({"WARNING"}, f"impulse: {warning}")
        for note in baker.info.notes:
            self.report({"INFO"}, f"impulse: {note}")
        return baker

    def execute(self, context):
        baker = self._start(context)
        if baker is None:
            return {"CANCELLED"}
        try:
            baker.advance()
        except RuntimeError as error:
            self.report({"ERROR"}, f"impulse: {error}; not baked (the earlier bake is kept)")
            return {"CANCELLED"}
        baker.write()
        self.report({"INFO"}, _bake_report(baker, cancelled=not baker.done))
        return {"FINISHED"}

    def invoke(self, context, event):
        baker = self._start(context)
        if baker is None:
            return {"CANCELLED"}
        IMPULSE_OT_bake._baker = baker
        window_manager = context.window_manager
        window_manager.progress_begin(0, baker.total_frames)
        IMPULSE_OT_bake._timer = window_manager.event_timer_add(0.01, window=context.window)
        window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _finish(self, context, cancelled, failure=None):
        baker = IMPULSE_OT_bake._baker
        window_manager = context.window_manager
        window_manager.event_timer_remove(IMPULSE_OT_bake._timer)
        window_manager.progress_end()
        context.workspace.status_text_set(None)
        IMPULSE_OT_bake._baker = None
        IMPULSE_OT_bake._timer = None
        if failure is not None or cancelled:
            reason = f"{failure}; " if failure is not None else ""
            self.report({"WARNING"}, f"impulse: {reason}cancelled at frame {baker.frames_done}: the earlier bake is kept")
            return {"CANCELLED"}
        baker.write()
        self.report({"INFO"}, _bake_report(baker, cancelled))
        return {"FINISHED"}

    def modal(self, context, event):
        baker = IMPULSE_OT_bake._baker
        if event.type == "ESC":
            return self._finish(context, cancelled=True)
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            baker.advance(max_frames=CHUNK_FRAMES, max_seconds=CHUNK_SECONDS)
        except RuntimeError as error:
            return self._finish(context, cancelled=True, failure=error)
        context.window_manager.progress_update(baker.frames_done)
        context.workspace.status_text_set(
            f"impulse: frame {baker.frames_done}/{baker.total_frames} (Esc cancels, keeping the earlier bake)"
        )
        if baker.done:
            return self._finish(context, cancelled=False)
        return {"RUNNING_MODAL"}


class IMPULSE_OT_free_bake(bpy.types.Operator):
    """Remove impulse's keyframes from the Rigid Body World's objects (each back at its start
    pose, animated objects' own animation back) and turn Blender's own simulation on again"""

    bl_idname = "impulse.free_bake"
    bl_label = "Free impulse Bake"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012  (Blender reads it as a class attribute)

    @classmethod
    def poll(cls, context):
        world = context.scene.rigidbody_world if context.scene else None
        return world is not None and world.collection is not None

    def execute(self, context):
        freed = bake.free_bake(context.scene)
        self.report({"INFO"}, f"impulse: freed the bake of {freed} objects; Blender's simulation is on")
        return {"FINISHED"}


def _draw(layout, context):
    settings = context.scene.impulse_bake
    column = layout.column()
    column.prop(settings, "preset")
    column.prop(settings, "materials")
    column.prop(settings, "mesh_resolution")
    column.prop(settings, "substeps")
    column.prop(settings, "steps_per_frame")
    column.prop(settings, "split_overlap")
    column.prop(settings, "collision_steps")
    row = column.row()
    row.operator(IMPULSE_OT_bake.bl_idname, icon="PHYSICS")
    row.operator(IMPULSE_OT_free_bake.bl_idname, icon="TRASH")


class SCENE_PT_impulse_bake(bpy.types.Panel):
    """A subpanel of the Rigid Body World panel of the Scene properties."""

    bl_label = "Bake with impulse"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "scene"
    bl_parent_id = "SCENE_PT_rigid_body_world"

    @classmethod
    def poll(cls, context):
        return context.scene.rigidbody_world is not None

    def draw(self, context):
        _draw(self.layout, context)


class PHYSICS_PT_impulse_bake(bpy.types.Panel):
    """In the Physics properties of a rigid body object."""

    bl_label = "Bake with impulse"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "physics"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.rigid_body is not None and context.scene.rigidbody_world is not None

    def draw(self, context):
        _draw(self.layout, context)


_classes = (ImpulseBakeSettings, IMPULSE_OT_bake, IMPULSE_OT_free_bake, SCENE_PT_impulse_bake, PHYSICS_PT_impulse_bake)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.impulse_bake = bpy.props.PointerProperty(type=ImpulseBakeSettings)


def unregister():
    del bpy.types.Scene.impulse_bake
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
