"""Rendering a scene's guides with Cycles into the guide cache (tempera.app.guide_cache).

    render_guides(scene, frames, out_dir, params=None, progress=None)

Per frame: one main render with the light-path, motion, depth, normal and
object-index passes, and a second render with one diffuse and no glossy or
transmission bounce for LD{1,2}E. The derived guides (velocities, occlusion,
structure tensor, lines, masks) are computed with numpy and tempera.engine.guides.
Scenes with fluids (gas and liquid domains, emitter particles) also get the
fluid_velocity guide from the simulation (tempera.blender.fluid_velocity),
since the Vector pass is zero on volumes.
Guides of arbitrary light path expressions (params["lpe"]) come from
Tempera's own path tracer on the exported scene (scene_export, tempera.tracer.lpe).

Every setting changed for this (render, Cycles, passes, view layers, frame,
objects' pass index) is put back exactly afterwards by GuideRenderSettings:
the user's file is never left changed.
"""
import math
import os
import secrets
import shutil
from contextlib import contextmanager
from pathlib import Path

import bpy
import numpy as np

from ..app import guide_cache
from ..engine import guides
from .. import image_info, read_image
from . import compat, fluid_velocity, rigid_tracks
from ..app.frames import MAX_FRAME, check_frame
from ..tracer.lpe import check_lpe, trace_lpe
from ..engine.guides import tonemap
from .scene_export import SceneExportError, evaluated_depsgraph, export_scene, path_settings


class GuideRenderError(RuntimeError):
    """A scene that cannot be rendered into guides; the message says what to change."""


# Settings changed while rendering guides, restored in this order afterwards
# (image settings: see compat.IMAGE_FORMAT_SETTINGS).
RENDER_SETTINGS = ("engine", "film_transparent", "filepath", "use_file_extension", "use_compositing",
                   "use_sequencer", "use_border")
IMAGE_SETTINGS = compat.IMAGE_FORMAT_SETTINGS
CYCLES_SETTINGS = ("device", "samples", "use_adaptive_sampling", "use_denoising", "sample_clamp_direct",
                   "sample_clamp_indirect", "seed", "use_animated_seed", "max_bounces", "diffuse_bounces",
                   "glossy_bounces", "transmission_bounces", "volume_bounces", "transparent_max_bounces",
                   "caustics_reflective", "caustics_refractive")
VIEW_LAYER_SETTINGS = ("use", "samples", "use_pass_combined", "use_pass_z", "use_pass_normal", "use_pass_vector",
                       "use_pass_object_index", "use_pass_diffuse_direct", "use_pass_diffuse_indirect",
                       "use_pass_diffuse_color", "use_pass_glossy_direct", "use_pass_glossy_color")

# Passes of each render (Blender's EXR pass names and their components).
MAIN_PASSES = {"Combined": "RGBA", "DiffDir": "RGB", "DiffInd": "RGB", "DiffCol": "RGB", "GlossDir": "RGB",
               "GlossCol": "RGB", "Vector": "XYZW", "Depth": "Z", "Normal": "XYZ", "IndexOB": "X"}
LD12E_PASSES = {"Combined": "RGBA", "DiffDir": "RGB", "DiffInd": "RGB", "DiffCol": "RGB"}
MOTION_PASSES = {"Combined": "RGBA", "Vector": "XYZW"}
PASS_PROPERTIES = {"Combined": "use_pass_combined", "DiffDir": "use_pass_diffuse_direct",
                   "DiffInd": "use_pass_diffuse_indirect", "DiffCol": "use_pass_diffuse_color",
                   "GlossDir": "use_pass_glossy_direct", "GlossCol": "use_pass_glossy_color",
                   "Vector": "use_pass_vector", "Depth": "use_pass_z", "Normal": "use_pass_normal",
                   "IndexOB": "use_pass_object_index"}
RENDERABLE_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "POINTCLOUD", "VOLUME"}


# --------------------------------------------------------------------------- settings

def _snapshot(struct, names):
    return [(name, getattr(struct, name)) for name in names if hasattr(struct, name)]


def _restore(struct, values):
    for name, value in values:
        if getattr(struct, name) != value:
            setattr(struct, name, value)


