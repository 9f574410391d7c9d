"""Fluidymation in the panel (docs/fluidymation.md): a moving object or
collection painted by a filmed medium spreading along its motion; the
registry's job, a frame per step, over the render."""
import os

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty

from ... import _native
from ...app import guide_cache
from ..layout import wide_prop
from ..setting_paths import resolve_path
from ..stylize_operator import RgbaRun
from . import table_flags, table_properties

MEDIUM = True
EXEMPLAR_MASKS = True
OPTIONS = {row["name"]: row for row in _native.FluidymationOptions.table()}
# Options shown as the table has them: property -> (option, label, soft maximum).
TABLE_OPTIONS = {
    "fm_boundary_weight": ("boundary_weight", "Boundary (w_b)", 10.0),
    "fm_direction_weight": ("direction_weight", "Direction (w_d)", 10.0),
    "fm_extent_weight": ("extent_weight", "Motion Extent (w_e)", 2.0),
    "fm_temporal_weight": ("temporal_weight", "Temporal (w_t)", 10.0),
    "fm_uniformity_weight": ("uniformity_weight", "Uniformity (w_u)", 10.0),
}
FLOWS = (
    ("AUTO", "Automatic", "Fluid Velocity when the scene has smoke or liquids, else Blender Motion"),
    ("FLUID", "Fluid Velocity", "A smoke or liquid's velocity from its simulation (the guide cache's "
     "fluid_velocity; the render's motion is zero on volumes)"),
    ("GUIDES", "Blender Motion", "The target's exact motion from the render (the guide cache's velocity)"),
    ("MASKS", "From Masks", "Motion estimated from the target's masks alone (signed distance, diffusion fill, "
     "temporal smoothing; Fluidymation App. A)"),
)
PROPERTIES = {
    "fm_target_object": PointerProperty(
        name="Target Object", type=bpy.types.Object,
        description="The object the medium fills (its mask guide); empty: the collection below, else everything "
        "rendered (the render's alpha)"),
    "fm_target_collection": PointerProperty(
        name="Target Collection", type=bpy.types.Collection,
        description="The collection the medium fills (its mask guide), when no Target Object is set"),
    "fm_flow": EnumProperty(name="Flow", items=FLOWS, default="AUTO",
                            description="Where the target's motion comes from"),
    "fm_bidirectional": BoolProperty(
        name="Bidirectional", default=OPTIONS["bidirectional"]["default"],
        description="A forward and a backward pass merged (the paper's future work): the medium also leads "
        "into where the target will be; twice the time"),
    **table_properties(OPTIONS, TABLE_OPTIONS),
}


def draw(box, settings):
    """The target (its mask guide), the flow, the two passes, the table's options, the seed."""
    col = box.column()
    col.prop(settings, "fm_target_object")
    if settings.fm_target_object is None:
        col.prop(settings, "fm_target_collection")
    col.prop(settings, "fm_flow")
    col.prop(settings, "fm_bidirectional")
    for prop in TABLE_OPTIONS:
        wide_prop(col, settings, prop)
    col.prop(settings, "seed")


class MediaRun(RgbaRun):
    """Guides (with the target's mask), then Fluidymation: a moving object or collection as a medium."""

    folder = "fluidymation"
    method_label = "Natural Media"
    seconds_per_mpix = 25.0  # wall, 2 cores (docs/benchmarks.md: 2.5 s idle, 14 s loaded per 0.3 Mpix)
    kinds = ("SEQUENCE", "MOVIE")

    def __init__(self, scene, frames, mode="ANIMATION"):
        super().__init__(scene, frames, mode)
        settings = scene.tempera
        masks = settings.media_masks.strip()
        self.exemplar_masks = resolve_path(masks, "exemplar Masks folder") if masks else None
        if self.exemplar_masks is not None and not os.path.isdir(self.exemplar_masks):
            raise FileNotFoundError(f"The exemplar Masks folder '{self.exemplar_masks}' does not exist.")
        self.target_mask = "alpha"  # everything rendered
        target = settings.fm_target_object or settings.fm_target_collection
        if target is not None:
            kind = "OB" if settings.fm_target_object is not None else "CO"
            self.target_mask = guide_cache.mask_guide(kind, target.name)
            self.guides.params["masks"] = guide_cache.masks_including(self.guides.params["masks"], kind)
        self.options["target-mask"] = self.target_mask
        if self.exemplar_masks is not None:
            self.options["exemplar-masks"] = self.exemplar_masks

    def job_options(self, settings):
        return {"flow": settings.fm_flow.lower(), "bidirectional": bool(settings.fm_bidirectional),
                **table_flags(settings, OPTIONS, TABLE_OPTIONS)}


def run(scene, frames, mode):
    """Stylize Animation's run, and Stylize Frame's (the method on that frame alone)."""
    return MediaRun(scene, frames, mode)
