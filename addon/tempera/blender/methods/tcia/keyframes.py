"""Painted keyframes of the coherent method (Scene.tempera.keyframes): the
list in the panel and its operators.

Add Keyframe turns the current frame into an image to paint over: the frame's
StyLit result (Stylize Frame), or else its render in low contrast (the guide
cache's FULL). It is saved in the Keyframe Folder (beside the .blend by
default) as key_0012.png, never over an existing painting, and opened in the
Image Editor in Paint mode when Blender has a window. Import Key registers a
painting made elsewhere for the current frame. Stylize Animation saves key
images painted in Blender but not saved yet before it reads them.
"""
import os

import bpy
import numpy as np
from bpy.props import IntProperty
from bpy.types import Operator, UIList

from ... import compat, results
from ...guide_operator import resolve_guide_dir
from ...kit_operators import ImageFileChooser
from ...setting_paths import FRAMES_DIR, output_dir, resolve_path

LOW_CONTRAST = 0.4  # the render's tones squeezed around mid grey: a ground to paint on, not a picture


def key_file_name(frame):
    return f"key_{frame:04d}.png"


def keyframe_ground(scene, frame):
    """(image (H, W, 3) in [0, 1], what it is) to paint keyframe `frame` over:
    its StyLit result if there is one, else its render in low contrast."""
    import tempera
    from tempera.app import guide_cache
    from tempera.engine.guides import tonemap


    settings = scene.tempera
    for ext in ("png", "exr"):
        path = os.path.join(output_dir(settings), FRAMES_DIR, f"frame_{frame:04d}.{ext}")
        if os.path.isfile(path):
            return np.clip(tempera.read_image(path)[:, :, :3], 0, 1), "its StyLit result"
    guides = resolve_guide_dir(settings.guide_dir)
    if not os.path.isfile(os.path.join(guides, f"frame_{frame:04d}.exr")):
        raise ValueError(f"Frame {frame} has no StyLit result and no guides yet: Stylize Frame (or Render "
                         "Guides Only) on it first.")
    full = tonemap(guide_cache.read_frame(guides, frame, ["FULL"])["FULL"])
    return 0.5 + LOW_CONTRAST * (full - 0.5), "its render in low contrast"


def add_key(settings, frame, painting, mask=""):
    """Registers (or re-points) the keyframe of `frame`; its index in the list."""
    for i, key in enumerate(settings.keyframes):
        if key.frame == frame:
            key.painting, key.mask = painting, mask
            settings.keyframe_index = i
            return i
    key = settings.keyframes.add()
    key.frame, key.painting, key.mask = frame, painting, mask
    settings.keyframe_index = len(settings.keyframes) - 1
    return settings.keyframe_index


def key_list(settings, layer=None):
    """[(frame, painting path, mask path or None), ...] in frame order, for
    tempera.methods.tcia.tcia.ShotJob: the keys of the whole frame, or those of the
    layer `layer` (a collection). Keys painted in Blender are saved first."""

    keys = []
    for key in settings.keyframes:
        if key.layer != layer:
            continue
        painting = resolve_path(key.painting, f"painting of keyframe {key.frame}")
        for image in bpy.data.images:
            if image.is_dirty and image.filepath and os.path.normpath(bpy.path.abspath(image.filepath)) == painting:
                image.save()
        mask = resolve_path(key.mask, f"mask of keyframe {key.frame}") if key.mask.strip() else None
        keys.append((key.frame, painting, mask))
    frames = [k[0] for k in keys]
    if len(set(frames)) != len(frames):
        whose = "" if layer is None else f" of layer '{layer.name}'"
        raise ValueError(f"Two keyframes{whose} are of the same frame: remove one from the Keyframes list.")
    return sorted(keys)


def open_for_painting(context, image):
    """The image in an Image Editor in Paint mode (an open editor, else a new
    window); where it went, for the report."""
    for _window, area in results._areas(context):
        if area.type == "IMAGE_EDITOR":
            area.spaces.active.image = image
            compat.image_paint_mode(area.spaces.active)
            area.tag_redraw()
            return f"'{image.name}' open in the Image Editor in Paint mode"
    return results.show(context, image, "IMAGE")


class TEMPERA_UL_keyframes(UIList):
    """The painted keyframes: frame and painting."""

    def draw_item(self, _context, layout, _data, item, _icon, _active_data, _active_prop, _index=0, _flt_flag=0):
        row = layout.row(align=True)
        row.prop(item, "frame", text="", emboss=False)
        row.label(text=os.path.basename(item.painting) or "(no painting)", icon="IMAGE_DATA")
        if item.mask:
            row.label(text="", icon="MOD_MASK")


class TEMPERA_OT_add_keyframe(Operator):
    """Make the current frame a keyframe: its StyLit result (or its render in low contrast) saved as an image in
    the Keyframe Folder and opened for painting in the Image Editor"""

    bl_idname = "tempera.add_keyframe"
    bl_label = "Add Keyframe"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        import tempera


        scene = context.scene
        settings, frame = scene.tempera, scene.frame_current
        try:
            folder = resolve_path(settings.keyframe_dir, "Keyframe Folder")
            path = os.path.join(folder, key_file_name(frame))
            if os.path.isfile(path):
                what = "your painting (kept)"
            else:
                ground, what = keyframe_ground(scene, frame)
                os.makedirs(folder, exist_ok=True)
                tempera.write_image(path, np.ascontiguousarray(ground, np.float32))
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        add_key(settings, frame, path)
        image = bpy.data.images.load(path, check_existing=True)
        image.reload()
        where = "" if bpy.app.background else open_for_painting(context, image)
        self.report({"INFO"}, f"Tempera: keyframe {frame} is {path} ({what})" + (f"; {where}" if where else ""))
        return {"FINISHED"}


class TEMPERA_OT_import_keyframe(ImageFileChooser, Operator):
    """Register a keyframe painted elsewhere (the frame's size) for the current frame"""

    bl_idname = "tempera.import_keyframe"
    bl_label = "Import Key"
    bl_options = {"REGISTER", "UNDO"}

    frame: IntProperty(name="Frame", default=-1, options={"SKIP_SAVE"}, description="-1: the current frame")

    def execute(self, context):
        if not self.chosen("key painting"):
            return {"CANCELLED"}
        frame = context.scene.frame_current if self.frame < 0 else self.frame
        add_key(context.scene.tempera, frame, self.filepath)
        self.report({"INFO"}, f"Tempera: keyframe {frame} is {self.filepath}")
        return {"FINISHED"}


class TEMPERA_OT_remove_keyframe(Operator):
    """Remove the selected keyframe from the list (its image file stays)"""

    bl_idname = "tempera.remove_keyframe"
    bl_label = "Remove Keyframe"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and len(context.scene.tempera.keyframes) > 0

    def execute(self, context):
        remove_selected(context.scene.tempera, "keyframes", "keyframe_index")
        return {"FINISHED"}


def remove_selected(settings, items, index):
    """Removes the selected item of the list `settings.<items>` (selection
    `settings.<index>`) and keeps the selection within the list."""
    listed = getattr(settings, items)
    listed.remove(min(getattr(settings, index), len(listed) - 1))
    setattr(settings, index, max(0, min(getattr(settings, index), len(listed) - 1)))


CLASSES = (TEMPERA_UL_keyframes, TEMPERA_OT_add_keyframe, TEMPERA_OT_import_keyframe, TEMPERA_OT_remove_keyframe)
