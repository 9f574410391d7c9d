"""Properties editor > Output tab > Tempera: the buttons on top, then one box
per step of the workflow (exemplar, light paths, synthesis, output, guides)."""
import bpy
from bpy.types import Panel

from .. import __version__
from .guide_operator import TEMPERA_OT_render_guides, cache_status
from .properties import WEIGHT_PROPERTIES
from .stylize_operator import TEMPERA_OT_stylize


class TEMPERA_PT_output(Panel):
    bl_label = "Tempera"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.tempera

        layout.label(text=f"Version {__version__}")
        row = layout.row(align=True)
        row.operator(TEMPERA_OT_render_guides.bl_idname, icon="RENDERLAYERS")
        row.operator(TEMPERA_OT_stylize.bl_idname, text="Stylize Frame", icon="RENDER_STILL").mode = "FRAME"
        row.operator(TEMPERA_OT_stylize.bl_idname, text="Stylize Animation", icon="RENDER_ANIMATION").mode = "ANIMATION"

        draw_exemplar(layout.box(), settings)
        draw_light_paths(layout.box(), settings)
        draw_synthesis(layout.box(), settings)
        draw_output(layout.box(), settings)
        draw_guides(layout.box(), context.scene, settings)


def draw_exemplar(box, settings):
    box.label(text="Exemplar", icon="BRUSH_DATA")
    box.prop(settings, "exemplar_source")
    if settings.exemplar_source == "CUSTOM":
        box.prop(settings, "exemplar_style")
        box.prop(settings, "exemplar_guide_dir")
        box.prop(settings, "exemplar_frame")


def draw_light_paths(box, settings):
    box.label(text="Light Path Guides", icon="LIGHT")
    col = box.column(align=True)
    for prop in WEIGHT_PROPERTIES.values():
        col.prop(settings, prop)


def draw_synthesis(box, settings):
    box.label(text="Synthesis", icon="MOD_REMESH")
    col = box.column()
    col.prop(settings, "quality")
    col.prop(settings, "usage")
    col.prop(settings, "temporal_weight")
    col.prop(settings, "patch_size")
    col.prop(settings, "seed")


def draw_output(box, settings):
    box.label(text="Output", icon="OUTPUT")
    box.prop(settings, "output_dir")
    if settings.output_dir.startswith("//") and not bpy.data.filepath:
        box.label(text="Save the .blend file first: '//' is relative to it", icon="ERROR")
    col = box.column()
    col.prop(settings, "output_format")
    col.prop(settings, "make_video")
    col.prop(settings, "load_result")


def draw_guides(box, scene, settings):
    """The Guides box: settings of the guide cache and its status."""
    box.label(text="Guides", icon="RENDERLAYERS")
    box.prop(settings, "guide_dir")
    box.prop(settings, "guide_frame_range")
    if settings.guide_frame_range == "CUSTOM":
        col = box.column(align=True)
        col.prop(settings, "guide_frame_start")
        col.prop(settings, "guide_frame_end")
    col = box.column()
    col.prop(settings, "guide_samples")
    col.prop(settings, "guide_occlusion_epsilon")
    col.prop(settings, "guide_line_d_max")
    col.prop(settings, "guide_masks")
    col.prop(settings, "guide_orientation_aov")
    col.prop(settings, "guide_lpe")
    if settings.guide_lpe.strip():
        col.prop(settings, "guide_lpe_samples")
    try:
        text, icon = cache_status(scene)
    except Exception as exc:  # a status line must never break the panel
        text, icon = f"Guide cache status unavailable: {exc}", "ERROR"
    box.label(text=text, icon=icon)
