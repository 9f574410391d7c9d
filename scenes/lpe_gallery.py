"""The validation gallery of the light-path tracer: small scenes, one per
feature of Cycles the exporter and tracer model (docs/lpe_guides.md,
"Validation gallery"), each rendered by Cycles and traced at matched
settings by blender_tests/test_lpe_gallery.py and docs/make_lpe_figures.py.

    scene = build("mix_glossy_diffuse")      # a bpy scene, 80 x 60
    remove(scene)

Every scene has a floor and a back wall (Diffuse BSDF, grey 0.5), one or two
objects carrying the feature, and the same camera. Names are in SCENES.
"""
import math

import bmesh
import bpy
import numpy as np
from mathutils import Vector

import lpe_scene  # noqa: E402  (scenes/, beside this file)

SIZE = (80, 60)
BOUNCES = 6


# --------------------------------------------------------------------------- materials

def _tree(name):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    return mat, tree, tree.nodes["Material Output"]


def _node(tree, kind, **inputs):
    node = tree.nodes.new(kind)
    for key, value in inputs.items():
        if key.startswith("_"):
            setattr(node, key[1:], value)
        else:
            node.inputs[key].default_value = value
    return node


def _compat():
    """tempera.blender.compat, imported when a scene is built (the add-on is installed by then)."""
    from tempera.blender import compat

    return compat


def _rgba(c):
    return (*c, 1.0)


