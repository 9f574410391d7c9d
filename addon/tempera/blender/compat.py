"""Differences between the Blender versions Tempera runs in, in one place.

Tested: Debian's Blender 3.4, blender.org 4.2 LTS, 4.5 LTS, 5.0, 5.2 LTS and
5.3 (PyPI bpy). Every function here works in all of them; the rest of the add-on, the scene scripts
(scenes/) and the in-Blender tests call these instead of testing versions
themselves. Each helper asks Blender for the feature (hasattr, enum items),
not for a version number, so a point release that back-ports a change is
handled too.

The breaks handled:

* 4.2: EEVEE's engine id became BLENDER_EEVEE_NEXT (and BLENDER_EEVEE again
  in 5.0): `eevee_engine()`.
* 4.0: Principled BSDF sockets renamed (Emission -> Emission Color,
  Specular -> Specular IOR Level, Transmission -> Transmission Weight, ...):
  `principled_socket()`.
* 4.4/5.0: layered actions; Action.fcurves is gone in 5.0 (the F-curves live
  in the channel bag of the ID's action slot): `action_fcurves()`.
* 5.0: ImageFormatSettings.media_type must be chosen before file_format
  (multilayer EXR is its own media type): `set_file_format()` and
  `IMAGE_FORMAT_SETTINGS` for saving and restoring.
* 5.0: Scene.node_tree is gone; the compositor is a node group in
  Scene.compositing_node_group: `compositor_node_tree()` (guide renders
  switch compositing off, so only scene scripts and tests need it).
* 5.0: multilayer EXR files name the render passes as the UI does
  ("Diffuse Direct", "Object Index"), where 3.x/4.x wrote "DiffDir",
  "IndexOB": `exr_pass_name()` picks the one a file holds.
* 4.1: Mesh.calc_normals_split() is gone, corner normals are always there
  (Mesh.corner_normals): `corner_normals()`.
* 4.0: lights have a soft falloff, on by default: `hard_light_falloff()`.
* 4.0: Cycles' lights changed: area lights emit their power (radiance
  P / (pi A), was P / (4 A)), spot lights lost the cosine to their axis, and
  point and spot lights with a radius are spheres unless Soft Falloff is on
  (then the disk facing the shaded point of 3.x): `cycles_light_model()`.
* 4.0: the Glass, Refraction and Glossy nodes lost the SHARP distribution
  (roughness 0 renders sharp): `set_sharp_distribution()`.
* 4.0: the Velvet BSDF node became the Sheen BSDF: `sheen_bsdf_node_type()`.
* 5.0: the Separate RGB node is gone (Separate Color, since 3.3, stays):
  `new_separate_rgb_node()`; the Cycles light setting Cast Shadow became
  Light.use_shadow: `set_light_cast_shadow()`; an empty material slot
  renders Blender's default material, a Principled BSDF, no longer Cycles'
  diffuse default surface: `default_surface_is_principled()`.
* 4.x: the AOV Output node names its AOV in .aov_name: `set_aov_output_name()`.
* 5.0: the sequencer's Scene.sequence_editor.sequences became .strips
  (available since 4.4): `sequencer_strips()`.
* The Image Editor's paint mode: SpaceImageEditor.mode "PAINT" (its
  ui_mode in versions that split the two): `image_paint_mode()`.
* 5.2: Cycles writes the camera's motion against the world into the Vector
  pass where no surface is hit; 3.4-5.0 and 5.3 write 0 there:
  `surface_vector_pass()`.

Two breaks of the list in issue 16 need no helper: Tempera reads its
settings as RNA properties only (never `scene["tempera"]`, which 5.0 no
longer maps to bpy.props properties), and it passes no context dictionary to
operators (4.0 removed that; Context.temp_override exists since 3.2).
"""
import bpy
import numpy as np

from ..app import passes

# Principled BSDF sockets: the name Tempera uses (Blender 3.x) -> the 4.0+ name.
PRINCIPLED_RENAMES = {
    "Emission": "Emission Color",
    "Specular": "Specular IOR Level",
    "Transmission": "Transmission Weight",
    "Subsurface": "Subsurface Weight",
    "Sheen": "Sheen Weight",
    "Clearcoat": "Coat Weight",
    "Clearcoat Roughness": "Coat Roughness",
}


def _enum_ids(struct, prop):
    return {item.identifier for item in struct.bl_rna.properties[prop].enum_items}


def eevee_engine():
    """The render engine id of EEVEE in this Blender."""
    engines = _enum_ids(bpy.context.scene.render, "engine")
    return "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in engines else "BLENDER_EEVEE"


