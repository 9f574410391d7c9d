"""Stylized frames loaded back into Blender and shown, without touching the artist's scene."""
import os

import bpy

from . import compat

RESULT_SCENE_SUFFIX = " Tempera"
COMPOSITE_SCENE_SUFFIX = " Tempera Composite"  # RGBA results over the render
RESULT_MARK = "tempera_result"  # custom property of a result scene (the panel hides there)


def load(scene, paths, frames, how):
    """Loads the stylized frames `paths` (of `frames`, in order): "IMAGE" as an
    image (sequence) data-block, "SEQUENCER" as an image strip in the
    sequencer of a scene of its own, "NONE" not at all. Returns what was made."""
    if not paths or how == "NONE":
        return None
    if how == "IMAGE":
        return load_image(paths, frames)
    if how == "SEQUENCER":
        return load_sequencer_scene(scene, paths, frames)
    raise ValueError(f"unknown Load Result '{how}'")


def load_image(paths, frames):
    """One image data-block named after the folder: a SEQUENCE for several
    frames (the Image Editor plays it), a FILE for one; reloaded if present.
    It has a fake user, so saving the .blend keeps it."""
    name = f"Tempera {os.path.basename(os.path.dirname(paths[0]))}" + ("" if len(paths) > 1 else f" {frames[0]}")
    image = bpy.data.images.get(name)
    if image is None or bpy.path.abspath(image.filepath) != paths[0]:
        if image is not None:
            bpy.data.images.remove(image)
        image = bpy.data.images.load(paths[0])
        image.name = name
    image.source = "SEQUENCE" if len(paths) > 1 else "FILE"
    image.use_fake_user = True
    image.reload()
    return image


def is_result_scene(scene):
    return scene is not None and bool(scene.get(RESULT_MARK))


def load_sequencer_scene(scene, paths, frames):
    """A scene '<scene> Tempera' whose sequencer shows the frames as one image
    strip at their frame numbers, with the scene's frame rate and the frames'
    resolution (made anew on each run). Its view transform is Standard: the
    frames are display-referred paint, which Filmic would dim."""
    result = _new_result_scene(scene, scene.name + RESULT_SCENE_SUFFIX, paths[0], frames)
    _image_strip(result, "Tempera", paths, frames, channel=1)
    return result


def load_composite_scene(scene, render_paths, rgba_paths, frames):
    """A scene '<scene> Tempera Composite' whose sequencer lays the RGBA
    frames (channel 2, Alpha Over) over the render frames (channel 1): what
    the fluid and natural-media methods look like over the shot."""
    result = _new_result_scene(scene, scene.name + COMPOSITE_SCENE_SUFFIX, rgba_paths[0], frames)
    _image_strip(result, "Render", render_paths, frames, channel=1)
    _image_strip(result, "Tempera", rgba_paths, frames, channel=2).blend_type = "ALPHA_OVER"
    return result


def _new_result_scene(scene, name, first_path, frames):
    """A new result scene `name` (replacing an old one) with the scene's frame
    rate, the frames' range and the resolution of the image at `first_path`,
    in the Standard view transform."""
    old = bpy.data.scenes.get(name)
    if old is not None:
        for window in bpy.context.window_manager.windows:  # no window may show a removed scene
            if window.scene == old:
                window.scene = scene
        bpy.data.scenes.remove(old)
    result = bpy.data.scenes.new(name)
    result[RESULT_MARK] = True
    result.use_fake_user = True
    result.render.fps, result.render.fps_base = scene.render.fps, scene.render.fps_base
    result.frame_start, result.frame_end = frames[0], frames[-1]
    result.frame_current = frames[0]
    first = bpy.data.images.load(first_path, check_existing=False)
    result.render.resolution_x, result.render.resolution_y = first.size
    result.render.resolution_percentage = 100
    bpy.data.images.remove(first)
    result.view_settings.view_transform = "Standard"
    result.view_settings.look = "None"
    result.view_settings.exposure = 0.0
    result.view_settings.gamma = 1.0
    result.display_settings.display_device = "sRGB"
    result.sequencer_colorspace_settings.name = "sRGB"
    return result


