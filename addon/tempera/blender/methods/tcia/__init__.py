"""The coherent method in the panel (Bénard et al. 2013, docs/engine.md):
its painted keyframes and layers (.keyframes, .layers), its
settings, and Stylize Animation's run, one segment between keys per step
(tempera.methods.tcia.tcia.ShotJob; each resumable, Esc stops within a
segment and nothing of it is written). It shares StyLit's settings (quality,
usage, temporal weight, Temporal Noise) and extends StyLit's run; Stylize
Frame stays per-frame StyLit: a quick look, and the ground Add Keyframe
paints over."""
import time

import bpy
from bpy.props import BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, \
    StringProperty
from bpy.types import PropertyGroup

from ....app import guide_cache
from ....app.frames import MAX_FRAME
from ....methods.tcia import tcia
from . import keyframes, layers
from ...guide_operator import format_duration
from .keyframes import TEMPERA_OT_add_keyframe, TEMPERA_OT_import_keyframe, TEMPERA_OT_remove_keyframe, key_list
from .layers import TEMPERA_OT_add_tcia_layer, TEMPERA_OT_remove_tcia_layer, layer_list
from ...panels import draw_light_path_settings
from ...stylize_operator import StylizeRun, require_consecutive

MEDIUM = False
EXEMPLAR_MASKS = False

DEFAULT_KEYFRAME_DIR = "//tempera/keys/"


class TemperaKeyframe(PropertyGroup):
    """A painted keyframe of the coherent method (.keyframes)."""

    frame: IntProperty(name="Frame", description="The frame this painting is of", default=1, min=0,
                       max=MAX_FRAME)
    painting: StringProperty(name="Painting", subtype="FILE_PATH", default="",
                             description="The painted frame (the frame's size); '//' is relative to the .blend file")
    mask: StringProperty(name="Mask", subtype="FILE_PATH", default="",
                         description="Optional: where the key is painted (white); empty: the whole frame")
    layer: PointerProperty(name="Layer", type=bpy.types.Collection,
                           description="Optional: the key of this layer only (a collection of the Layers list); "
                           "empty: a key of the whole frame")


class TemperaLayer(PropertyGroup):
    """A layer of the coherent method (.layers): a collection painted and synthesized alone."""

    collection: PointerProperty(name="Collection", type=bpy.types.Collection,
                                description="The collection of this layer (its mask guide)")
    painting: StringProperty(name="Painting", subtype="FILE_PATH", default="",
                             description="Optional: this layer's own painting over the exemplar render (the "
                             "exemplar's size); empty: the shared painting")


LAYER_ORDERS = (
    ("depth", "By Depth", "Per frame, the nearer layer (median depth of its pixels) on top"),
    ("given", "List Order", "The first layer of the list at the back, the last on top"),
)


PROPERTIES = {
    "keyframes": CollectionProperty(type=TemperaKeyframe, name="Keyframes"),
    "keyframe_index": IntProperty(name="Active Keyframe", default=0, min=0),
    "line_weight": FloatProperty(
        name="Line Term",
        description="For line paintings (ink on paper): pulls the painting's ink onto the scene's lines (the "
        "guide cache's line distance, Bénard 2013 eq. 9); 0 = off, 4 typical",
        default=0.0, min=0.0, soft_max=10.0),
    "tcia_orientation": BoolProperty(
        name="Orientation from Guides",
        description="Patches turn with the guide cache's orientation (the render's structure, or your "
        "Orientation AOV), so strokes follow the surfaces (Bénard 2013 §3.1); needs the exemplar's too",
        default=False),
    "tcia_layers": CollectionProperty(type=TemperaLayer, name="Layers"),
    "tcia_layer_index": IntProperty(name="Active Layer", default=0, min=0),
    "tcia_layer_order": EnumProperty(name="Layer Order", items=LAYER_ORDERS, default="depth",
                                   description="How the layers' frames are stacked into the composite"),
    "keyframe_dir": StringProperty(
        name="Keyframe Folder",
        description="Where Add Keyframe saves the images to paint over ('//' is beside the .blend file)",
        subtype="DIR_PATH", default=DEFAULT_KEYFRAME_DIR),
}

# Registered before Scene.tempera: the property groups of its lists, then their lists and operators.
CLASSES = (TemperaKeyframe, TemperaLayer, *keyframes.CLASSES, *layers.CLASSES)


def draw(box, settings):
    """The keyframes and layers, then StyLit's settings, which the method shares."""
    draw_keyframes(box, settings)
    draw_light_path_settings(box, settings, warm_start=False)


def draw_list(box, settings, items, index, add, remove, rows):
    """The list `settings.<items>` (drawn by TEMPERA_UL_<items>, selection
    `settings.<index>`) with its add and remove operators' buttons beside it."""
    row = box.row()
    row.template_list(f"TEMPERA_UL_{items}", "", settings, items, settings, index, rows=rows)
    side = row.column(align=True)
    side.operator(add.bl_idname, text="", icon="ADD")
    side.operator(remove.bl_idname, text="", icon="REMOVE")


