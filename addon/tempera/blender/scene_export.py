"""The evaluated Blender scene as the scene dict of Tempera's light-path tracer.

    depsgraph = evaluated_depsgraph(scene, view_layer, frame)
    scene_dict, warnings = export_scene(scene, depsgraph, (width, height))

Geometry comes from the depsgraph (modifiers applied, instances expanded,
world transforms) as triangles with per-corner split normals and UVs;
materials become Cycles' closures by a small interpreter of the shader nodes
(tempera.blender.shader_nodes); lights, world
and camera are converted to physical units with tempera.tracer.scene_units so that
the tracer's buffers match Cycles pixel for pixel. Whatever the tracer cannot
represent is approximated and named in `warnings` (docs/lpe_guides.md lists
what is supported). Blender units are taken as metres, as Cycles does (the
scene's unit scale is ignored by Cycles too).
"""
import numpy as np

from ..tracer import scene_units
from . import compat
from .shader_nodes import DEFAULT_GREY, ImageCache, ShaderInterpreter

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}
FALLBACK_GREY = DEFAULT_GREY  # Cycles' default surface: a diffuse BSDF of 0.8 grey
# Ray visibility bits of the tracer (scene.hpp), from Blender's object properties.
VISIBILITY_BITS = (("visible_camera", 1), ("visible_diffuse", 2), ("visible_glossy", 4),
                   ("visible_transmission", 8), ("visible_shadow", 16))


class SceneExportError(ValueError):
    """A scene the tracer cannot render at all (e.g. a panoramic camera)."""


def evaluated_depsgraph(scene, view_layer, frame):
    """The view layer's depsgraph with the scene evaluated afresh at `frame`.

    After bpy.ops.render.render, Blender 3.4 can leave a scene's evaluated
    objects without their transforms while the depsgraph counts as current
    (seen: every mesh at the origin), so every object is tagged for
    re-evaluation, its animation included (a tag without TIME puts animated
    objects back at their unanimated values). frame_set then evaluates the
    tags at `frame`, and creates the depsgraph of a scene never evaluated."""
    for obj in scene.objects:
        obj.update_tag(refresh={"OBJECT", "DATA", "TIME"} if obj.data is not None else {"OBJECT", "TIME"})
    scene.frame_set(frame)
    depsgraph = view_layer.depsgraph
    depsgraph.update()
    return depsgraph


def export_scene(scene, depsgraph, size):
    """(scene dict, [warning, ...]) of `scene` as `depsgraph` evaluates it,
    seen by the scene's camera at `size` = (width, height) pixels."""
    warnings = []
    rendered = _rendered_objects(depsgraph.view_layer, warnings)
    images = ImageCache()
    materials = _Materials(warnings, images)
    geometry = {"vertices": [], "triangles": [], "triangle_materials": [], "normals": [], "uvs": [],
                "visibility": []}
    lights = []
    meshes = {}  # evaluated object and data -> its triangles in object space: instances share them
    offset = 0
    for instance in depsgraph.object_instances:
        obj = instance.object
        # An instance renders if its instancer does (the instanced original
        # often sits in a collection hidden on purpose).
        owner = instance.parent if instance.is_instance else obj
        if owner.original.name not in rendered or not instance.show_self:
            continue
        matrix = np.array(instance.matrix_world, np.float64)
        if obj.type == "LIGHT":
            light = _light(obj, matrix, warnings)
            light.update(_light_paths(owner))
            lights.append(light)
            continue
        if obj.type not in GEOMETRY_TYPES:
            continue
        key = (obj.name, obj.data.as_pointer() if obj.data is not None else 0)
        if key not in meshes:
            meshes[key] = _triangles(obj, materials, warnings)
        local = meshes[key]
        if local is None:
            continue
        verts, tris, mats, normals, uvs = local
        world = verts @ matrix[:3, :3].T + matrix[:3, 3]
        normal_matrix = np.linalg.inv(matrix[:3, :3]).T  # normals transform by the inverse transpose
        n = normals.reshape(-1, 3) @ normal_matrix.T
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-20)
        geometry["vertices"].append(world)
        geometry["triangles"].append(tris + offset)
        geometry["triangle_materials"].append(mats)
        geometry["normals"].append(n.reshape(-1, 3, 3))
        geometry["uvs"].append(uvs)
        geometry["visibility"].append(np.full(len(tris), _visibility(owner), np.int32))
        offset += len(verts)
    textures = []
    world = _world(scene.world, warnings, images, textures)
    world_visibility = _world_visibility(scene.world)
    if world_visibility != 31:
        world["visibility"] = world_visibility
    material_list = [_index_textures(m, textures) for m in (materials.list or [default_surface()])]
    visibility = _stack(geometry["visibility"], (0,), np.int32)
    out = {
        "vertices": _stack(geometry["vertices"], (0, 3), np.float32),
        "triangles": _stack(geometry["triangles"], (0, 3), np.int32),
        "triangle_materials": _stack(geometry["triangle_materials"], (0,), np.int32),
        "normals": _stack(geometry["normals"], (0, 3, 3), np.float32),
        "uvs": _stack(geometry["uvs"], (0, 3, 2), np.float32),
        "materials": material_list,
        "lights": lights,
        "world": world,
        "textures": textures,
        "camera": export_camera(scene, depsgraph, size),
        "closure_model": compat.cycles_closure_model(),  # Cycles 3.x's microfacets or 4.0's
    }
    if (visibility != 31).any():
        out["triangle_visibility"] = visibility
    return out, warnings