@contextmanager
def guide_render_settings(scene):
    """Snapshots every setting render_guides touches and restores it on exit,
    whatever happens inside (errors, cancelling)."""
    render = scene.render
    saved = [
        (render, _snapshot(render, RENDER_SETTINGS)),
        (render.image_settings, _snapshot(render.image_settings, IMAGE_SETTINGS)),
        (scene.cycles, _snapshot(scene.cycles, CYCLES_SETTINGS)),
        *((layer, _snapshot(layer, VIEW_LAYER_SETTINGS)) for layer in scene.view_layers),
        *((layer.freestyle_settings, _snapshot(layer.freestyle_settings, ("as_render_pass",)))
          for layer in scene.view_layers),
        *((obj, _snapshot(obj, ("pass_index",))) for obj in scene.objects),
    ]
    frame, subframe = scene.frame_current, scene.frame_subframe
    try:
        yield
    finally:
        for struct, values in saved:
            _restore(struct, values)
        scene.frame_set(frame, subframe=subframe)


@contextmanager
def shown_in_window(scene):
    """Makes `scene` the window's scene while rendering. Cycles computes the
    previous-frame half of the Vector pass (XY) only for the scene the window
    shows; for any other scene it is left all zeros (seen on Blender 3.4)."""
    windows = bpy.context.window_manager.windows
    window = bpy.context.window or (windows[0] if len(windows) else None)  # e.g. called from a timer
    if window is None or window.scene == scene:
        yield
        return
    saved_scene, saved_layer = window.scene, window.view_layer
    window.scene = scene
    try:
        yield
    finally:
        window.scene = saved_scene
        if window.view_layer != saved_layer:
            window.view_layer = saved_layer


def guide_view_layer(scene):
    """The view layer guides come from: the first one that renders."""
    for layer in scene.view_layers:
        if layer.use:
            return layer
    raise GuideRenderError(f"Scene '{scene.name}' has no view layer enabled for rendering.")


def check_scene(scene):
    """Raises GuideRenderError if guides cannot be rendered from `scene`."""
    if scene.render.use_motion_blur:
        # With motion blur Cycles leaves the Vector pass all zeros, so there
        # would be no motion guides; refuse instead of writing wrong ones.
        raise GuideRenderError(
            f"Motion blur is on in scene '{scene.name}': Blender then renders no motion vectors, which the "
            "guides need. Turn off Render Properties > Motion Blur and render the guides again.")
    if scene.camera is None:
        raise GuideRenderError(f"Scene '{scene.name}' has no active camera to render the guides from.")
    guide_view_layer(scene)


def check_lpe_expressions(expressions):
    """Raises GuideRenderError naming the first malformed light path
    expression and where it goes wrong, before anything is rendered."""
    if isinstance(expressions, str):
        raise GuideRenderError(f"The light path expressions must be a list of strings, got the string "
                               f"'{expressions}'.")
    seen = {}
    for i, expression in enumerate(expressions, start=1):
        if not isinstance(expression, str) or not expression.strip():
            raise GuideRenderError(f"Light path expression {i} is empty.")
        try:
            check_lpe(expression)
        except ValueError as exc:
            raise GuideRenderError(f"Light path expression {i} '{expression}' is malformed: {exc}") from None
        name = guide_cache.lpe_guide(expression)
        if name in seen:
            raise GuideRenderError(f"Light path expression {i} '{expression}' repeats expression {seen[name]}.")
        seen[name] = i


# Light Path Expressions field text -> what is wrong with it (None: fine),
# filled by the field's update callback (properties.py), never by draw():
# compiling an expression may take a while, and draw() runs on every redraw.
LPE_PROBLEMS = {}


def check_lpe_field(text):
    """Checks the field's expressions once per text (the update callback)."""
    if text not in LPE_PROBLEMS:
        if len(LPE_PROBLEMS) > 64:
            LPE_PROBLEMS.clear()
        try:
            check_lpe_expressions(guide_cache.split_expressions(text))
            LPE_PROBLEMS[text] = None
        except GuideRenderError as exc:
            LPE_PROBLEMS[text] = str(exc)
    return LPE_PROBLEMS[text]