def diffuse(name, color):
    mat, tree, out = _tree(name)
    node = _node(tree, "ShaderNodeBsdfDiffuse", Color=_rgba(color))
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def mix_glossy_diffuse(name, color, roughness, fac, distribution="GGX", fac_node=None):
    """Mix Shader of a Diffuse BSDF (first) and a white Glossy BSDF (second)."""
    mat, tree, out = _tree(name)
    d = _node(tree, "ShaderNodeBsdfDiffuse", Color=_rgba(color))
    g = _node(tree, "ShaderNodeBsdfGlossy", Roughness=roughness, _distribution=distribution)
    mix = _node(tree, "ShaderNodeMixShader", Fac=fac)
    if fac_node is not None:
        kind, settings, output = fac_node
        f = _node(tree, kind, **settings)
        tree.links.new(f.outputs[output], mix.inputs["Fac"])
    tree.links.new(d.outputs[0], mix.inputs[1])
    tree.links.new(g.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def _image(name, pixels, float_buffer=True, colorspace=None):
    h, w = pixels.shape[:2]
    image = bpy.data.images.new(name, w, h, float_buffer=float_buffer)
    if colorspace:  # before the pixels: changing it regenerates a generated image
        image.colorspace_settings.name = colorspace
    rgba = np.dstack([pixels[:, :, :3], np.ones((h, w))]) if pixels.shape[2] == 3 else pixels
    image.pixels.foreach_set(rgba[::-1].astype(np.float32).ravel())  # Blender stores rows bottom-up
    return image


def smooth_texture(size=32):
    """Smoothly varying colours (no sharp texel edges: filtering order does not matter)."""
    y, x = np.mgrid[0:size, 0:size] / size
    return np.dstack([0.5 + 0.4 * np.sin(2 * np.pi * x), 0.5 + 0.4 * np.cos(2 * np.pi * y),
                      0.3 + 0.2 * np.sin(2 * np.pi * (x + y))])


def grouped_textured(name):
    """A node group wrapping a Diffuse + Glossy Add, fed an image texture
    through Mapping (scale 2) and a Multiply Mix; roughness from a Math node."""
    group = bpy.data.node_groups.new(f"{name} group", "ShaderNodeTree")
    if hasattr(group, "interface"):  # Blender 4
        group.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
        group.interface.new_socket("Gloss", in_out="INPUT", socket_type="NodeSocketFloat")
        group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    else:
        group.inputs.new("NodeSocketColor", "Color")
        group.inputs.new("NodeSocketFloat", "Gloss")
        group.outputs.new("NodeSocketShader", "Shader")
    g_in = group.nodes.new("NodeGroupInput")
    g_out = group.nodes.new("NodeGroupOutput")
    d = _node(group, "ShaderNodeBsdfDiffuse")
    g = _node(group, "ShaderNodeBsdfGlossy", Roughness=0.3, _distribution="GGX")
    mix = _node(group, "ShaderNodeMixShader")
    group.links.new(g_in.outputs["Color"], d.inputs["Color"])
    group.links.new(g_in.outputs["Gloss"], mix.inputs["Fac"])
    group.links.new(d.outputs[0], mix.inputs[1])
    group.links.new(g.outputs[0], mix.inputs[2])
    group.links.new(mix.outputs[0], g_out.inputs["Shader"])

    mat, tree, out = _tree(name)
    tex = _node(tree, "ShaderNodeTexImage")
    tex.image = _image(f"{name} texture", smooth_texture())
    coords = _node(tree, "ShaderNodeTexCoord")
    mapping = _node(tree, "ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (2.0, 2.0, 1.0)
    tree.links.new(coords.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    tint = _node(tree, "ShaderNodeMixRGB", Fac=1.0, Color2=(1.0, 0.8, 0.6, 1.0), _blend_type="MULTIPLY")
    tree.links.new(tex.outputs["Color"], tint.inputs["Color1"])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.inputs["Gloss"].default_value = 0.2
    tree.links.new(tint.outputs[0], node.inputs["Color"])
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def principled_rough_texture(name):
    """Principled metal whose roughness comes from a texture's red channel through Separate RGB."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    tree = mat.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.9, 0.6, 0.3, 1)
    bsdf.inputs["Metallic"].default_value = 1.0
    y, x = np.mgrid[0:16, 0:16] / 16
    rough = 0.25 + 0.2 * np.sin(2 * np.pi * x)
    tex = _node(tree, "ShaderNodeTexImage")
    tex.image = _image(f"{name} roughness", np.dstack([rough, rough, rough]), colorspace="Non-Color")
    sep = _compat().new_separate_rgb_node(tree)
    tree.links.new(tex.outputs["Color"], sep.inputs[0])
    tree.links.new(sep.outputs[0], bsdf.inputs["Roughness"])
    return mat


def emission(name, color, strength):
    mat, tree, out = _tree(name)
    node = _node(tree, "ShaderNodeEmission", Color=_rgba(color), Strength=strength)
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def leaf(name):
    """Mix of Translucent and Diffuse (a leaf-like card), and a Transparent mix."""
    mat, tree, out = _tree(name)
    t = _node(tree, "ShaderNodeBsdfTranslucent", Color=(0.3, 0.7, 0.2, 1))
    d = _node(tree, "ShaderNodeBsdfDiffuse", Color=(0.2, 0.5, 0.1, 1))
    mix = _node(tree, "ShaderNodeMixShader", Fac=0.4)
    tree.links.new(d.outputs[0], mix.inputs[1])
    tree.links.new(t.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def veil(name):
    """60 % transparent, 40 % diffuse orange."""
    mat, tree, out = _tree(name)
    tr = _node(tree, "ShaderNodeBsdfTransparent", Color=(1, 1, 1, 1))
    d = _node(tree, "ShaderNodeBsdfDiffuse", Color=(0.9, 0.4, 0.1, 1))
    mix = _node(tree, "ShaderNodeMixShader", Fac=0.6)
    tree.links.new(d.outputs[0], mix.inputs[1])
    tree.links.new(tr.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def glass(name):
    mat, tree, out = _tree(name)
    node = _node(tree, "ShaderNodeBsdfGlass", Color=(0.9, 0.95, 1.0, 1), IOR=1.45)
    _compat().set_sharp_distribution(node)
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


# --------------------------------------------------------------------------- geometry

def _mesh_object(scene, name, build, materials, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1),
                 smooth=False):
    bm = bmesh.new()
    build(bm)
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    for polygon in mesh.polygons:
        polygon.use_smooth = smooth
    for mat in materials:
        mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    scene.collection.objects.link(obj)
    return obj


def plane(bm):
    bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.0, calc_uvs=True)


def sphere(radius):
    return lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=radius, calc_uvs=True)


def cube(size):
    return lambda bm: bmesh.ops.create_cube(bm, size=size, calc_uvs=True)


def _aim(location, target):
    return (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def base_scene(name, floor=None, wall=None, wall_material=True, size=SIZE):
    scene = bpy.data.scenes.new(name)
    scene.render.engine = "CYCLES"
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.frame_start = scene.frame_end = scene.frame_current = 1
    c = scene.cycles
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = BOUNCES
    c.transparent_max_bounces = 8
    c.blur_glossy = 0.0  # Filter Glossy changes roughness after bounces; not modelled
    scene.world = None
    _mesh_object(scene, "Floor", plane, [floor or diffuse(f"{name} floor", (0.5, 0.5, 0.5))],
                 scale=(3.0, 2.5, 1))
    if wall_material:
        _mesh_object(scene, "Wall", plane, [wall or diffuse(f"{name} wall", (0.55, 0.45, 0.35))],
                     location=(0, 2.0, 1.2), rotation=(math.radians(90), 0, 0), scale=(3.0, 1.2, 1))
    camera = bpy.data.objects.new(f"{name} camera", bpy.data.cameras.new(f"{name} camera"))
    camera.data.lens = 35
    camera.location = (0.0, -5.2, 2.3)
    camera.rotation_euler = _aim(camera.location, (0.0, 0.4, 0.6))
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def add_light(scene, kind, power, location, target=(0, 0, 0), **settings):
    data = bpy.data.lights.new(f"{scene.name} {kind}", kind)
    data.energy = power
    for key, value in settings.items():
        setattr(data, key, value)
    lamp = bpy.data.objects.new(f"{scene.name} {kind} light", data)
    lamp.location = location
    lamp.rotation_euler = _aim(location, target)
    scene.collection.objects.link(lamp)
    return lamp


def environment_image(name, width=128, height=64, sun=(math.radians(40), math.radians(35)), rgb=True):
    """An equirectangular HDRI: a sky gradient and a soft bright sun disc."""
    v = (np.arange(height)[::-1] + 0.5) / height  # row 0 is the top (v = 1)
    u = (np.arange(width) + 0.5) / width
    uu, vv = np.meshgrid(u, v)
    elevation = (vv - 0.5) * np.pi
    azimuth = (0.5 - uu) * 2 * np.pi
    d = np.dstack([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    s = np.array([math.cos(sun[1]) * math.cos(sun[0]), math.cos(sun[1]) * math.sin(sun[0]), math.sin(sun[1])])
    angle = np.arccos(np.clip(d @ s, -1, 1))
    sky = np.where(elevation[..., None] > 0, [0.25, 0.35, 0.6], [0.15, 0.12, 0.1]) * \
        (0.6 + 0.4 * np.abs(np.sin(elevation))[..., None])
    glow = 30.0 * np.exp(-(angle / math.radians(8)) ** 2)[..., None] * np.array([1.0, 0.9, 0.7])
    return _image(name, (sky + glow).astype(np.float32))


def hdri_world(name, strength=1.0, rotation_z=0.0):
    world = bpy.data.worlds.new(name)
    world.use_nodes = True
    tree = world.node_tree
    background = tree.nodes["Background"]
    background.inputs["Strength"].default_value = strength
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = environment_image(f"{name} hdri")
    tree.links.new(env.outputs["Color"], background.inputs["Color"])
    if rotation_z:
        coords = tree.nodes.new("ShaderNodeTexCoord")
        mapping = tree.nodes.new("ShaderNodeMapping")
        mapping.inputs["Rotation"].default_value = (0, 0, rotation_z)
        tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    return world


def color_world(name, color, strength):
    world = bpy.data.worlds.new(name)
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = _rgba(color)
    background.inputs["Strength"].default_value = strength
    return world


# --------------------------------------------------------------------------- the scenes

SPHERE_AT = (0.6, 0.0, 0.7)
CUBE_AT = (-0.9, 0.3, 0.45)


def _sphere(scene, mat, radius=0.7, at=SPHERE_AT):
    return _mesh_object(scene, "Sphere", sphere(radius), [mat], location=at, smooth=True)


def _cube(scene, mat, size=0.9):
    return _mesh_object(scene, "Cube", cube(size), [mat], location=CUBE_AT, rotation=(0, 0, math.radians(25)))


def _key(scene, radius=0.2, power=600.0):
    return add_light(scene, "POINT", power, (2.0, -2.0, 3.2), shadow_soft_size=radius)


def s_mix_glossy_diffuse(name):
    scene = base_scene(name)
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.8, 0.1, 0.1), 0.32, 0.3))
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)))
    _key(scene)
    return scene


def s_fresnel_beckmann(name):
    scene = base_scene(name)
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.1, 0.5, 0.2), 0.4, 0.0, "BECKMANN",
                                      ("ShaderNodeFresnel", {"IOR": 1.6}, "Fac")))
    _cube(scene, diffuse(f"{name} cube", (0.7, 0.7, 0.2)))
    add_light(scene, "AREA", 600.0, (1.8, -1.5, 2.8), SPHERE_AT, shape="RECTANGLE", size=2.0, size_y=1.0)
    return scene


def s_layer_weight(name):
    scene = base_scene(name)
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.6, 0.3, 0.7), 0.2, 0.0, "GGX",
                                      ("ShaderNodeLayerWeight", {"Blend": 0.3}, "Facing")))
    _cube(scene, mix_glossy_diffuse(f"{name} cube", (0.3, 0.6, 0.6), 0.4, 0.0, "GGX",
                                    ("ShaderNodeLayerWeight", {"Blend": 0.4}, "Fresnel")))
    _key(scene)
    return scene


def s_group_texture(name):
    scene = base_scene(name, floor=grouped_textured(f"{name} floor"))
    _sphere(scene, grouped_textured(f"{name} sphere"))
    _key(scene)
    return scene


def s_principled_texture(name):
    scene = base_scene(name)
    _sphere(scene, principled_rough_texture(f"{name} sphere"))
    mat = bpy.data.materials.new(f"{name} cube")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.2, 0.3, 0.8, 1)
    bsdf.inputs["Roughness"].default_value = 0.4
    _cube(scene, mat)
    _key(scene, radius=0.5)  # a broader highlight: less noise in both renderers at the gallery's samples
    return scene


def s_principled_layers(name):
    """Principled v1 with clearcoat over a red base, and with subsurface."""
    scene = base_scene(name)
    coat = bpy.data.materials.new(f"{name} coat")
    coat.use_nodes = True
    bsdf = coat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.6, 0.05, 0.05, 1)
    bsdf.inputs["Roughness"].default_value = 0.6
    _compat().principled_socket(bsdf, "Clearcoat").default_value = 1.0
    _compat().principled_socket(bsdf, "Clearcoat Roughness").default_value = 0.15
    _sphere(scene, coat)
    skin = bpy.data.materials.new(f"{name} skin")
    skin.use_nodes = True
    bsdf = skin.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.6, 0.5, 1)
    _compat().principled_socket(bsdf, "Subsurface").default_value = 0.5
    if "Subsurface Color" in bsdf.inputs:  # Principled v1 only; v2 scatters the base colour
        bsdf.inputs["Subsurface Color"].default_value = (0.9, 0.3, 0.2, 1)
    bsdf.inputs["Subsurface Radius"].default_value = (0.05, 0.02, 0.01)
    _cube(scene, skin)
    _key(scene, radius=0.5)
    return scene


def s_default_surfaces(name):
    """An empty material slot (Cycles' default grey), a material without
    nodes (its viewport colour) and a mesh with no slot at all."""
    scene = base_scene(name, wall_material=False)
    _mesh_object(scene, "Wall", plane, [None], location=(0, 2.0, 1.2), rotation=(math.radians(90), 0, 0),
                 scale=(3.0, 1.2, 1))
    plain = bpy.data.materials.new(f"{name} plain")
    plain.use_nodes = False
    plain.diffuse_color = (0.2, 0.6, 0.3, 1)
    _sphere(scene, plain)
    _mesh_object(scene, "Cube", cube(0.9), [], location=CUBE_AT, rotation=(0, 0, math.radians(25)))
    add_light(scene, "SUN", 3.0, (0, 0, 5), (-1.0, 1.5, 0.0), angle=math.radians(5))
    return scene


def s_large_point(name):
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.8, 0.3, 0.2)))
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)))
    add_light(scene, "POINT", 1500.0, (1.8, -1.2, 2.4), shadow_soft_size=1.0)
    return scene


def s_diffuse_roughness(name):
    """Diffuse BSDFs with a roughness: Oren-Nayar, whose energy Cycles 4.3
    restores by a multiple-scattering term (3.x's loses it)."""
    scene = base_scene(name)
    mat = diffuse(f"{name} sphere", (0.8, 0.8, 0.8))
    mat.node_tree.nodes["Diffuse BSDF"].inputs["Roughness"].default_value = 1.0
    _sphere(scene, mat)
    mat = diffuse(f"{name} cube", (0.2, 0.4, 0.8))
    mat.node_tree.nodes["Diffuse BSDF"].inputs["Roughness"].default_value = 0.5
    _cube(scene, mat)
    _key(scene, radius=0.5)
    return scene


def s_spot(name):
    """A spot light with a blend, and a node tree tinting it."""
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.8, 0.8, 0.8)))
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)))
    spot = add_light(scene, "SPOT", 1500.0, (1.0, -2.0, 3.5), (0, 0.2, 0), shadow_soft_size=0.1,
                     spot_size=math.radians(60), spot_blend=0.3)
    # A light node tree: Cycles multiplies colour x power by its Emission node.
    spot.data.use_nodes = True
    emission_node = spot.data.node_tree.nodes["Emission"]
    emission_node.inputs["Color"].default_value = (1.0, 0.7, 0.5, 1)
    emission_node.inputs["Strength"].default_value = 1.5
    return scene