def _visibility(obj):
    """Ray visibility bits of an object (Object Properties > Visibility > Ray Visibility)."""
    bits = 0
    for prop, bit in VISIBILITY_BITS:
        if getattr(obj, prop, True):
            bits |= bit
    return bits


def _world_visibility(world):
    """Ray visibility bits of the world (World > Settings > Ray Visibility)."""
    settings = getattr(world, "cycles_visibility", None) if world is not None else None
    if settings is None:
        return 31
    bits = 16
    for prop, bit in (("camera", 1), ("diffuse", 2), ("glossy", 4), ("transmission", 8)):
        if getattr(settings, prop, True):
            bits |= bit
    return bits


def _light_paths(obj):
    """Which paths a light object lights: its ray visibility, shadow casting,
    and Cycles' Max Bounces and Multiple Importance of the light."""
    out = {"visibility": _visibility(obj) | 16}
    light = obj.data
    cycles = getattr(light, "cycles", None)
    cast = getattr(cycles, "cast_shadow", None) if cycles is not None else None
    if cast is None:
        cast = getattr(light, "use_shadow", True)
    out["cast_shadow"] = bool(cast)
    out["max_bounces"] = int(getattr(cycles, "max_bounces", 1024))
    out["multiple_importance"] = bool(getattr(cycles, "use_multiple_importance_sampling", True))
    return out


def path_settings(scene):
    """The scene's Cycles settings that shape the tracer's paths and pixels
    (Light Paths, Film > Pixel Filter) as trace_lpe keywords."""
    c = scene.cycles
    return {"max_bounces": int(c.max_bounces), "diffuse_bounces": int(c.diffuse_bounces),
            "glossy_bounces": int(c.glossy_bounces), "transmission_bounces": int(c.transmission_bounces),
            "transparent_bounces": int(c.transparent_max_bounces),
            "caustics_reflective": bool(c.caustics_reflective), "caustics_refractive": bool(c.caustics_refractive),
            "filter_glossy": float(c.blur_glossy),
            "pixel_filter": {"BOX": "box", "GAUSSIAN": "gaussian"}.get(c.pixel_filter_type, "blackman_harris"),
            "filter_width": float(c.filter_width)}