# Valid ranges of the numeric guide parameters: (low, high, what it is);
# checked before anything is rendered, so no value can crash the renderer.
PARAM_RANGES = {
    "samples": (1, 1 << 20, "Cycles samples"),
    "ld12e_samples": (1, 1 << 20, "Cycles samples of the LD{1,2}E render"),
    "seed": (0, (1 << 31) - 1, "Cycles seed"),
    "occlusion_epsilon": (1e-6, 1e6, "occlusion epsilon (squared pixels)"),
    "tensor_sigma": (0.0, 1000.0, "structure tensor sigma (pixels)"),
    "line_depth_threshold": (0.0, 1e30, "line depth threshold"),
    "line_normal_angle": (0.0, 180.0, "line normal angle (degrees)"),
    "line_d_max": (1e-3, 1e6, "line distance max (pixels)"),
    "lpe_samples": (1, 1 << 20, "path-tracer samples"),
}
INT_PARAMS = {"samples", "ld12e_samples", "seed", "lpe_samples"}
MASK_MODES = ("objects+collections", "objects", "collections", "none")


def check_params(params):
    """Raises ValueError naming the first guide parameter out of its range."""
    for name, (low, high, what) in PARAM_RANGES.items():
        value = params[name]
        integral = isinstance(value, int) and not isinstance(value, bool)
        if name in INT_PARAMS and not integral:
            raise ValueError(f"{name} ({what}) must be a whole number, got {value!r}")
        if not integral and not isinstance(value, float):
            raise ValueError(f"{name} ({what}) must be a number, got {value!r}")
        if not (math.isfinite(value) and low <= value <= high):
            raise ValueError(f"{name} ({what}) must be from {low:g} to {high:g}, got {value!r}")
    if params["masks"] not in MASK_MODES:
        raise ValueError(f"masks must be one of {', '.join(MASK_MODES)}, got {params['masks']!r}")
    if not isinstance(params["orientation_aov"], str):
        raise ValueError(f"orientation_aov must be a string, got {params['orientation_aov']!r}")


def trace_lpe_guides(scene, layer, frame, size, params, paths=None):
    """({guide name: (H, W, 3) radiance}, warnings) of the frame's light path
    expressions, traced on the scene as the view layer evaluates it at
    `frame`, with the light path settings `paths` (scene_export.path_settings
    of the user's scene, taken before render_guides changes any; by default
    the scene's current ones): bounce limits and caustics options."""
    try:
        scene_dict, warnings = export_scene(scene, evaluated_depsgraph(scene, layer, frame), size)
    except SceneExportError as exc:
        raise GuideRenderError(str(exc)) from None
    images, _alpha = trace_lpe(scene_dict, params["lpe"], samples=params["lpe_samples"], seed=params["seed"],
                               **(paths or path_settings(scene)))
    return {guide_cache.lpe_guide(e): image for e, image in zip(params["lpe"], images)}, warnings


def check_orientation_aov(scene, layer, name):
    """The artist's direction AOV must be a Color AOV declared on the layer
    (Tempera reads it; it does not add AOVs to the user's file)."""
    aov = next((a for a in layer.aovs if a.name == name), None)
    if aov is None or aov.type != "COLOR":
        raise GuideRenderError(
            f"Shader AOV '{name}' is not declared as a Color AOV on view layer '{layer.name}' of scene "
            f"'{scene.name}': add it in View Layer Properties > Shader AOV (type Color) and write the stroke "
            "direction to it with an AOV Output node in the materials.")


def aov_tensor(direction, computed):
    """Structure tensor of the artist's stroke directions (screen space, y up):
    the tensor of the gradient across the strokes, the form the computed
    orientation has, so both read back the same way. Pixels where no
    direction was written keep the computed tensor."""
    dx, dy = direction[:, :, 0], -direction[:, :, 1]  # to row-down image coordinates
    nx, ny = -dy, dx  # across the stroke
    tensor = np.dstack([nx * nx, nx * ny, ny * ny]).astype(np.float32)
    written = (dx * dx + dy * dy) > 1e-6
    return np.where(written[:, :, None], tensor, computed)