def _image_strip(result, name, paths, frames, channel):
    """An image strip of `paths` (one folder) from frames[0] in `result`'s sequencer."""
    editor = result.sequence_editor or result.sequence_editor_create()
    strip = compat.sequencer_strips(editor).new_image(name, paths[0], channel=channel, frame_start=frames[0])
    for path in paths[1:]:
        strip.elements.append(os.path.basename(path))
    return strip


def reload_images_under(folder):
    """Reloads every image data-block whose file lies in `folder` (or below):
    after a rerun, an Image Editor showing a frame shows the new pixels."""
    root = os.path.normpath(os.path.abspath(folder)) + os.sep
    reloaded = []
    for image in bpy.data.images:
        if image.source not in {"FILE", "SEQUENCE"} or not image.filepath:
            continue
        path = os.path.normpath(bpy.path.abspath(image.filepath, library=image.library))
        if path.startswith(root):
            image.reload()
            reloaded.append(image.name)
    return reloaded


def _windows(context):
    windows = getattr(context.window_manager, "windows", None)
    return [w for w in windows if isinstance(w, bpy.types.Window)] if windows is not None else []


def _areas(context):
    for window in _windows(context):
        for area in window.screen.areas:
            yield window, area


def show(context, loaded, how, interactive=None):
    """Shows what load() made; returns where, for the report ("" if nowhere).

    An image goes into an Image Editor: one already open, else a new window
    with one (not in background mode, which has no windows to open). A
    result scene becomes the scene of the window, with a sequencer editor
    set to show its preview if the screen has one; that happens only in the
    UI (`interactive`, default: not background mode), where someone sees it."""
    if loaded is None:
        return ""
    interactive = not bpy.app.background if interactive is None else interactive
    if how == "IMAGE":
        for _window, area in _areas(context):
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = loaded
                area.tag_redraw()
                return f"'{loaded.name}' shown in the Image Editor"
        if interactive and isinstance(context.window, bpy.types.Window):
            # Opened once the operator has returned: a window opened from a
            # modal handler would get a copy of that handler.
            window, name = context.window, loaded.name
            bpy.app.timers.register(lambda: _open_image_window(window, name), first_interval=0.05)
            return f"'{loaded.name}' shown in a new Image Editor window"
        return f"the result is the image '{loaded.name}' (open it in an Image Editor)"
    if how == "SEQUENCER":
        windows = _windows(context)
        window = context.window if isinstance(context.window, bpy.types.Window) else (windows[0] if windows else None)
        if window is None or not interactive:
            return f"the result is in scene '{loaded.name}' (its sequencer plays the frames)"
        window.scene = loaded
        for area in window.screen.areas:
            if area.type == "SEQUENCE_EDITOR":
                area.spaces.active.view_type = "SEQUENCER_PREVIEW"
                area.tag_redraw()
        return (f"now showing scene '{loaded.name}' (press Space to play; its sequencer holds the frames; "
                f"switch back to your scene in the scene selector at the top)")
    return ""


def _open_image_window(window, image_name):
    """A new window (a copy of `window`) whose largest area becomes an Image
    Editor showing the image; run from a timer. Returns None (timer done)."""
    wm = bpy.context.window_manager
    image = bpy.data.images.get(image_name)
    if image is None or window not in wm.windows[:]:
        return None
    before = set(wm.windows[:])
    try:
        area = max(window.screen.areas, key=lambda a: a.width * a.height)
        with bpy.context.temp_override(window=window, area=area):
            bpy.ops.wm.window_new()
    except (RuntimeError, TypeError):
        return None
    new = [w for w in wm.windows if w not in before]
    if new:
        target = max(new[0].screen.areas, key=lambda a: a.width * a.height)
        target.type = "IMAGE_EDITOR"
        target.spaces.active.image = image
    return None