def _rendered_objects(view_layer, warnings):
    """Names of the objects a render of the view layer shows: not disabled in
    renders, in collections neither excluded nor disabled in renders. Those
    disabled in viewports are missing from the depsgraph (warned)."""
    names = set()

    def walk(layer_collection, hidden_in_viewport):
        collection = layer_collection.collection
        if layer_collection.exclude or collection.hide_render:
            return
        hidden_in_viewport = hidden_in_viewport or collection.hide_viewport
        for obj in collection.objects:
            if obj.hide_render or obj.name in names:
                continue
            names.add(obj.name)
            if hidden_in_viewport or obj.hide_viewport:
                warnings.append(f"Object '{obj.name}' is disabled in viewports: the light-path tracer, which "
                                "sees the scene as the viewport evaluates it, leaves it out.")
        for child in layer_collection.children:
            walk(child, hidden_in_viewport)

    walk(view_layer.layer_collection, False)
    return names


def _stack(parts, empty_shape, dtype):
    return np.ascontiguousarray(np.concatenate(parts), dtype) if parts else np.zeros(empty_shape, dtype)


# --------------------------------------------------------------------------- camera

def export_camera(scene, depsgraph, size):
    """The camera fields of the scene dict for the scene's camera at `size`."""
    render = scene.render
    if abs(render.pixel_aspect_x - render.pixel_aspect_y) > 1e-6:
        raise SceneExportError(f"Scene '{scene.name}' has non-square pixels (Pixel Aspect "
                               f"{render.pixel_aspect_x:g}:{render.pixel_aspect_y:g}); the light-path tracer "
                               "needs a pixel aspect of 1:1.")
    camera = scene.camera.evaluated_get(depsgraph)
    data = camera.data
    if data.type not in ("PERSP", "ORTHO"):
        raise SceneExportError(f"Camera '{scene.camera.name}' is {data.type.lower()}: the light-path tracer "
                               "renders perspective and orthographic cameras only.")
    width, height = size
    out = scene_units.camera_intrinsics(
        data.type, width, height, lens=data.lens, sensor_width=data.sensor_width,
        sensor_height=data.sensor_height, sensor_fit=data.sensor_fit, ortho_scale=data.ortho_scale,
        shift_x=data.shift_x, shift_y=data.shift_y)
    # Cycles ignores the camera object's scale: keep only rotation and position.
    location, rotation, _scale = camera.matrix_world.decompose()
    matrix = np.eye(4)
    matrix[:3, :3] = np.array(rotation.to_matrix())
    matrix[:3, 3] = location
    out.update(camera_to_world=matrix.astype(np.float32), clip_start=float(data.clip_start),
               clip_end=float(data.clip_end))
    return out


# --------------------------------------------------------------------------- geometry

def _triangles(obj, materials, warnings):
    """(vertices, triangles, material per triangle, corner normals, corner
    UVs) of an evaluated object in object space, or None if it has no faces."""
    for modifier in obj.original.modifiers:
        # The depsgraph is evaluated as the viewport shows it; say when the render would differ.
        levels_differ = getattr(modifier, "render_levels", None) not in (None, getattr(modifier, "levels", None))
        if modifier.show_viewport != modifier.show_render or levels_differ:
            warnings.append(f"Object '{obj.name}': modifier '{modifier.name}' differs between viewport and "
                            "render; the light-path guides use the viewport's version.")
    mesh = obj.to_mesh()
    try:
        if mesh is None or not mesh.polygons:
            return None
        mesh.calc_loop_triangles()
        count = len(mesh.loop_triangles)
        verts = _get(mesh.vertices, "co", (len(mesh.vertices), 3), np.float64)
        tris = _get(mesh.loop_triangles, "vertices", (count, 3), np.int32)
        loops = _get(mesh.loop_triangles, "loops", (count, 3), np.int32)
        slots = _get(mesh.loop_triangles, "material_index", (count,), np.int32)
        loop_normals = compat.corner_normals(mesh)  # smooth, flat and auto-smooth faces as Cycles shades them
        uv_layer = next((layer for layer in mesh.uv_layers if layer.active_render), None)
        if uv_layer is not None:
            uvs = _get(uv_layer.data, "uv", (len(mesh.loops), 2), np.float32)[loops]
        else:
            uvs = np.zeros((count, 3, 2), np.float32)
        global_index = np.array([materials.index(slot.material) for slot in obj.material_slots] or
                                [materials.index(None)], np.int32)
        mats = global_index[np.clip(slots, 0, len(global_index) - 1)]
        return verts, tris, mats, loop_normals[loops], uvs
    finally:
        obj.to_mesh_clear()