def _configure(scene, layer, samples, passes, seed):
    """Cycles settings that keep passes usable as guides: no denoising (it
    smears passes differently), no clamping (it biases indirect light), a fixed
    seed, output as a 32-bit multilayer EXR with exactly `passes`."""
    render, cycles = scene.render, scene.cycles
    render.engine = "CYCLES"
    render.film_transparent = True  # alpha guide; the background is then 0 in the light paths
    render.use_file_extension = False
    render.use_compositing = False  # the EXR holds the render passes, not a composite
    render.use_sequencer = False
    render.use_border = False  # guides cover the whole frame
    settings = render.image_settings
    compat.set_file_format(settings, "OPEN_EXR_MULTILAYER")
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    cycles.device = "CPU"
    cycles.samples = samples
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.seed = seed
    cycles.use_animated_seed = False
    cycles.caustics_reflective = False  # L.*DDE without caustic paths (the definition)
    cycles.caustics_refractive = False
    for other in scene.view_layers:
        other.use = other == layer
    layer.samples = 0  # no per-layer override of the samples
    for name, prop in PASS_PROPERTIES.items():
        setattr(layer, prop, name in passes)
    # The user's Freestyle lines (if they draw any) go to their own pass, so
    # the light-path guides stay line-free and the lines join the line guide.
    layer.freestyle_settings.as_render_pass = "Freestyle" in passes


def _render(scene, path, frame):
    scene.frame_set(frame)
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    if not Path(path).is_file():
        raise RuntimeError(f"Blender did not write {path}")
    return path


def _read_passes(path, layer_name, passes):
    channels = image_info(str(path))["channels"]
    return {name: read_image(str(path), [f"{layer_name}.{compat.exr_pass_name(channels, layer_name, name)}.{c}"
                                         for c in comps])
            for name, comps in passes.items()}


# --------------------------------------------------------------------------- scene description

def assign_pass_indices(scene, mode):
    """Gives every renderable object a pass index 1..N (restored afterwards by
    guide_render_settings) and returns {mask guide: (kind, name, [indices])}."""
    objects = sorted((o for o in scene.objects if o.type in RENDERABLE_TYPES), key=lambda o: o.name)
    index = {}
    for i, obj in enumerate(objects, start=1):
        obj.pass_index = i
        index[obj.name] = i
    masks = {}
    if mode in ("objects", "objects+collections"):
        for obj in objects:
            masks[guide_cache.mask_guide("OB", obj.name)] = ("object", obj.name, [index[obj.name]])
    if mode in ("collections", "objects+collections"):
        for coll in scene.collection.children_recursive:
            members = sorted(index[o.name] for o in coll.all_objects if o.name in index)
            masks[guide_cache.mask_guide("CO", coll.name)] = ("collection", coll.name, members)
    return masks


def scene_fingerprint(scene, frame):
    """What the guides of `frame` depend on besides the parameters: camera and
    lens, resolution, bounces, film, the world, and every object with its
    transform or, if animated, its keyframes, mesh size, modifiers, materials
    (their node values and links) and light settings.

    Taken from the original data, not evaluated at `frame`: evaluated
    transforms of a scene are not reliable outside the active depsgraph (seen
    stale after a render on Blender 3.4). The file itself is not part of it,
    so saving, or copying the .blend to a render farm, keeps the cache current.
    Not seen: drivers, constraints, and mesh edits that keep the vertex and
    face counts (delete the cache folder to re-render after those)."""
    render = scene.render
    return {
        "blender": bpy.app.version_string, "scene": scene.name, "frame": frame,
        "camera": scene.camera.name, "resolution": effective_resolution(scene),
        "view_layer": guide_view_layer(scene).name, "world": _world_fingerprint(scene.world),
        "bounces": [scene.cycles.max_bounces, scene.cycles.diffuse_bounces, scene.cycles.glossy_bounces,
                    scene.cycles.transmission_bounces, scene.cycles.transparent_max_bounces,
                    scene.cycles.caustics_reflective, scene.cycles.caustics_refractive, scene.cycles.blur_glossy],
        "pixel_aspect": [render.pixel_aspect_x, render.pixel_aspect_y],
        "film": [scene.cycles.film_exposure, scene.cycles.pixel_filter_type, scene.cycles.filter_width],
        "camera_data": _camera_fingerprint(scene.camera.data),
        "objects": [_object_fingerprint(o) for o in sorted(scene.objects, key=lambda o: o.name)],
    }


def _socket_value(socket):
    """An unlinked input's value in JSON terms (numbers, lists, names)."""
    value = getattr(socket, "default_value", None)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if hasattr(value, "name"):  # an ID such as an object or image
        return value.name
    try:
        return [float(v) for v in value]
    except (TypeError, ValueError):
        return str(value)


def _node_tree_fingerprint(tree):
    if tree is None:
        return None
    nodes = [[n.name, n.bl_idname, n.mute, getattr(getattr(n, "image", None), "name", None),
              [[i.identifier, _socket_value(i)] for i in n.inputs if not i.is_linked]]
             for n in sorted(tree.nodes, key=lambda n: n.name)]
    links = sorted([l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier]
                   for l in tree.links)
    return [nodes, links]


