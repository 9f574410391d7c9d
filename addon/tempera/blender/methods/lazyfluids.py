"""LazyFluids in the panel (docs/lazyfluids.md): smoke, fire and liquids
painted from an RGBA exemplar carried along the flow; the registry's job,
a frame per step, over the render."""
from bpy.props import BoolProperty, FloatProperty

from ... import _native
from ..layout import wide_prop
from ..stylize_operator import RgbaRun
from . import table_flags, table_properties

MEDIUM = True
EXEMPLAR_MASKS = False
OPTIONS = {row["name"]: row for row in _native.LazyFluidsOptions.table()}
# Options shown as the table has them: property -> (option, label, soft maximum).
TABLE_OPTIONS = {
    "lf_eta": ("alpha_guide_weight", "Boundary Shape (η)", 10.0),
    "lf_alpha_weight": ("alpha_weight", "Alpha Weight", 10.0),
    "lf_warm_start": ("warm_start", "Warm Start", None),
}
PROPERTIES = {
    "lf_lambda": FloatProperty(
        name="Temporal Coherence", default=OPTIONS["temporal_weight"]["default"],
        min=OPTIONS["temporal_weight"]["min"], soft_max=1.0,
        description="λ, the pull of the previous frame carried along the flow (thesis eq. 5.6): higher flickers less "
        "but lets the texture smear; 0 paints every frame afresh"),
    "lf_rotations": BoolProperty(
        name="Rotations", default=OPTIONS["rotations"]["default"],
        description="Also use the exemplar turned by 90, 180 and 270 degrees (more patches, for swirling flows)"),
    "lf_motion_blur": FloatProperty(
        name="Motion Blur", default=OPTIONS["motion_blur"]["default"], min=OPTIONS["motion_blur"]["min"],
        soft_max=16.0, subtype="PIXEL", description="Length in pixels of the blur along the flow; 0 = none"),
    **table_properties(OPTIONS, TABLE_OPTIONS),
}


def draw(box, settings):
    """The temporal pull, the rotated exemplars, the motion blur, the table's options, the seed."""
    col = box.column()
    wide_prop(col, settings, "lf_lambda")
    col.prop(settings, "lf_rotations")
    col.prop(settings, "lf_motion_blur")
    for prop in TABLE_OPTIONS:
        wide_prop(col, settings, prop)
    col.prop(settings, "seed")


class FluidRun(RgbaRun):
    """Guides, then LazyFluids: smoke, fire and liquids."""

    folder = "lazyfluids"
    method_label = "Fluid"
    seconds_per_mpix = 20.0  # wall, loaded 2-core machine (docs/benchmarks.md: 4.6-8.6 s per 0.26 Mpix)

    def job_options(self, settings):
        return {"lambda": float(settings.lf_lambda), "rotations": bool(settings.lf_rotations),
                "motion-blur": float(settings.lf_motion_blur), **table_flags(settings, OPTIONS, TABLE_OPTIONS)}


def run(scene, frames, mode):
    """Stylize Animation's run, and Stylize Frame's (the method on that frame alone)."""
    return FluidRun(scene, frames, mode)