def s_area_shapes(name):
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.7, 0.7, 0.7)))
    _cube(scene, diffuse(f"{name} cube", (0.8, 0.3, 0.3)))
    add_light(scene, "AREA", 300.0, (1.5, -1.0, 2.5), SPHERE_AT, shape="ELLIPSE", size=1.0, size_y=0.4)
    add_light(scene, "AREA", 200.0, (-1.8, -1.0, 2.2), CUBE_AT, shape="SQUARE", size=0.6)
    add_light(scene, "AREA", 150.0, (0.0, 1.5, 2.8), (0, 0, 0), shape="DISK", size=0.8)
    return scene


def s_sun_angle(name):
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.7, 0.7, 0.3)))
    _cube(scene, diffuse(f"{name} cube", (0.3, 0.3, 0.8)))
    add_light(scene, "SUN", 4.0, (0, 0, 5), (-1.2, 1.0, 0.0), angle=math.radians(12))
    return scene


def s_emissive_mesh(name):
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.7, 0.7, 0.7)))
    _mesh_object(scene, "Panel", plane, [emission(f"{name} panel", (1.0, 0.8, 0.6), 12.0)],
                 location=(-0.6, -0.3, 2.2), rotation=(math.radians(180 - 20), 0, 0), scale=(0.7, 0.5, 1))
    return scene