def _material_fingerprint(material):
    if material is None:
        return None
    shading = _node_tree_fingerprint(material.node_tree) if material.use_nodes else list(material.diffuse_color)
    return [material.name, shading]


def _world_fingerprint(world):
    if world is None:
        return None
    return [world.name, _node_tree_fingerprint(world.node_tree) if world.use_nodes else list(world.color)]


def _light_fingerprint(light):
    return [light.type, light.energy, list(light.color), light.shadow_soft_size, getattr(light, "size", None),
            getattr(light, "size_y", None), getattr(light, "spot_size", None), getattr(light, "angle", None),
            _node_tree_fingerprint(light.node_tree) if light.use_nodes else None]


def _animation(id_block):
    """Keyframes of an ID's action as a list (None if it is not animated)."""
    anim = getattr(id_block, "animation_data", None)
    if anim is None or anim.action is None:
        return None
    return [[fc.data_path, fc.array_index, fc.extrapolation,
             [[*k.co, *k.handle_left, *k.handle_right, k.interpolation] for k in fc.keyframe_points]]
            for fc in compat.action_fcurves(id_block)]


def _camera_fingerprint(camera):
    return [camera.type, camera.lens, camera.ortho_scale, camera.sensor_fit, camera.sensor_width,
            camera.sensor_height, camera.shift_x, camera.shift_y, camera.clip_start, camera.clip_end]


def _object_fingerprint(obj):
    animation = _animation(obj)
    transform = None
    if animation is None:  # animated values depend on the frame last evaluated, the keyframes do not
        transform = [list(obj.location), list(obj.rotation_euler), list(obj.rotation_quaternion),
                     obj.rotation_mode, list(obj.scale)]
    mesh = [len(obj.data.vertices), len(obj.data.polygons)] if obj.type == "MESH" else None
    modifiers = [[m.name, m.type, m.show_render] for m in obj.modifiers]
    light = _light_fingerprint(obj.data) if obj.type == "LIGHT" else None
    return [obj.name, obj.type, obj.data.name if obj.data else None, obj.hide_render,
            obj.parent.name if obj.parent else None, transform, animation, _animation(obj.data), mesh,
            modifiers, [_material_fingerprint(slot.material) for slot in obj.material_slots], light]


def effective_resolution(scene):
    """(width, height) Blender renders: resolution times its percentage."""
    r = scene.render
    return [int(r.resolution_x * r.resolution_percentage / 100), int(r.resolution_y * r.resolution_percentage / 100)]


# --------------------------------------------------------------------------- guides of one frame

def light_path_guides(main, ld12e):
    """Linear radiance guides from the passes of the two renders."""
    rgb = {name: a[:, :, :3] for name, a in main.items()}
    return {
        "FULL": rgb["Combined"],
        "LDE": rgb["DiffDir"] * rgb["DiffCol"],
        "LSE": rgb["GlossDir"] * rgb["GlossCol"],
        "LDDE": rgb["DiffInd"] * rgb["DiffCol"],
        "LD12E": (ld12e["DiffDir"] + ld12e["DiffInd"]) * ld12e["DiffCol"],
    }


def surface_velocities(passes):
    """(velocity_backward, velocity_forward) of the surfaces a render's
    Vector and Combined passes show."""
    vector = compat.surface_vector_pass(passes["Vector"], passes["Combined"][:, :, 3])
    return guide_cache.velocities_from_vector_pass(vector)


def frame_guides(main, ld12e, v_plus_prev, v_minus_next, masks, params):
    """Every guide of one frame, as written to the cache."""
    backward, forward = surface_velocities(main)
    eps = params["occlusion_epsilon"]
    lines = guide_cache.line_guide(main["Depth"], main["Normal"], params["line_depth_threshold"],
                                   params["line_normal_angle"])
    if "Freestyle" in main:  # the artist's own Freestyle lines count too
        lines = np.maximum(lines, (main["Freestyle"][:, :, 3] > 0.5).astype(np.float32))
    out = light_path_guides(main, ld12e)
    out.update({
        "velocity_forward": forward,
        "velocity_backward": backward,
        "occlusion_backward": guides.occlusion_backward(backward, v_plus_prev, eps),
        "occlusion_forward": guides.occlusion_forward(forward, v_minus_next, eps),
        # Of the tone-mapped render, as seen, so that dark areas have structure too.
        "tensor": np.asarray(guides.structure_tensor(tonemap(out["FULL"]), params["tensor_sigma"])),
        "alpha": main["Combined"][:, :, 3],
        "depth": main["Depth"],
        "normal": main["Normal"],
        "lines": lines,
        "line_distance": guides.line_distance(lines, params["line_d_max"]),
    })
    if params["orientation_aov"]:
        out["tensor"] = aov_tensor(main[params["orientation_aov"]], out["tensor"])
    index = np.rint(main["IndexOB"][:, :, 0])
    for guide, (_kind, _name, indices) in masks.items():
        out[guide] = np.isin(index, indices).astype(np.float32)
    return out