def _get(collection, attribute, shape, dtype):
    flat = np.empty(int(np.prod(shape)), dtype)
    collection.foreach_get(attribute, flat)
    return flat.reshape(shape)


# --------------------------------------------------------------------------- materials

def default_surface():
    """What empty or missing material slots render as: Cycles' default
    surface, diffuse 0.8 grey, or in Blender 5.0 its default material, a
    Principled BSDF of 0.8 grey, roughness 0.5, IOR 1.5 (compat)."""
    grey = np.array(FALLBACK_GREY, np.float32)
    if compat.default_surface_is_principled():
        return {"base_color": grey, "closures": [{"type": "principled", "color": grey, "metallic": 0.0,
                                                  "specular": 0.5, "roughness": 0.5, "transmission": 0.0,
                                                  "ior": 1.5, "multiscatter": True}]}  # the node's default
    return {"base_color": grey, "closures": [{"type": "diffuse", "color": grey}]}


class _Materials:
    """Blender materials -> the tracer's material list, each converted once."""

    def __init__(self, warnings, images=None):
        self.list, self._index, self._warnings = [], {}, warnings
        self._images = images if images is not None else ImageCache()

    def index(self, material):
        key = material.name if material is not None else None
        if key not in self._index:
            self._index[key] = len(self.list)
            self.list.append(convert_material(material, self._warnings, self._images))
        return self._index[key]


def convert_material(material, warnings, images=None):
    """The tracer's material (a list of Cycles closures) for a Blender material.

    None (an empty slot, or an object without material) is Cycles' default
    surface, diffuse 0.8 grey. A material without nodes renders in Cycles as
    a diffuse BSDF of its viewport colour. With nodes, the tree feeding the
    Cycles Material Output's Surface is interpreted (shader_nodes); nothing
    plugged in renders black, as in Cycles.
    """
    if material is None:
        return default_surface()
    color = np.array(material.diffuse_color[:3], np.float32)
    if not material.use_nodes or material.node_tree is None:
        return {"base_color": color, "closures": [{"type": "diffuse", "color": color}]}
    owner = f"Material '{material.name}'"
    output = material.node_tree.get_output_node("CYCLES")
    if output is None:
        warnings.append(f"{owner}: no active Material Output; it renders black.")
        closures = []
    else:
        interpreter = ShaderInterpreter(owner, warnings, images if images is not None else ImageCache())
        closures = interpreter.closures(output.inputs["Surface"])
        if output.inputs["Volume"].is_linked or output.inputs["Displacement"].is_linked:
            warnings.append(f"{owner}: volume and displacement are ignored by the light-path tracer.")
    if not closures:  # a surface that neither scatters nor emits: black
        closures = [{"type": "diffuse", "color": np.zeros(3, np.float32)}]
    return {"base_color": color, "closures": closures}


def _index_textures(material, textures):
    """Replaces the texel arrays of a material's closures by indices into `textures`."""
    def ref(t):
        for i, existing in enumerate(textures):
            if existing is t["texels"]:
                break
        else:
            textures.append(t["texels"])
            i = len(textures) - 1
        out = {"image": i, "uv": np.array(t["uv"], np.float32)}
        if "channel" in t:
            out["channel"] = int(t["channel"])
        return out

    closures = []
    for c in material.get("closures", []):
        c = dict(c)
        for key in ("color_texture", "roughness_texture"):
            if key in c:
                c[key] = ref(c[key])
        factors = []
        for f in c.get("factors", []):
            f = dict(f)
            if "texture" in f:
                f["texture"] = ref(f["texture"])
            factors.append(f)
        if "factors" in c:
            c["factors"] = factors
        closures.append(c)
    return dict(material, closures=closures)