def s_world_color(name):
    scene = base_scene(name)
    _sphere(scene, diffuse(f"{name} sphere", (0.8, 0.8, 0.8)))
    _cube(scene, diffuse(f"{name} cube", (0.8, 0.4, 0.2)))
    scene.world = color_world(f"{name} world", (0.4, 0.5, 0.7), 1.5)
    return scene


def s_hdri(name):
    scene = base_scene(name)
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.7, 0.7, 0.7), 0.3, 0.3))
    _cube(scene, diffuse(f"{name} cube", (0.8, 0.4, 0.2)))
    scene.world = hdri_world(f"{name} world", strength=1.0, rotation_z=math.radians(30))
    return scene


def s_world_visibility(name):
    """The HDRI world invisible to glossy rays: it lights the diffuse lobes only."""
    scene = s_hdri(name)
    scene.world.cycles_visibility.glossy = False
    return scene


def s_translucent_transparent(name):
    scene = base_scene(name)
    _mesh_object(scene, "Leaf", plane, [leaf(f"{name} leaf")], location=(0.6, 0.0, 0.8),
                 rotation=(math.radians(80), 0, math.radians(20)), scale=(0.6, 0.6, 1))
    _mesh_object(scene, "Veil", plane, [veil(f"{name} veil")], location=(-0.9, -0.5, 0.7),
                 rotation=(math.radians(90), 0, math.radians(-10)), scale=(0.6, 0.6, 1))
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)), size=0.6)
    _key(scene)
    add_light(scene, "POINT", 400.0, (0.8, 1.5, 2.0), shadow_soft_size=0.2)  # behind the leaf
    return scene