# --------------------------------------------------------------------------- the whole run

def render_guides(scene, frames, out_dir, params=None, progress=None):
    """Renders the guides of `frames` of `scene` into the cache folder `out_dir`.

    Frames whose cache is current (same parameters, same scene at that frame)
    are skipped. `params` overrides tempera.app.guide_cache.DEFAULT_PARAMS.
    `progress(done, total, message)` is called as frames complete.
    Returns {"rendered": [frames], "skipped": [frames], "manifest": path,
    "warnings": [what the light-path tracer approximates]}.
    Raises GuideRenderError with an explanation if the scene cannot be used
    or a light path expression is malformed (before rendering anything).
    """
    unknown = set(params or {}) - set(guide_cache.DEFAULT_PARAMS)
    if unknown:
        raise ValueError(f"unknown guide parameters {sorted(unknown)}; known: {sorted(guide_cache.DEFAULT_PARAMS)}")
    params = {**guide_cache.DEFAULT_PARAMS, **(params or {})}
    # A list of stripped strings: as JSON gives it back, so that the manifest's params compare equal.
    lpe = params["lpe"]
    params["lpe"] = lpe if isinstance(lpe, str) else [e.strip() if isinstance(e, str) else e for e in lpe]
    check_params(params)
    check_lpe_expressions(params["lpe"])
    check_scene(scene)
    if isinstance(frames, range) and len(frames) > MAX_FRAME + 1:
        raise ValueError(f"render_guides: {len(frames)} frames; Blender has frames 0-{MAX_FRAME} only")
    frames = sorted({check_frame(f) for f in frames})
    if not frames:
        raise ValueError("render_guides: no frames to render")
    out_dir = Path(out_dir)
    report = {"rendered": [], "skipped": [], "manifest": out_dir / guide_cache.MANIFEST_NAME, "warnings": []}
    warn = report["warnings"].append  # a damaged manifest set aside is said in the report
    manifest = guide_cache.read_manifest(out_dir, warn) or {}
    if manifest.get("params") != params:
        manifest = {}  # other parameters: no cached frame can be current
    paths = path_settings(scene)  # the user's, before the Cycles guides change them
    with shown_in_window(scene), guide_render_settings(scene):
        keys = {f: guide_cache.frame_key(params, scene_fingerprint(scene, f)) for f in frames}
        todo = [f for f in frames if not guide_cache.is_frame_current(out_dir, manifest, f, keys[f])]
        report["skipped"] = [f for f in frames if f not in todo]
        if _has_stale_frames(scene, manifest, out_dir, params) and not todo:
            guide_cache.update_manifest(out_dir, lambda m: _forget_stale_frames(scene, m, out_dir, params), warn)
        if todo:
            out_dir.mkdir(parents=True, exist_ok=True)
            with _work_folder(out_dir) as tmp:
                report["warnings"] += _render_frames(scene, todo, keys, manifest, out_dir, tmp, params, progress,
                                                     warn, paths)
        report["rendered"] = todo
    bodies = rigid_tracks.rigid_body_objects(scene)
    if bodies:  # a rigid-body world: its tracks beside the masks (docs/rigid_bodies.md)
        report["warnings"] += rigid_tracks.write_tracks(scene, bodies, out_dir)
    return report


WORK_PREFIX = ".tempera-render-"


