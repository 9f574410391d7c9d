"""Stylized frames loaded back into Blender, without touching the artist's scene."""
import os

import bpy

from . import compat

RESULT_SCENE_SUFFIX = " Tempera"


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
    frames (the Image Editor plays it), a FILE for one; reloaded if present."""
    name = f"Tempera {os.path.basename(os.path.dirname(paths[0]))}" + ("" if len(paths) > 1 else f" {frames[0]}")
    image = bpy.data.images.get(name)
    if image is None or bpy.path.abspath(image.filepath) != paths[0]:
        if image is not None:
            bpy.data.images.remove(image)
        image = bpy.data.images.load(paths[0])
        image.name = name
    image.source = "SEQUENCE" if len(paths) > 1 else "FILE"
    image.reload()
    return image


def load_sequencer_scene(scene, paths, frames):
    """A scene '<scene> Tempera' whose sequencer shows the frames as one image
    strip at their frame numbers, with the scene's frame rate and the frames'
    resolution (made anew on each run)."""
    name = scene.name + RESULT_SCENE_SUFFIX
    old = bpy.data.scenes.get(name)
    if old is not None:
        bpy.data.scenes.remove(old)
    result = bpy.data.scenes.new(name)
    result.render.fps, result.render.fps_base = scene.render.fps, scene.render.fps_base
    result.frame_start, result.frame_end = frames[0], frames[-1]
    first = bpy.data.images.load(paths[0], check_existing=False)
    result.render.resolution_x, result.render.resolution_y = first.size
    result.render.resolution_percentage = 100
    bpy.data.images.remove(first)
    editor = result.sequence_editor_create()
    strip = compat.sequencer_strips(editor).new_image("Tempera", paths[0], channel=1, frame_start=frames[0])
    for path in paths[1:]:
        strip.elements.append(os.path.basename(path))
    return result
