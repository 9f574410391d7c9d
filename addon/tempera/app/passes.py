"""Blender render passes as stored in multilayer EXR files.

Blender (Cycles, 3.x/4.x) names multilayer EXR channels
"<view layer>.<pass>.<component>", e.g. "ViewLayer.DiffDir.R"; Blender 5.0
writes the passes' UI names instead ("ViewLayer.Diffuse Direct.R"), and
readers here accept both (LONG_NAMES, stored_pass_name). This module
knows the passes Tempera uses as guides: their channel components and the
ViewLayer property that enables each, so that code building a render setup
and code reading its output agree on one table.
"""
from dataclasses import dataclass

from .._native import image_info, read_image


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


# Render passes in multilayer EXR files: the short names of 3.x/4.x -> 5.0's.
LONG_NAMES = {
    "DiffDir": "Diffuse Direct", "DiffInd": "Diffuse Indirect", "DiffCol": "Diffuse Color",
    "GlossDir": "Glossy Direct", "GlossInd": "Glossy Indirect", "GlossCol": "Glossy Color",
    "TransDir": "Transmission Direct", "TransInd": "Transmission Indirect", "TransCol": "Transmission Color",
    "IndexOB": "Object Index", "IndexMA": "Material Index", "Emit": "Emission", "Env": "Environment",
    "AO": "Ambient Occlusion",
}


def stored_pass_name(channels, view_layer, pass_name):
    """The name under which the pass `pass_name` (short form, e.g. 'DiffDir')
    is stored in an EXR with `channels`: the short name or 5.0's long one,
    whichever the file has (the short one if neither, so that the error
    names what was asked for)."""
    for candidate in (pass_name, LONG_NAMES.get(pass_name)):
        if candidate and any(c.startswith(f"{view_layer}.{candidate}.") for c in channels):
            return candidate
    return pass_name


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
    names = channel_names(pass_name, view_layer)
    stored = stored_pass_name(image_info(str(path))["channels"], view_layer, pass_name)
    if stored != pass_name:
        names = [f"{view_layer}.{stored}.{n.rsplit('.', 1)[1]}" for n in names]
    return read_image(str(path), names)