@contextmanager
def _work_folder(out_dir):
    """A folder for the renders in progress, inside the cache (same file
    system, so nothing is left in the system's temporary folder), holding a
    lock while its run lives. Folders of runs that died (kill -9, power cut)
    are removed here: their lock is free."""
    import fcntl

    for old in out_dir.glob(WORK_PREFIX + "*"):
        try:
            fd = os.open(old, os.O_RDONLY | os.O_DIRECTORY)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            shutil.rmtree(old, ignore_errors=True)
        except OSError:
            pass  # a live run holds it
        finally:
            os.close(fd)
    tmp = out_dir / f"{WORK_PREFIX}{os.getpid()}-{secrets.token_hex(4)}"
    tmp.mkdir()
    fd = os.open(tmp, os.O_RDONLY | os.O_DIRECTORY)  # locked through itself while this run lives
    fcntl.flock(fd, fcntl.LOCK_EX)
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        os.close(fd)


def _has_stale_frames(scene, manifest, out_dir, params):
    return any(not guide_cache.is_frame_current(
        out_dir, manifest, int(f), guide_cache.frame_key(params, scene_fingerprint(scene, int(f))), verify=False)
        for f in manifest.get("frames", {}))


def _forget_stale_frames(scene, manifest, out_dir, params):
    """Drops the manifest entries of frames rendered from an older state of the
    scene (the manifest lists only current frames). True if any was dropped."""
    entries = manifest.get("frames", {})
    stale = [f for f in entries if not guide_cache.is_frame_current(
        out_dir, manifest, int(f), guide_cache.frame_key(params, scene_fingerprint(scene, int(f))), verify=False)]
    for f in stale:
        del entries[f]
    if stale and entries:
        manifest["frame_range"] = [min(map(int, entries)), max(map(int, entries))]
    return bool(stale)


def uses_freestyle(scene, layer):
    """Whether the user draws Freestyle lines on this layer (Blender writes no
    Freestyle pass when no line set renders)."""
    settings = layer.freestyle_settings
    drawing = settings.mode != "EDITOR" or any(lineset.show_render for lineset in settings.linesets)
    return scene.render.use_freestyle and layer.use_freestyle and drawing


def _render_frames(scene, todo, keys, manifest, out_dir, tmp, params, progress, warn=None, paths=None):
    layer = guide_view_layer(scene)
    masks = assign_pass_indices(scene, params["masks"])
    main_passes = {**MAIN_PASSES, "Freestyle": "RGBA"} if uses_freestyle(scene, layer) else dict(MAIN_PASSES)
    if params["orientation_aov"]:
        check_orientation_aov(scene, layer, params["orientation_aov"])
        main_passes[params["orientation_aov"]] = "RGB"  # declared AOVs are written with every render
    total = len(todo)
    todo_set = set(todo)

    def step(done, message):
        if progress:
            progress(done, total, message)

    # Occlusion needs the velocities of the neighbouring frames, so a frame is
    # finished once the next one is rendered (or is not to be rendered); then
    # its EXR goes into the cache atomically and its entry into the manifest.
    # An interrupted run keeps every frame finished so far, and `tmp` holds at
    # most three frames' renders.
    renders = {}
    has_fluids = bool(fluid_velocity.fluid_objects(scene))
    fluids = {}  # frame -> (fluid samples, camera matrix), read before the frame's render

    def render(frame):
        if has_fluids:
            fluids[frame] = _fluid_state(scene, layer, frame)
        _configure(scene, layer, params["samples"], main_passes, params["seed"])
        main = _render(scene, tmp / f"main_{frame}.exr", frame)
        _configure(scene, layer, params["ld12e_samples"], LD12E_PASSES, params["seed"])
        with _ld12e_bounces(scene):
            ld12e = _render(scene, tmp / f"ld12e_{frame}.exr", frame)
        renders[frame] = (main, ld12e)

    finished = {}  # frame -> manifest entry, of this run

    def velocities(frame):
        """(backward, forward) velocities of a neighbouring frame: rendered
        now, finished in this run, in the cache, or from a quick motion-only
        render (one sample: only its velocities are used)."""
        if frame in renders:
            return surface_velocities(_read_passes(renders[frame][0], layer.name, MOTION_PASSES))
        if frame in finished or guide_cache.is_frame_current(out_dir, manifest, frame, keys.get(frame)):
            cached = guide_cache.read_frame(out_dir, frame, ["velocity_backward", "velocity_forward"])
            return cached["velocity_backward"], cached["velocity_forward"]
        _configure(scene, layer, 1, MOTION_PASSES, params["seed"])
        path = _render(scene, tmp / f"motion_{frame}.exr", frame)
        return surface_velocities(_read_passes(path, layer.name, MOTION_PASSES))

    warnings = []

    def finish(i, frame):
        main = _read_passes(renders[frame][0], layer.name, main_passes)
        ld12e = _read_passes(renders[frame][1], layer.name, LD12E_PASSES)
        _, v_plus_prev = velocities(frame - 1)
        v_minus_next, _ = velocities(frame + 1)
        frame_data = frame_guides(main, ld12e, v_plus_prev, v_minus_next, masks, params)
        height, width = main["Combined"].shape[:2]
        samples, clip = fluids.pop(frame, (None, None))
        if samples is not None:
            frame_data["fluid_velocity"] = fluid_velocity.fluid_velocity_guide(samples, clip,
                                                                               main["Combined"][:, :, 3])
        if params["lpe"]:
            step(i, f"tracing the light path expressions of frame {frame}")
            traced, frame_warnings = trace_lpe_guides(scene, layer, frame, (width, height), params, paths)
            frame_data.update(traced)
            warnings.extend(w for w in frame_warnings if w not in warnings)
        guide_cache.write_frame(out_dir, frame, frame_data)
        finished[frame] = guide_cache.frame_entry(out_dir, frame, keys[frame])
        guide_names = list(frame_data)

        def merge(on_disk):
            # Under the folder's lock: other runs (a farm) add their frames too.
            if on_disk.get("params") != params:
                on_disk.clear()  # made with other parameters: none of its frames is current for us
            entries = on_disk.get("frames", {})
            entries.update({str(f): e for f, e in finished.items()})
            on_disk.clear()
            on_disk.update(_manifest(scene, layer, params, entries, guide_names, masks, (width, height)))

        nonlocal manifest
        manifest = guide_cache.update_manifest(out_dir, merge, warn)
        for old in [f for f in renders if f < frame]:  # no later frame needs them
            for path in renders.pop(old):
                Path(path).unlink(missing_ok=True)
        step(i + 1, f"guides of frame {frame} written")

    done = 0
    for frame in todo:
        step(done, f"rendering frame {frame}")
        render(frame)
        if frame - 1 in todo_set and frame - 1 not in finished:
            finish(done, frame - 1)
            done += 1
        if frame + 1 not in todo_set:
            finish(done, frame)
            done += 1
    return warnings