def s_bounce_limits(name):
    scene = base_scene(name)
    c = scene.cycles
    c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 3, 1, 2
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.8, 0.8, 0.8), 0.2, 0.4))
    _cube(scene, diffuse(f"{name} cube", (0.9, 0.9, 0.9)))
    _key(scene)
    return scene


def s_ray_visibility(name):
    scene = base_scene(name)
    sphere_obj = _sphere(scene, diffuse(f"{name} sphere", (0.8, 0.8, 0.8)))
    sphere_obj.visible_shadow = False  # casts no shadow
    cube_obj = _cube(scene, diffuse(f"{name} cube", (0.9, 0.2, 0.2)))
    cube_obj.visible_diffuse = False  # no red bleeding onto the floor
    _key(scene)
    # Lights' own visibility: one that lights only glossy lobes (none here:
    # it must add nothing), one that casts no shadows.
    glossy_only = add_light(scene, "POINT", 800.0, (-2.0, -1.5, 2.5), shadow_soft_size=0.3)
    glossy_only.visible_diffuse = False
    unshadowed = add_light(scene, "AREA", 150.0, (-0.5, 1.0, 2.8), (0, 0, 0), shape="SQUARE", size=0.5)
    _compat().set_light_cast_shadow(unshadowed.data, False)
    return scene


