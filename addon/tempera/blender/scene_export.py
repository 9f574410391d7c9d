"""The evaluated Blender scene as the scene dict of Tempera's light-path tracer.

    depsgraph = evaluated_depsgraph(scene, view_layer, frame)
    scene_dict, warnings = export_scene(scene, depsgraph, (width, height))

Geometry comes from the depsgraph (modifiers applied, instances expanded,
world transforms) as triangles with per-corner split normals and UVs;
materials are reduced to the tracer's Principled-like model; lights, world
and camera are converted to physical units with tempera.scene_units so that
the tracer's buffers match Cycles pixel for pixel. Whatever the tracer cannot
represent is approximated and named in `warnings` (docs/lpe_guides.md lists
what is supported). Blender units are taken as metres, as Cycles does (the
scene's unit scale is ignored by Cycles too).
"""
import numpy as np

from .. import scene_units
from . import compat

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}
FALLBACK_GREY = (0.8, 0.8, 0.8)
# Principled BSDF (Blender 3.4) inputs the tracer models, and its parameter names.
PRINCIPLED_INPUTS = {"Metallic": "metallic", "Specular": "specular", "Roughness": "roughness",
                     "Transmission": "transmission", "IOR": "ior"}
# Principled inputs the tracer ignores, and the value at which ignoring them changes nothing.
PRINCIPLED_IGNORED = {"Subsurface": 0.0, "Sheen": 0.0, "Clearcoat": 0.0, "Anisotropic": 0.0, "Alpha": 1.0}


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
    materials = _Materials(warnings)
    geometry = {"vertices": [], "triangles": [], "triangle_materials": [], "normals": [], "uvs": []}
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
            lights.append(_light(obj, matrix, warnings))
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
        offset += len(verts)
    out = {
        "vertices": _stack(geometry["vertices"], (0, 3), np.float32),
        "triangles": _stack(geometry["triangles"], (0, 3), np.int32),
        "triangle_materials": _stack(geometry["triangle_materials"], (0,), np.int32),
        "normals": _stack(geometry["normals"], (0, 3, 3), np.float32),
        "uvs": _stack(geometry["uvs"], (0, 3, 2), np.float32),
        "materials": materials.list or [_default_material()],
        "lights": lights,
        "world": {"radiance": _world_radiance(scene.world, warnings)},
        "camera": export_camera(scene, depsgraph, size),
    }
    return out, warnings


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

def _default_material():
    return {"base_color": np.array(FALLBACK_GREY, np.float32), "metallic": 0.0, "specular": 0.0,
            "roughness": 0.5, "transmission": 0.0, "ior": 1.45, "emission": np.zeros(3, np.float32)}


class _Materials:
    """Blender materials -> the tracer's material list, each converted once."""

    def __init__(self, warnings):
        self.list, self._index, self._warnings = [], {}, warnings

    def index(self, material):
        key = material.name if material is not None else None
        if key not in self._index:
            self._index[key] = len(self.list)
            self.list.append(convert_material(material, self._warnings))
        return self._index[key]


def convert_material(material, warnings):
    """The tracer's material for a Blender material (None: Cycles' default grey).

    Materials without nodes render in Cycles as a diffuse BSDF of their
    viewport colour, which the tracer represents exactly. With nodes, the
    shader feeding the Material Output's Surface must be a Principled BSDF
    (or a plain Diffuse BSDF or Emission); anything else is approximated by
    a diffuse surface of the material's viewport colour, with a warning.
    """
    out = _default_material()
    if material is None:
        return out
    out["base_color"] = np.array(material.diffuse_color[:3], np.float32)
    if not material.use_nodes or material.node_tree is None:
        return out
    owner = f"Material '{material.name}'"
    output = material.node_tree.get_output_node("CYCLES")
    shader = _linked_node(output.inputs["Surface"]) if output is not None else None
    kind = shader.bl_idname if shader is not None else None
    if kind == "ShaderNodeBsdfPrincipled":
        _principled(shader, owner, out, warnings)
    elif kind == "ShaderNodeBsdfDiffuse":
        _base_color(shader.inputs["Color"], owner, warnings, out)
    elif kind == "ShaderNodeEmission":
        out["base_color"] = np.zeros(3, np.float32)
        out["emission"] = _unlinked(shader.inputs["Color"], owner, warnings)[:3] * \
            _unlinked(shader.inputs["Strength"], owner, warnings)
    else:
        what = f"a {shader.name} node" if shader is not None else "nothing"
        warnings.append(f"{owner}: its surface is {what}, not a Principled BSDF; the light-path "
                        "tracer approximates it by a diffuse surface of the material's Viewport Display colour.")
    if output is not None:
        if output.inputs["Volume"].is_linked or output.inputs["Displacement"].is_linked:
            warnings.append(f"{owner}: volume and displacement are ignored by the light-path tracer.")
    out["base_color"] = np.asarray(out["base_color"], np.float32)
    out["emission"] = np.asarray(out["emission"], np.float32)
    return out


def _principled(node, owner, out, warnings):
    inputs = node.inputs
    _base_color(inputs["Base Color"], owner, warnings, out)
    for socket, key in PRINCIPLED_INPUTS.items():
        out[key] = float(_unlinked(compat.principled_socket(node, socket), owner, warnings))
    emission = _unlinked(compat.principled_socket(node, "Emission"), owner, warnings)[:3] * float(
        _unlinked(inputs["Emission Strength"], owner, warnings))
    out["emission"] = np.asarray(emission, np.float32)
    ignored = [s for s, neutral in PRINCIPLED_IGNORED.items()
               if _ignored_socket_used(node, s, neutral)]
    if ignored:
        warnings.append(f"{owner}: Principled {', '.join(ignored)} not modelled by the light-path "
                        "tracer (ignored).")
    if inputs["Normal"].is_linked:
        warnings.append(f"{owner}: the normal map is ignored by the light-path tracer.")