def _fluid_state(scene, layer, frame):
    """(fluid samples or None, world to clip matrix) of `frame`, read from the
    scene evaluated afresh (a render can leave Blender 3.4's evaluated objects
    stale: scene_export.evaluated_depsgraph)."""
    depsgraph = evaluated_depsgraph(scene, layer, frame)
    return (fluid_velocity.scene_fluid_samples(scene, depsgraph),
            fluid_velocity.world_to_clip(scene, depsgraph, effective_resolution(scene)))


@contextmanager
def _ld12e_bounces(scene):
    """Bounce limits that leave only light paths L D E and L D D E: one
    diffuse bounce, no glossy or transmission; the user's limits come back
    for the next main render."""
    cycles = scene.cycles
    saved = _snapshot(cycles, ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                               "volume_bounces"))
    cycles.diffuse_bounces = 1
    cycles.glossy_bounces = 0
    cycles.transmission_bounces = 0
    cycles.volume_bounces = 0
    cycles.max_bounces = max(cycles.max_bounces, 1)
    try:
        yield
    finally:
        _restore(cycles, saved)


def _manifest(scene, layer, params, frames, guide_names, masks, size):
    render = scene.render
    numbers = sorted(int(f) for f in frames)
    return {
        "scene": scene.name,
        "camera": scene.camera.name,
        "view_layer": layer.name,
        "resolution": list(size),
        "resolution_setting": [render.resolution_x, render.resolution_y, render.resolution_percentage],
        "frame_range": [numbers[0], numbers[-1]],
        "frames": frames,
        "guides": guide_names,
        "masks": {g: {"kind": kind, "name": name} for g, (kind, name, _) in masks.items()},
        "lpe": {guide_cache.lpe_guide(e): e for e in params["lpe"]},
        "blender_version": bpy.app.version_string,
        "source_file": bpy.data.filepath or None,
        "params": params,
        "conventions": {"rows": "top-down", "x": "right", "y": "down", "velocity_unit": "pixels",
                        "light_paths": "linear radiance, background 0 (transparent film)"},
    }
