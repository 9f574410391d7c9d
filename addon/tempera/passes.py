"""Blender render passes as stored in multilayer EXR files.

Blender (Cycles, 3.x/4.x) names multilayer EXR channels
"<view layer>.<pass>.<component>", e.g. "ViewLayer.DiffDir.R". This module
knows the passes Tempera uses as guides: their channel components and the
ViewLayer property that enables each, so that code building a render setup
and code reading its output agree on one table.
"""
from dataclasses import dataclass

from ._native import read_image


@dataclass(frozen=True)
class RenderPass:
    name: str  # the pass name in EXR channel names
    components: str  # one letter per channel, in reading order
    view_layer_property: str  # bpy ViewLayer boolean that enables the pass
    description: str


PASSES = {
    p.name: p
    for p in (
        RenderPass("Combined", "RGBA", "use_pass_combined", "beauty image, linear scene-referred"),
        RenderPass("DiffDir", "RGB", "use_pass_diffuse_direct", "direct diffuse lighting (without albedo)"),
        RenderPass("DiffInd", "RGB", "use_pass_diffuse_indirect", "indirect diffuse lighting"),
        RenderPass("DiffCol", "RGB", "use_pass_diffuse_color", "diffuse albedo"),
        RenderPass("GlossDir", "RGB", "use_pass_glossy_direct", "direct glossy reflection (without colour)"),
        RenderPass("GlossCol", "RGB", "use_pass_glossy_color", "glossy colour"),
        RenderPass("Normal", "XYZ", "use_pass_normal", "world-space shading normal"),
        RenderPass("Vector", "XYZW", "use_pass_vector", "motion vectors in pixels: XY relative to the previous frame, ZW to the next"),
        RenderPass("Depth", "Z", "use_pass_z", "camera distance"),
    )
}


def channel_names(pass_name, view_layer="ViewLayer"):
    """EXR channel names of one pass, e.g. ['ViewLayer.DiffDir.R', ...G, ...B]."""
    try:
        render_pass = PASSES[pass_name]
    except KeyError:
        raise ValueError(f"unknown render pass {pass_name!r}; known passes: {', '.join(PASSES)}") from None
    return [f"{view_layer}.{pass_name}.{c}" for c in render_pass.components]


def read_pass(path, pass_name, view_layer="ViewLayer"):
    """One pass of a multilayer EXR as a float32 (H, W, C) array.

    Raises FileNotFoundError / OSError naming the file, or ValueError naming
    the missing channel and listing the channels the file has.
    """
    return read_image(str(path), channel_names(pass_name, view_layer))