def s_glass(name):
    """A sharp Glass sphere and a Refraction cube: seen through, and their
    (opaque, caustics off) shadows."""
    scene = base_scene(name)
    _sphere(scene, glass(f"{name} sphere"))
    mat, tree, out = _tree(f"{name} cube")
    node = _node(tree, "ShaderNodeBsdfRefraction", Color=(0.8, 0.9, 0.8, 1), IOR=1.3)
    _compat().set_sharp_distribution(node)
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    _cube(scene, mat)
    _key(scene, radius=1.0)  # a large reflection in the glass: LSE not dominated by noise
    return scene


def s_rough_glass(name):
    """A rough GGX Glass sphere and a rough Beckmann Refraction cube."""
    scene = base_scene(name)
    mat, tree, out = _tree(f"{name} sphere")
    node = _node(tree, "ShaderNodeBsdfGlass", Color=(0.95, 0.95, 1.0, 1), IOR=1.5, Roughness=0.3,
                 _distribution="GGX")
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    _sphere(scene, mat)
    mat, tree, out = _tree(f"{name} cube")
    node = _node(tree, "ShaderNodeBsdfRefraction", Color=(0.9, 0.8, 0.7, 1), IOR=1.4, Roughness=0.2,
                 _distribution="BECKMANN")
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    _cube(scene, mat)
    _key(scene, radius=0.5)
    return scene


def s_filter_glossy(name):
    """Glossy seen in glossy with Cycles' default Filter Glossy (1.0): a
    nearly smooth sphere over a half-glossy floor."""
    scene = base_scene(name, floor=mix_glossy_diffuse(f"{name} floor", (0.4, 0.4, 0.45), 0.05, 0.5))
    scene.cycles.blur_glossy = 1.0
    mat, tree, out = _tree(f"{name} sphere")
    node = _node(tree, "ShaderNodeBsdfGlossy", Color=(0.9, 0.8, 0.6, 1), Roughness=0.03, _distribution="GGX")
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    _sphere(scene, mat)
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)))
    _key(scene, radius=0.5)
    return scene