def principled_socket(node, name):
    """The input socket `name` (3.x name) of a Principled BSDF node, under its
    name in this Blender. KeyError names both if neither exists."""
    inputs = node.inputs
    if name in inputs:
        return inputs[name]
    renamed = PRINCIPLED_RENAMES.get(name)
    if renamed is not None and renamed in inputs:
        return inputs[renamed]
    raise KeyError(f"{node.bl_idname} '{node.name}' has no input '{name}'"
                   + (f" nor '{renamed}'" if renamed else ""))


def action_fcurves(id_block):
    """The F-curves animating `id_block` (an object, camera, light, ...):
    Action.fcurves before 5.0, the channel bag of the ID's action slot in
    layered actions. An empty list if it is not animated."""
    anim = getattr(id_block, "animation_data", None)
    action = anim.action if anim is not None else None
    if action is None:
        return []
    if hasattr(action, "fcurves") and not hasattr(action, "layers"):
        return list(action.fcurves)
    slot = getattr(anim, "action_slot", None)
    if slot is None:
        return list(action.fcurves)
    from bpy_extras import anim_utils

    channelbag = anim_utils.action_get_channelbag_for_slot(action, slot)
    return list(channelbag.fcurves) if channelbag is not None else []


def _media_type(file_format):
    return "MULTI_LAYER_IMAGE" if file_format == "OPEN_EXR_MULTILAYER" else (
        "VIDEO" if file_format == "FFMPEG" else "IMAGE")


def has_media_type(image_settings):
    return "media_type" in image_settings.bl_rna.properties


def set_file_format(image_settings, file_format):
    """image_settings.file_format = file_format, choosing the media type
    first where Blender has one (5.0: the formats on offer depend on it)."""
    if has_media_type(image_settings):
        image_settings.media_type = _media_type(file_format)
    image_settings.file_format = file_format


# ImageFormatSettings that render code changes, in the order to restore them:
# media_type (5.0 only; callers skip the names a struct lacks) before
# file_format before color_depth (what is on offer depends on the one before).
IMAGE_FORMAT_SETTINGS = ("media_type", "file_format", "color_depth", "exr_codec", "color_mode", "use_preview")


def compositor_node_tree(scene, create=False):
    """The scene's compositor node tree (None if it has none): Scene.node_tree
    with use_nodes before 5.0, Scene.compositing_node_group in 5.0. With
    `create`, makes one."""
    if hasattr(scene, "compositing_node_group"):
        tree = scene.compositing_node_group
        if tree is None and create:
            tree = bpy.data.node_groups.new(f"{scene.name} Compositing", "CompositorNodeTree")
            scene.compositing_node_group = tree
        return tree
    if create and not scene.use_nodes:
        scene.use_nodes = True
    return scene.node_tree


def exr_pass_name(channels, layer, name):
    """The name the render pass `name` (short form, 'DiffDir') has in an EXR
    file with `channels`: see tempera.app.passes.stored_pass_name (no bpy there,
    so the guide readers outside Blender share it)."""
    return passes.stored_pass_name(channels, layer, name)


def corner_normals(mesh):
    """Per-corner (loop) normals of `mesh` as a float64 (loops, 3) array, as
    Cycles shades them: Mesh.corner_normals (4.1+), or calc_normals_split()
    and MeshLoop.normal before."""
    if hasattr(mesh, "corner_normals"):
        flat = np.empty(len(mesh.corner_normals) * 3, np.float64)
        mesh.corner_normals.foreach_get("vector", flat)
    else:
        mesh.calc_normals_split()
        flat = np.empty(len(mesh.loops) * 3, np.float64)
        mesh.loops.foreach_get("normal", flat)
    return flat.reshape(-1, 3)


def cycles_light_model(light):
    """How this Cycles renders `light` (a bpy Light), as the tracer's light
    fields: {"soft_shape": "disk" | "sphere", "spot_axis_cosine": bool,
    "area_emits_power": bool}. Cycles 4.0's lights came with the Soft Falloff
    option, so its presence tells them apart."""
    cycles4 = "use_soft_falloff" in bpy.types.PointLight.bl_rna.properties
    soft_falloff = bool(getattr(light, "use_soft_falloff", True))
    return {"soft_shape": "sphere" if cycles4 and not soft_falloff else "disk",
            "spot_axis_cosine": not cycles4, "area_emits_power": cycles4}