# --------------------------------------------------------------------------- lights and world

def _light(obj, matrix, warnings):
    """A light object at world `matrix` in the tracer's units (tempera.tracer.scene_units)."""
    light = obj.data
    position = matrix[:3, 3]
    z_axis = matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])  # Blender lights shine down their local -Z
    tint = _light_node_tint(obj, warnings)
    model = compat.cycles_light_model(light)  # Cycles 3.x's lights or 4.0's
    if light.type in ("POINT", "SPOT"):
        out = {"type": "point", "position": position, "radius": float(light.shadow_soft_size),
               "intensity": scene_units.point_intensity(light.energy, light.color),
               "soft_shape": model["soft_shape"]}
        if light.type == "SPOT":
            out.update(type="spot", direction=-z_axis, spot_half_angle=float(light.spot_size) / 2,
                       spot_blend=float(light.spot_blend), spot_axis_cosine=model["spot_axis_cosine"])
    elif light.type == "SUN":
        out = {"type": "sun", "direction": z_axis, "angle": float(light.angle),
               "irradiance": scene_units.sun_irradiance(light.energy, light.color)}
    elif light.type == "AREA":
        # Cycles scales the light's size by the object's scale along its axes.
        u_len, v_len = np.linalg.norm(matrix[:3, 0]), np.linalg.norm(matrix[:3, 1])
        u, v, area = scene_units.area_size(light.shape, light.size, light.size_y)
        u, v, area = u * u_len, v * v_len, area * u_len * v_len
        out = {"type": "area", "center": position, "axis_u": matrix[:3, 0] / u_len,
               "axis_v": matrix[:3, 1] / v_len, "normal": -z_axis, "size_u": float(u), "size_v": float(v),
               "shape": "disk" if light.shape in ("DISK", "ELLIPSE") else "rect",
               "radiance": scene_units.area_radiance(light.energy, light.color, area, model["area_emits_power"])}
        if getattr(light, "spread", np.pi) < np.pi - 1e-4:
            warnings.append(f"Light '{obj.name}': area light spread is not modelled by the light-path tracer "
                            "(it emits over the full hemisphere).")
    else:
        raise SceneExportError(f"Light '{obj.name}' has an unknown type {light.type!r}")
    for key in ("intensity", "irradiance", "radiance"):
        if key in out:
            out[key] = np.asarray(out[key], np.float64) * tint
    return {k: (np.asarray(v, np.float32) if isinstance(v, np.ndarray) else v) for k, v in out.items()}


def _light_node_tint(obj, warnings):
    """The factor a light's node tree puts on its colour x power: Cycles
    multiplies them by the Emission node plugged into the Light Output
    (colour x strength; 1 without nodes). Only constant trees are modelled."""
    light = obj.data
    if not light.use_nodes or light.node_tree is None:
        return np.ones(3)
    owner = f"Light '{obj.name}'"
    output = light.node_tree.get_output_node("CYCLES")
    if output is None:
        return np.ones(3)
    interpreter = ShaderInterpreter(owner, warnings, ImageCache())
    closures = interpreter.closures(output.inputs["Surface"])
    if not closures:
        return np.zeros(3) if output.inputs["Surface"].is_linked else np.ones(3)
    tint = np.zeros(3)
    for c in closures:
        if c["type"] != "emission" or c.get("factors") or "color" not in c:
            warnings.append(f"{owner}: its node tree varies (textures, mixes) and is not modelled; its constant "
                            "part is used.")
            continue
        tint += np.asarray(c["color"], np.float64) * np.asarray(c["weight"], np.float64)
    return tint