def s_public_style(name):
    """As a user's StyLit exemplar scene: a Mix Shader of Glossy (0.32) and
    Diffuse on the sphere, a 3500 W point light of radius 2 m, a backdrop
    with an empty material slot, and an HDRI world."""
    scene = base_scene(name, wall_material=False)
    backdrop = _mesh_object(scene, "Backdrop", plane, [None], location=(0, 2.0, 1.2),
                            rotation=(math.radians(90), 0, 0), scale=(3.0, 1.2, 1))
    backdrop.name = "Backdrop"
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.8, 0.05, 0.05), 0.32, 0.5))
    add_light(scene, "POINT", 3500.0, (3.0, -2.5, 4.0), shadow_soft_size=2.0)
    scene.world = hdri_world(f"{name} world", strength=0.3)
    return scene


def s_light_max_bounces(name):
    """A scene set up for StyLit as Creative Flow+'s renders set one up
    (creativefloworg/creativeflow, blender/stylit_util.py): a Mix Shader of
    Diffuse and Glossy on the sphere, a backdrop of objects without material
    (Cycles' default surface), a large soft point light whose own Max Bounces
    is 0 (Light > Settings: it lights directly only) and whose radius reaches
    the floor, and a dark world."""
    scene = base_scene(name, wall_material=False)
    for obj in scene.objects:
        if obj.type == "MESH":
            obj.data.materials.clear()  # the floor: a mesh with no slot
    _mesh_object(scene, "Wall", plane, [None], location=(0, 2.0, 1.2), rotation=(math.radians(90), 0, 0),
                 scale=(3.0, 1.2, 1))
    _sphere(scene, mix_glossy_diffuse(f"{name} sphere", (0.8, 0.05, 0.05), 0.2, 0.5))
    key = add_light(scene, "POINT", 1500.0, (2.2, -1.8, 1.8), shadow_soft_size=2.2)
    key.data.cycles.max_bounces = 0
    scene.world = color_world(f"{name} world", (0.05, 0.05, 0.05), 1.0)
    return scene


def s_light_without_mis(name):
    """A mirror sphere reflecting two area lights, one with Multiple
    Importance off (Light > Settings): only BSDF rays find a light in a
    mirror, and they pass through that one, so the mirror does not show it."""
    scene = base_scene(name)
    mat, tree, out = _tree(f"{name} mirror")
    node = _node(tree, "ShaderNodeBsdfGlossy", Color=(0.8, 0.8, 0.8, 1))
    _compat().set_sharp_distribution(node)
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    _sphere(scene, mat)
    _cube(scene, diffuse(f"{name} cube", (0.2, 0.4, 0.8)))
    add_light(scene, "AREA", 300.0, (2.0, -2.0, 2.5), SPHERE_AT, size=0.8)
    without = add_light(scene, "AREA", 300.0, (-2.0, -2.0, 2.5), SPHERE_AT, size=0.8)
    without.data.cycles.use_multiple_importance_sampling = False
    return scene


SCENES = {
    "mix_glossy_diffuse": s_mix_glossy_diffuse,
    "fresnel_beckmann": s_fresnel_beckmann,
    "layer_weight": s_layer_weight,
    "group_texture": s_group_texture,
    "principled_texture": s_principled_texture,
    "principled_layers": s_principled_layers,
    "default_surfaces": s_default_surfaces,
    "large_point": s_large_point,
    "diffuse_roughness": s_diffuse_roughness,
    "spot": s_spot,
    "area_shapes": s_area_shapes,
    "sun_angle": s_sun_angle,
    "emissive_mesh": s_emissive_mesh,
    "world_color": s_world_color,
    "hdri": s_hdri,
    "world_visibility": s_world_visibility,
    "translucent_transparent": s_translucent_transparent,
    "bounce_limits": s_bounce_limits,
    "filter_glossy": s_filter_glossy,
    "ray_visibility": s_ray_visibility,
    "glass": s_glass,
    "rough_glass": s_rough_glass,
    "public_style": s_public_style,
    "light_max_bounces": s_light_max_bounces,
    "light_without_mis": s_light_without_mis,
}


def build(key):
    return SCENES[key](f"Gallery {key}")


def remove(scene):
    """lpe_scene.remove_scene, and the gallery scene's own world."""
    world = scene.world
    lpe_scene.remove_scene(scene)
    if world is not None and world.users == 0:
        bpy.data.worlds.remove(world)
