"""The exemplar from inside Blender: pick a painting (image files only), make
the printable painting template of the exemplar, and register a photo or
scan of the painted template as the exemplar's painting. Before, both kit
steps needed a terminal (scenes/exemplar_kit.py, python -m
tempera.methods.stylit.register_painting)."""
import os

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy.types import Operator

from .. import read_image, write_image
from .setting_paths import exemplar_paths, output_dir

KIT_FOLDER = "painting_kit"  # inside the Output Folder: template.pdf, template.png, kit.json, painting.png
IMAGE_GLOB = "*.png;*.jpg;*.jpeg;*.tif;*.tiff;*.exr;*.bmp;*.tga"

_previews = None  # bpy.utils.previews collection of the panel's thumbnail


def register_previews():
    global _previews
    import bpy.utils.previews

    if _previews is None:
        _previews = bpy.utils.previews.new()


def unregister_previews():
    global _previews
    if _previews is not None:
        bpy.utils.previews.remove(_previews)
        _previews = None


def painting_preview(path):
    """A thumbnail (bpy.types.ImagePreview) of the image at `path`, or None:
    Blender's preview system loads it once per file version. Its icon_id is
    what template_icon shows (0 in background mode, which has no icons)."""
    if _previews is None:
        return None
    try:
        key = f"{os.path.abspath(path)}|{os.stat(path).st_mtime_ns}"
    except OSError:
        return None
    return _previews.get(key) or _previews.load(key, path, "IMAGE")


def _kit_folder(settings):

    return os.path.join(output_dir(settings), KIT_FOLDER)


class ImageFileChooser:
    """Mix-in of the operators that take one image file from the file browser
    (image files only): invoke opens the browser, execute checks the choice."""

    filepath: StringProperty(subtype="FILE_PATH", options={"SKIP_SAVE"})
    filter_image: BoolProperty(default=True, options={"HIDDEN", "SKIP_SAVE"})
    filter_folder: BoolProperty(default=True, options={"HIDDEN", "SKIP_SAVE"})
    filter_glob: StringProperty(default=IMAGE_GLOB, options={"HIDDEN", "SKIP_SAVE"})

    def invoke(self, context, _event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def chosen(self, what):
        """True if filepath is a file; else reports that no `what` was chosen."""
        if os.path.isfile(self.filepath):
            return True
        self.report({"ERROR"}, f"No {what} chosen ('{self.filepath}' is not a file)")
        return False


class TEMPERA_OT_choose_painting(ImageFileChooser, Operator):
    """Choose your painted exemplar (image files only)"""

    bl_idname = "tempera.choose_painting"
    bl_label = "Choose Painting"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        if not self.chosen("painting"):
            return {"CANCELLED"}
        settings = context.scene.tempera
        settings.exemplar_source = "CUSTOM"
        settings.exemplar_style = self.filepath
        return {"FINISHED"}


class TEMPERA_OT_painting_template(Operator):
    """Write a printable painting template of the exemplar (its render, faded, inside four alignment marks)
    into the Output Folder's painting_kit folder: print it, paint over it, photograph it, then Register Photo"""

    bl_idname = "tempera.painting_template"
    bl_label = "Painting Template"
    bl_options = {"REGISTER"}

    def execute(self, context):
        from ..app import guide_cache
        from ..methods.stylit.painting_template import make_template, write_kit_json, write_pdf
        from ..engine.guides import tonemap

        settings = context.scene.tempera
        try:
            _style, guides, frame = exemplar_paths(settings)
            if frame is None:
                frames = sorted(int(p.stem[6:]) for p in __import__("pathlib").Path(guides).glob("frame_*.exr")
                                if p.stem[6:].isdigit())
                if len(frames) != 1:
                    raise ValueError(f"The Exemplar Guides folder '{guides}' holds {len(frames)} frames; "
                                     "set Exemplar Frame")
                frame = frames[0]
            render = tonemap(guide_cache.read_frame(guides, frame, ["FULL"])["FULL"])
            folder = _kit_folder(settings)
            os.makedirs(folder, exist_ok=True)
            template = make_template(render)
            write_image(os.path.join(folder, "template.png"), template.image)
            write_pdf(os.path.join(folder, "template.pdf"), template.image, template.page_mm,
                      caption="Tempera painting template: paint over the picture, keep the four marks visible")
            write_kit_json(os.path.join(folder, "kit.json"), template, guides=os.path.abspath(guides),
                           frame=frame)
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Painting template written: {os.path.join(folder, 'template.pdf')} "
                              "(print it at 100 %, paint over it, then Register Photo)")
        return {"FINISHED"}


class TEMPERA_OT_register_painting(ImageFileChooser, Operator):
    """Register a photo or scan of the painted template (made with Painting Template): it is aligned by
    its four marks and becomes the exemplar's painting (Exemplar is set to Custom)"""

    bl_idname = "tempera.register_painting"
    bl_label = "Register Photo"
    bl_options = {"REGISTER", "UNDO"}

    flatten: BoolProperty(name="Even Out Lighting", default=True,
                          description="Divide by the paper's colour as photographed: even lighting, white paper")

    def execute(self, context):
        from ..methods.stylit.painting_template import read_kit_json
        from ..methods.stylit.registration import register_painting

        settings = context.scene.tempera
        try:
            folder = _kit_folder(settings)
            kit_json = os.path.join(folder, "kit.json")
            if not os.path.isfile(kit_json):
                raise FileNotFoundError(f"No painting template in '{folder}': press Painting Template first "
                                        "(the photo is aligned to that template)")
            kit = read_kit_json(kit_json)
            photo = read_image(self.filepath)
            style = register_painting(photo, kit, flatten=self.flatten)
            painting = os.path.join(folder, "painting.png")
            write_image(painting, style)
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, f"Register Photo: {exc}")
            return {"CANCELLED"}
        settings.exemplar_source = "CUSTOM"
        settings.exemplar_style = painting
        settings.exemplar_guide_dir = kit["guides"]
        settings.exemplar_frame = int(kit["frame"])
        self.report({"INFO"}, f"Painting registered: {painting} is now the exemplar's Painting "
                              f"({style.shape[1]} x {style.shape[0]})")
        return {"FINISHED"}


CLASSES = (TEMPERA_OT_choose_painting, TEMPERA_OT_painting_template, TEMPERA_OT_register_painting)
