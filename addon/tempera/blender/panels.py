"""Properties editor > Output tab > Tempera: the buttons and the frames they
use on top, then one box per step of the workflow (exemplar, light paths,
synthesis, output, guides). Labels fit the default Properties width: long
rows are split in two."""
import os

import bpy
from bpy.types import Panel

from .. import __version__
from . import methods, noise_pass
from .guide_operator import TEMPERA_OT_render_guides, cache_status
from .layout import wide_prop
from .kit_operators import (TEMPERA_OT_choose_painting, TEMPERA_OT_painting_template, TEMPERA_OT_register_painting,
                            painting_preview)
from .properties import WEIGHT_PROPERTIES
from .results import is_result_scene
from .setting_paths import exemplar_paths
from .stylize_operator import TEMPERA_OT_stylize

THUMBNAIL_SCALE = 6.0
# Labels shortened in the panel to fit its default width (the tooltip keeps the full name).
SHORT_LABELS = {"weight_ld12e": "Two Diffuse Bounces"}
STATUS_WIDTH = 38  # characters per status line at the default Properties width


def status_lines(layout, text, icon):
    """A long status or error text on as many lines as it takes (a label
    is cut at the editor's edge, not wrapped)."""
    import textwrap

    col = layout.column(align=True)
    for i, line in enumerate(textwrap.wrap(text, STATUS_WIDTH) or [""]):
        col.label(text=line, icon=icon if i == 0 else "BLANK1")


class TEMPERA_PT_output(Panel):
    bl_label = "Tempera"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"

    @classmethod
    def poll(cls, context):
        # Not in the scene that shows a result: stylizing it would stylize the stylized frames.
        return context.scene is not None and hasattr(context.scene, "tempera") and not is_result_scene(context.scene)

    def draw_header_preset(self, _context):
        self.layout.label(text=f"v{__version__}")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.tempera

        col = layout.column(align=True)
        row = col.row(align=True)
        row.operator(TEMPERA_OT_stylize.bl_idname, text="Stylize Frame", icon="RENDER_STILL").mode = "FRAME"
        row.operator(TEMPERA_OT_stylize.bl_idname, text="Stylize Animation", icon="RENDER_ANIMATION").mode = "ANIMATION"
        col.operator(TEMPERA_OT_render_guides.bl_idname, text="Render Guides Only", icon="RENDERLAYERS")
        draw_frames(layout.column(), settings)

        side = methods.side(settings.method)
        if side is not None and side.MEDIUM:  # an exemplar of the medium, no light-path guides
            draw_media_exemplar(layout.box(), settings, side.EXEMPLAR_MASKS)
        else:
            draw_exemplar(layout.box(), settings)
            draw_light_paths(layout.box(), settings)
        draw_synthesis(layout.box(), settings)
        draw_output(layout.box(), settings)
        draw_guides(layout.box(), context.scene, settings)


def draw_frames(col, settings):
    """The frames Stylize Animation (and Render Guides) use, next to their buttons."""
    col.prop(settings, "guide_frame_range")
    if settings.guide_frame_range == "CUSTOM":
        sub = col.column(align=True)
        sub.prop(settings, "guide_frame_start", text="Start")
        sub.prop(settings, "guide_frame_end", text="End")


def draw_exemplar(box, settings):
    box.label(text="Exemplar", icon="BRUSH_DATA")
    box.prop(settings, "exemplar_source")
    if settings.exemplar_source == "CUSTOM":
        row = box.row(align=True)
        row.prop(settings, "exemplar_style")
        row.operator(TEMPERA_OT_choose_painting.bl_idname, text="", icon="FILE_IMAGE")
        box.prop(settings, "exemplar_guide_dir")
        box.prop(settings, "exemplar_frame")
    draw_thumbnail(box, settings)
    row = box.row(align=True)
    row.operator(TEMPERA_OT_painting_template.bl_idname, text="Painting Template", icon="FILE_BLANK")
    row.operator(TEMPERA_OT_register_painting.bl_idname, text="Register Photo", icon="IMAGE_DATA")


def draw_thumbnail(box, settings):
    """A thumbnail of the painting the exemplar setting points at (loaded
    once per file version by the preview system, not decoded by draw())."""
    try:
        path = exemplar_painting_path(settings)
    except (ValueError, OSError):
        return
    preview = painting_preview(path)
    if preview is not None:
        box.template_icon(icon_value=preview.icon_id, scale=THUMBNAIL_SCALE)
        box.label(text=os.path.basename(path))


def exemplar_painting_path(settings):
    if settings.exemplar_source == "KIT":
        return exemplar_paths(settings)[0]
    path = bpy.path.abspath(settings.exemplar_style.strip()) if settings.exemplar_style.strip() else ""
    if not path or not os.path.isfile(path):
        raise FileNotFoundError(path)
    return path


def draw_light_paths(box, settings):
    box.label(text="Light Path Guides", icon="LIGHT")
    col = box.column(align=True)
    for prop in WEIGHT_PROPERTIES.values():
        wide_prop(col, settings, prop, SHORT_LABELS.get(prop))


def draw_synthesis(box, settings):
    box.label(text="Synthesis", icon="MOD_REMESH")
    box.prop(settings, "method")
    side = methods.side(settings.method)
    if side is not None:  # the method's own module (tempera.blender.methods)
        side.draw(box, settings)
    else:
        draw_light_path_settings(box, settings)


def draw_light_path_settings(box, settings, warm_start=True):
    """The light-path methods' settings (StyLit's, which the coherent method shares but for the warm
    start: its sweeps carry their own) and the Temporal Noise pass after them."""
    col = box.column()
    col.prop(settings, "quality")
    col.prop(settings, "usage")
    wide_prop(col, settings, "temporal_weight")
    if warm_start:
        col.prop(settings, "warm_start")
    col.prop(settings, "patch_size")
    col.prop(settings, "seed")
    noise_pass.draw(box, settings)


def draw_media_exemplar(box, settings, masks):
    """The exemplar of a medium: a still, a sequence or a movie (and, where
    the method takes them, its masks)."""
    box.label(text="Exemplar", icon="BRUSH_DATA")
    box.prop(settings, "media_exemplar_kind")
    box.prop(settings, "media_exemplar")
    if masks:
        box.prop(settings, "media_masks")


def draw_output(box, settings):
    box.label(text="Output", icon="OUTPUT")
    box.prop(settings, "output_dir")
    if settings.output_dir.startswith("//") and not bpy.data.filepath:
        col = box.column(align=True)
        col.label(text="Save the .blend file first:", icon="ERROR")
        col.label(text="'//' is relative to it")
    col = box.column()
    col.prop(settings, "output_format")
    col.prop(settings, "make_video")
    col.prop(settings, "load_result")


def draw_guides(box, scene, settings):
    """The Guides box: settings of the guide cache and its status."""
    box.label(text="Guides", icon="RENDERLAYERS")
    box.prop(settings, "guide_dir")
    col = box.column()
    col.prop(settings, "guide_samples")
    col.prop(settings, "guide_occlusion_epsilon")
    col.prop(settings, "guide_line_d_max")
    col.prop(settings, "guide_masks")
    col.prop(settings, "guide_orientation_aov")
    wide_prop(col, settings, "guide_lpe")
    if settings.guide_lpe.strip():
        col.prop(settings, "guide_lpe_samples")
    try:
        text, icon = cache_status(scene)
    except Exception as exc:  # a status line must never break the panel
        text, icon = f"Guide cache status unavailable: {exc}", "ERROR"
    status_lines(box, text, icon)