def cycles_closure_model():
    """Which microfacet closures this Cycles renders, as the tracer's
    closure_model: Cycles 4.0 rewrote them (height-correlated Smith
    shadowing; rough glass as one closure with the Fresnel of each
    microfacet). No RNA property of a registered type tells them apart (the
    node types are not in bpy.types until a node exists), so the version does.
    Cycles 4.0 also brought Principled v2 (coat, F82 metal, Lambertian diffuse
    under a dielectric layer), which the tracer models as "principled_v2".
    Cycles 4.3, the release that gave the Principled BSDF its Diffuse
    Roughness, made the Diffuse BSDF's roughness an energy-preserving
    Oren-Nayar (measured: 4.2 renders 3.x's, 4.5 and 5.0 the new one)."""
    cycles4 = bpy.app.version >= (4, 0, 0)
    return {"height_correlated_shadowing": cycles4, "microfacet_glass_fresnel": cycles4, "principled_v2": cycles4,
            "energy_preserving_oren_nayar": bpy.app.version >= (4, 3, 0)}


def set_sharp_distribution(node):
    """Makes a Glass, Refraction or Glossy BSDF node perfectly sharp: the SHARP
    distribution where it exists (3.x), else GGX of roughness 0, which Cycles
    4.0+ renders as sharp."""
    if "SHARP" in _enum_ids(node, "distribution"):
        node.distribution = "SHARP"
    else:
        node.distribution = "GGX"
        node.inputs["Roughness"].default_value = 0.0


def sheen_bsdf_node_type():
    """The node type of the Velvet BSDF (3.x), called Sheen BSDF since 4.0."""
    return "ShaderNodeBsdfVelvet" if hasattr(bpy.types, "ShaderNodeBsdfVelvet") else "ShaderNodeBsdfSheen"


def new_separate_rgb_node(tree):
    """A node in `tree` splitting a colour (input 0) into R, G, B (outputs
    0-2): Separate RGB where it exists (3.x, 4.x), else Separate Color."""
    kind = "ShaderNodeSeparateRGB" if hasattr(bpy.types, "ShaderNodeSeparateRGB") else "ShaderNodeSeparateColor"
    return tree.nodes.new(kind)


def set_light_cast_shadow(light, value):
    """A light's Cast Shadow: its Cycles setting before 5.0, Light.use_shadow in 5.0."""
    cycles = getattr(light, "cycles", None)
    if cycles is not None and "cast_shadow" in cycles.bl_rna.properties:
        cycles.cast_shadow = value
    else:
        light.use_shadow = value


def default_surface_is_principled():
    """Whether an empty material slot renders as Blender's default material
    (a Principled BSDF of its defaults: Blender 5.0, where every material
    renders its nodes: Material.use_nodes is deprecated there) rather than
    Cycles' default surface, a diffuse BSDF of 0.8 grey. No RNA feature
    tells this apart, so the version does (measured in the LPE gallery:
    the diffuse default leaves 5.0's empty slots' LSE 53 % low)."""
    return bpy.app.version >= (5, 0, 0)


def hard_light_falloff(light):
    """Turns off the soft falloff Cycles 4.0+ gives point, spot and area lights
    by default (no such option, and no soft falloff, before): Tempera's
    light-path tracer models the hard inverse-square falloff."""
    if "use_soft_falloff" in light.bl_rna.properties:
        light.use_soft_falloff = False


def set_aov_output_name(node, name):
    """Makes an AOV Output shader node write the AOV `name` (ShaderNodeOutputAOV.aov_name
    where it exists, the node's name in 3.x)."""
    if "aov_name" in node.bl_rna.properties:
        node.aov_name = name
    else:
        node.name = name


def sequencer_strips(editor):
    """The top-level strips of a sequence editor (.strips since 4.4, .sequences before)."""
    return editor.strips if hasattr(editor, "strips") else editor.sequences


def image_paint_mode(space):
    """Puts an Image Editor space into Paint mode (for the artist to paint a keyframe)."""
    for prop in ("mode", "ui_mode"):
        if prop in space.bl_rna.properties and "PAINT" in _enum_ids(space, prop):
            setattr(space, prop, "PAINT")
            return True
    return False


def surface_vector_pass(vector, alpha):
    """The Vector pass (H, W, 4) with 0 where the film is empty (alpha 0).

    Tempera's velocities are the motion of the surfaces the pixels see. Where
    a pixel sees only the world, Blender 3.4-5.0 and 5.3 write 0 (measured:
    every such pixel, exactly), but 5.2 writes the world's apparent motion as
    the camera turns (up to 7 px a frame on the Suzanne turntable), which made
    the coherent method advect its background by it. Rendering does not tell
    the two apart, so this applies in every version; where the pass is already
    0 there it changes nothing."""
    vector = np.asarray(vector, np.float32)
    empty = np.asarray(alpha).reshape(vector.shape[:2]) == 0
    if not empty.any():
        return vector
    return np.where(empty[:, :, None], np.float32(0), vector)