def draw_keyframes(box, settings):
    """The painted keyframes: the list and its buttons."""
    box.label(text="Keyframes (painted frames the shot follows)")
    draw_list(box, settings, "keyframes", "keyframe_index", TEMPERA_OT_add_keyframe, TEMPERA_OT_remove_keyframe,
              rows=3)
    row = box.row(align=True)
    row.operator(TEMPERA_OT_add_keyframe.bl_idname, text="Add Keyframe", icon="KEYFRAME")
    row.operator(TEMPERA_OT_import_keyframe.bl_idname, text="Import Key", icon="IMPORT")
    if 0 <= settings.keyframe_index < len(settings.keyframes):
        key = settings.keyframes[settings.keyframe_index]
        col = box.column(align=True)
        col.prop(key, "painting")
        col.prop(key, "mask")
        if len(settings.tcia_layers):
            col.prop(key, "layer")
    box.prop(settings, "keyframe_dir")
    box.prop(settings, "line_weight")
    box.prop(settings, "tcia_orientation")
    draw_layers(box, settings)


def draw_layers(box, settings):
    """The coherent method's layers, picked from collections."""
    box.label(text="Layers (collections painted separately)")
    draw_list(box, settings, "tcia_layers", "tcia_layer_index", TEMPERA_OT_add_tcia_layer,
              TEMPERA_OT_remove_tcia_layer, rows=2)
    if 0 <= settings.tcia_layer_index < len(settings.tcia_layers):
        layer = settings.tcia_layers[settings.tcia_layer_index]
        col = box.column(align=True)
        col.prop(layer, "collection")
        col.prop(layer, "painting")
    if len(settings.tcia_layers):
        box.prop(settings, "tcia_layer_order")


class CoherentRun(StylizeRun):
    """Guides of every frame, then the coherent method, one segment per step."""

    def __init__(self, scene, frames, mode="ANIMATION"):
        super().__init__(scene, frames, mode)
        require_consecutive(self.frames, "The coherent method")
        self.keys = [k for k in key_list(scene.tempera) if self.frames[0] <= k[0] <= self.frames[-1]]
        self.layers = layer_list(scene.tempera, (self.frames[0], self.frames[-1]))
        layer_keys = [k[0] for layer in self.layers for k in layer[3]]
        self.segments = tcia.segments(self.frames, [k[0] for k in self.keys] + layer_keys)
        self.segment_results = []
        self.line_weight = float(scene.tempera.line_weight)
        self.orientation = bool(scene.tempera.tcia_orientation)
        self.layer_order = scene.tempera.tcia_layer_order
        if self.layers:  # their collections' masks
            self.guides.params["masks"] = guide_cache.masks_including(self.guides.params["masks"], "CO")

    @property
    def stylize_steps(self):
        return len(self.segments)

    def _stylize(self, progress):
        c = self.config
        if self.job is None:
            self.job = tcia.ShotJob(c["style"], c["exemplar_guides"], c["guides"], self.frames, c["out"],
                               exemplar_frame=c.get("exemplar_frame"), keys=self.keys, weights=c["weights"],
                               format=c["format"], seed=c["seed"],
                               lines={"weight": self.line_weight, "d_max": self.guides.params["line_d_max"]},
                               layers=self.layers, layer_order=self.layer_order, orientation=self.orientation)
            self.warnings = list(self.job.warnings)
        i = self.index - len(self.frames)
        started = time.monotonic()
        result = self.job.run_segment(i, None if progress is None else lambda d: progress(d["fraction"]))
        if result["status"] == "stylized":
            self.stylize_seconds += time.monotonic() - started
        self.segment_results.append(result)
        for frame in self.job.segments[i][2]:
            self.results.append({"frame": frame, "path": self.job.output_path(frame), "status": result["status"]})
        if bpy.app.background:
            first, last = self.segments[i]
            print(f"Tempera: segment {i + 1}/{len(self.segments)} (frames {first}-{last}) {result['status']} "
                  f"in {time.monotonic() - started:.1f} s", flush=True)

    def current_frame(self):
        if self.in_guide_phase or self.in_noise_phase:
            return super().current_frame()
        return self.segments[min(self.index - len(self.frames), len(self.segments) - 1)][0]

    def eta_seconds(self):
        stylized = [r for r in self.segment_results if r["status"] == "stylized"]
        left = len(self.segments) - len(self.segment_results)
        if not stylized or left <= 0:
            return None
        return self.stylize_seconds / len(stylized) * left

    def status_text(self):
        if self.in_guide_phase or self.in_noise_phase:
            return super().status_text()
        i = min(len(self.segment_results), len(self.segments) - 1)
        eta = self.eta_seconds()
        first, last = self.segments[i]
        eta_text = "" if eta is None else f", ETA {format_duration(eta)}"
        return (f"Tempera: coherent segment {i + 1}/{len(self.segments)} (frames {first}-{last}){eta_text} "
                "(Esc to stop)")


def run(scene, frames, mode):
    """Stylize Animation's run; Stylize Frame stays per-frame StyLit (None)."""
    return CoherentRun(scene, frames, mode) if mode == "ANIMATION" else None