def _world(world, warnings, images, textures):
    """The world of the scene dict: a constant radiance (Background colour x
    strength, or the world colour without nodes), or an equirectangular
    Environment Texture (index into `textures`) times the strength, turned by
    the Mapping node in front of it. No world is black."""
    black = {"radiance": np.zeros(3, np.float32)}
    if world is None:
        return black
    if not world.use_nodes or world.node_tree is None:
        return {"radiance": np.array(world.color[:3], np.float32)}
    owner = f"World '{world.name}'"
    output = world.node_tree.get_output_node("CYCLES")
    if output is None:
        return black
    interpreter = ShaderInterpreter(owner, warnings, images)
    src = interpreter.source(output.inputs["Surface"], ())
    node = src[0].node if src is not None and src[0] != "default" else None
    if node is None:
        return black
    if node.bl_idname != "ShaderNodeBackground":
        # Mixes of backgrounds (e.g. a Light Path trick): their constant emission.
        closures = interpreter.closures(output.inputs["Surface"])
        warnings.append(f"{owner}: its surface is a {node.name} node, not a Background; the light-path tracer "
                        "uses the constant colours of the backgrounds it mixes.")
        radiance = np.zeros(3)
        for c in closures:
            if c["type"] == "emission" and not c.get("factors") and "color" in c:
                radiance += np.asarray(c["color"]) * np.asarray(c["weight"])
        return {"radiance": radiance.astype(np.float32)}
    ctx = src[1]
    strength = interpreter.constant_scalar(node.inputs["Strength"], ctx, "the background Strength")
    color_src = interpreter.source(node.inputs["Color"], ctx)
    texture = color_src[0].node if color_src is not None and color_src[0] != "default" else None
    if texture is not None and texture.bl_idname == "ShaderNodeTexEnvironment":
        return _environment(texture, color_src[1], strength, interpreter, images, textures, owner, warnings)
    color = interpreter.color(node.inputs["Color"], ctx)
    if color.texels is not None:
        warnings.append(f"{owner}: the background colour comes from an image not used as an Environment "
                        "Texture; its mean colour is used.")
        rgb = color.texels[:, :, :3].reshape(-1, 3).mean(axis=0)
    else:
        rgb = np.asarray(color.const, np.float64)[:3]
    return {"radiance": (rgb * strength).astype(np.float32)}


def _environment(node, ctx, strength, interpreter, images, textures, owner, warnings):
    """An Environment Texture node as the world map."""
    if node.image is None:
        warnings.append(f"{owner}: Environment Texture '{node.name}' has no image; black is used.")
        return {"radiance": np.zeros(3, np.float32)}
    if node.projection != "EQUIRECTANGULAR":
        warnings.append(f"{owner}: Environment Texture '{node.name}' projection {node.projection} is read as "
                        "equirectangular.")
    texels = images.pixels(node.image, owner, warnings)
    if texels is None:
        return {"radiance": np.zeros(3, np.float32)}
    rotation = np.eye(3)
    vec = interpreter.source(node.inputs["Vector"], ctx)
    if vec is not None and vec[0] != "default":
        mapping = vec[0].node
        if mapping.bl_idname == "ShaderNodeMapping":
            rot = np.array(mapping.inputs["Rotation"].default_value[:3], np.float64)
            scale = np.array(mapping.inputs["Scale"].default_value[:3], np.float64)
            if np.abs(scale - 1).max() > 1e-6:
                warnings.append(f"{owner}: Mapping '{mapping.name}' scale is ignored for the environment.")
            rotation = euler_xyz(rot)
            if mapping.vector_type == "TEXTURE":
                rotation = rotation.T
        elif not (mapping.bl_idname == "ShaderNodeTexCoord" and vec[0].name in ("Generated", "Object")):
            warnings.append(f"{owner}: environment coordinates from '{mapping.name}' are not modelled; the view "
                            "direction is used.")
    textures.append(texels)
    return {"radiance": np.full(3, strength, np.float32), "map": len(textures) - 1,
            "rotation": rotation.astype(np.float32)}


def euler_xyz(angles):
    """Blender's XYZ Euler rotation matrix (X first, then Y, then Z)."""
    x, y, z = angles
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    return rz @ ry @ rx
