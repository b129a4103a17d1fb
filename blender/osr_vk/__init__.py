# osr-vk for Blender: a render engine that exports the scene to glTF, renders it with the
# osr-vk executable (One Shot Radiance or path tracing on Vulkan) and shows the image and its
# passes in Blender. User guide: docs/blender.md in the osr-vk repository.
bl_info = {
    "name": "osr-vk",
    "author": "osr-vk developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Render Engine > osr-vk",
    "description": "Render with osr-vk (One Shot Radiance global illumination on Vulkan)",
    "category": "Render",
}

import bpy

from . import engine


class OsrVkPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    executable: bpy.props.StringProperty(
        name="osr-vk executable", subtype="FILE_PATH", default="",
        description="Path of the osr-vk program; empty: next to the add-on, else on PATH")

    def draw(self, context):
        self.layout.prop(self, "executable")


class OsrVkSettings(bpy.types.PropertyGroup):
    mode: bpy.props.EnumProperty(
        name="Integrator", default="path",
        items=(("path", "Path tracing", "Path tracing with osr-vk's denoiser: the lowest error "
                "at equal time measured (docs/denoise.md)"),
               ("osr", "One Shot Radiance", "Progressive OSR passes: converges to path tracing"),
               ("preview", "Preview", "Primary hits: albedo times a headlight")))
    time_limit: bpy.props.FloatProperty(
        name="Time budget", default=0.0, min=0.0, soft_max=600.0, unit="TIME_ABSOLUTE",
        description="Stop after this many seconds (0: no limit; with a pass or sample count, "
                    "whichever ends first)")
    passes: bpy.props.IntProperty(
        name="Passes", default=32, min=0, soft_max=1024,
        description="Progressive OSR passes (0: osr-vk's default, or as many as the time allows)")
    samples: bpy.props.IntProperty(
        name="Samples", default=64, min=0, soft_max=65536,
        description="Samples per pixel for path tracing and preview (0: osr-vk's default)")
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0, description="Random seed")
    weights: bpy.props.StringProperty(
        name="Weights", subtype="FILE_PATH", default="",
        description="Packed U-Net weights (.osrw) for the OSR denoiser; empty: osr-vk's default")
    denoiser: bpy.props.EnumProperty(
        name="Denoiser", default="mode",
        description="Image denoiser on the Combined pass (docs/denoise.md); the raw colour "
                    "stays in the EXR's 'noisy' layer",
        items=(("mode", "Mode's default", "What osr-vk --help lists for the integrator"),
               ("network", "Learned", "The shipped image denoiser (--network default)"),
               ("atrous", "A-trous filter", "The edge-aware a-trous filter (--filter atrous)"),
               ("none", "None", "No denoising")))
    device: bpy.props.StringProperty(
        name="Device", default="",
        description="Vulkan device index or name (osr-vk --list-devices); empty: the default")
    one_run_per_animation: bpy.props.BoolProperty(
        name="One run per animation", default=True,
        description="Render Animation: export the scene once with its animation and render "
                    "every frame in one osr-vk --frames run (off: a fresh export and osr-vk run "
                    "per frame, as for scenes whose animation glTF cannot carry)")
    temporal_reuse: bpy.props.FloatProperty(
        name="Temporal reuse", default=3.0, min=0.0, max=64.0,
        description="Render Animation in one run: blend each frame with the frames before it "
                    "where they saw the same surface, their samples counting for at most this "
                    "many times the frame's own, in full under a still camera (osr-vk "
                    "--temporal-reuse; 0: every frame on its own, as F12 renders it)")
    keep_directory: bpy.props.StringProperty(
        name="Keep files in", subtype="DIR_PATH", default="",
        description="Write the exported glTF, the command line, the log and the EXR here and "
                    "keep them; empty: a temporary directory, removed after the render")


class RENDER_PT_osr_vk(bpy.types.Panel):
    bl_label = "osr-vk"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {engine.OsrVkRenderEngine.bl_idname}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.osr_vk
        layout.prop(settings, "mode")
        if settings.mode == "osr":
            layout.prop(settings, "passes")
            layout.prop(settings, "weights")
        else:
            layout.prop(settings, "samples")
        layout.prop(settings, "time_limit")
        layout.prop(settings, "denoiser")
        layout.prop(settings, "seed")
        layout.prop(settings, "device")
        prefs = engine.addon_preferences(context)
        if prefs is not None:
            layout.prop(prefs, "executable", text="Executable")
        layout.prop(settings, "one_run_per_animation")
        layout.prop(settings, "temporal_reuse")
        layout.prop(settings, "keep_directory")


def _compatible_panels():
    # Blender's own light, material, world and output panels work for this engine too.
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines and "BLENDER_EEVEE" in engines and getattr(panel, "bl_context", "") in {
                "material", "data", "world", "view_layer"}:
            yield panel


classes = (OsrVkPreferences, OsrVkSettings, engine.OsrVkRenderEngine, RENDER_PT_osr_vk)


@bpy.app.handlers.persistent
def _render_job_edge(*_):
    # A render job starts or ends (complete or cancelled): a shot still running (Render
    # Animation stopped between frames) is stopped, and the per-job decisions forgotten.
    engine.ANIMATIONS.reset()


_JOB_HANDLERS = (bpy.app.handlers.render_init, bpy.app.handlers.render_complete,
                 bpy.app.handlers.render_cancel)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.osr_vk = bpy.props.PointerProperty(type=OsrVkSettings)
    for panel in _compatible_panels():
        panel.COMPAT_ENGINES.add(engine.OsrVkRenderEngine.bl_idname)
    for handlers in _JOB_HANDLERS:
        if _render_job_edge not in handlers:
            handlers.append(_render_job_edge)


def unregister():
    for handlers in _JOB_HANDLERS:
        if _render_job_edge in handlers:
            handlers.remove(_render_job_edge)
    engine.ANIMATIONS.reset()
    for panel in _compatible_panels():
        panel.COMPAT_ENGINES.discard(engine.OsrVkRenderEngine.bl_idname)
    del bpy.types.Scene.osr_vk
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