def _ignored_socket_used(node, name, neutral):
    try:
        socket = compat.principled_socket(node, name)
    except KeyError:  # a socket this Blender's Principled BSDF does not have
        return False
    return socket.is_linked or abs(float(socket.default_value) - neutral) > 1e-6


def _linked_node(socket):
    """The node plugged into `socket`, through reroutes (None if unlinked or muted)."""
    while socket.is_linked:
        node = socket.links[0].from_node
        if node.mute:
            return None
        if node.bl_idname != "NodeReroute":
            return node
        socket = node.inputs[0]
    return None


def _unlinked(socket, owner, warnings):
    """The socket's own value; a link into it is not followed (warned).
    `owner` names the material or world in the warning."""
    if socket.is_linked:
        warnings.append(f"{owner}: '{socket.name}' is driven by nodes the light-path "
                        "tracer does not evaluate; its unlinked value is used.")
    value = socket.default_value
    return np.array(value[:], np.float64) if hasattr(value, "__len__") else float(value)


def _base_color(socket, owner, warnings, out):
    """Sets the base colour from a colour input: its value, or the pixels of
    an Image Texture node plugged into it (as base_color_texture)."""
    node = _linked_node(socket)
    if node is not None and node.bl_idname == "ShaderNodeTexImage" and node.image is not None:
        texture = _image_texture(node.image, owner, warnings)
        if texture is not None:
            out["base_color_texture"] = texture
            return
    out["base_color"] = np.array(_unlinked(socket, owner, warnings)[:3], np.float32)


def _image_texture(image, owner, warnings):
    """Linear float32 (H, W, 3) pixels, row 0 at the top (the tracer's convention;
    Blender stores rows bottom-up), or None if the image has none. Byte images in the sRGB colour space are
    decoded to linear; float images already hold linear values."""
    width, height = image.size
    if width == 0 or height == 0:
        warnings.append(f"{owner}: image '{image.name}' has no pixels (missing file?); the socket's "
                        "own colour is used.")
        return None
    flat = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(flat)
    pixels = flat.reshape(height, width, image.channels)[::-1]
    rgb = pixels[:, :, :3] if image.channels >= 3 else np.repeat(pixels[:, :, :1], 3, axis=2)
    space = image.colorspace_settings.name
    if not image.is_float and space == "sRGB":
        rgb = scene_units.srgb_to_linear(rgb)
    elif space not in ("sRGB", "Linear", "Non-Color", "Raw"):
        warnings.append(f"{owner}: image '{image.name}' is in colour space '{space}', "
                        "which the light-path tracer reads as is.")
    return np.ascontiguousarray(rgb, np.float32)


# --------------------------------------------------------------------------- lights and world

def _light(obj, matrix, warnings):
    """A light object at world `matrix` in the tracer's units (tempera.scene_units)."""
    light = obj.data
    position = matrix[:3, 3]
    z_axis = matrix[:3, 2] / np.linalg.norm(matrix[:3, 2])  # Blender lights shine down their local -Z
    if light.use_nodes:
        warnings.append(f"Light '{obj.name}': light node trees are ignored by the light-path tracer "
                        "(colour x power is used).")
    if light.type in ("POINT", "SPOT"):
        out = {"type": "point", "position": position, "radius": float(light.shadow_soft_size),
               "intensity": scene_units.point_intensity(light.energy, light.color)}
        if light.type == "SPOT":
            out.update(type="spot", direction=-z_axis, spot_half_angle=float(light.spot_size) / 2,
                       spot_blend=float(light.spot_blend))
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
               "radiance": scene_units.area_radiance(light.energy, light.color, area)}
        if getattr(light, "spread", np.pi) < np.pi - 1e-4:
            warnings.append(f"Light '{obj.name}': area light spread is not modelled by the light-path tracer "
                            "(it emits over the full hemisphere).")
    else:
        raise SceneExportError(f"Light '{obj.name}' has an unknown type {light.type!r}")
    return {k: (np.asarray(v, np.float32) if isinstance(v, np.ndarray) else v) for k, v in out.items()}


def _world_radiance(world, warnings):
    """Constant radiance of the world: a Background node's colour x strength
    (or the world colour without nodes, as Cycles renders it); black without a world."""
    if world is None:
        return np.zeros(3, np.float32)
    if not world.use_nodes or world.node_tree is None:
        return np.array(world.color[:3], np.float32)
    output = world.node_tree.get_output_node("CYCLES")
    node = _linked_node(output.inputs["Surface"]) if output is not None else None
    if node is None:
        return np.zeros(3, np.float32)
    if node.bl_idname != "ShaderNodeBackground":
        warnings.append(f"World '{world.name}': its surface is a {node.name} node, not a Background; the "
                        "light-path tracer uses a black world.")
        return np.zeros(3, np.float32)
    color = node.inputs["Color"]
    if color.is_linked:
        warnings.append(f"World '{world.name}': the background colour is driven by nodes (e.g. an HDRI or "
                        "sky); the light-path tracer uses the node's constant colour instead.")
    strength = _unlinked(node.inputs["Strength"], f"World '{world.name}'", warnings)
    return np.array(color.default_value[:3], np.float32) * np.float32(strength)
