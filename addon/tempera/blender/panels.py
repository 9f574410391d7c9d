"""Properties editor > Output tab > Tempera."""
import bpy
from bpy.types import Panel

from .. import __version__
from .guide_operator import TEMPERA_OT_render_guides, cache_status


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
        layout.prop(settings, "output_dir")
        if settings.output_dir.startswith("//") and not bpy.data.filepath:
            layout.label(text="Save the .blend file first: '//' is relative to it", icon="ERROR")
        col = layout.column()
        col.prop(settings, "patch_size")
        col.prop(settings, "seed")

        draw_guides(layout.box(), context.scene, settings)


def draw_guides(box, scene, settings):
    """The Guides box: settings of the guide cache, its status and Render Guides."""
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
    box.operator(TEMPERA_OT_render_guides.bl_idname, icon="RENDER_ANIMATION")
