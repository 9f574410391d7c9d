"""Where the panel's path settings point: the Output Folder, the exemplar, any
'//'-relative path. Operators, key and layer lists and the kit share these, so
they live apart from every operator (no import cycles between them)."""
import os

import bpy

from ..app import exemplar_kit as kit

FRAMES_DIR = "frames"  # the stylized frames, in the Output Folder (or a method's folder in it)


def resolve_path(setting, what, blend_filepath=None):
    """Absolute path of a path setting ('//' relative to the .blend file)."""
    path = setting.strip()
    if not path:
        raise ValueError(f"Set the {what} in Output Properties > Tempera.")
    if path.startswith("//"):
        blend_filepath = bpy.data.filepath if blend_filepath is None else blend_filepath
        if not blend_filepath:
            raise ValueError(f"Save the .blend file first: the {what} '{setting}' is relative to it ('//'). "
                             "Or choose an absolute path.")
        path = bpy.path.abspath(path, start=os.path.dirname(blend_filepath))
    return os.path.normpath(path)


def exemplar_paths(settings):
    """(painting, exemplar guide cache, exemplar frame or None) of the Exemplar setting."""
    if settings.exemplar_source == "KIT":
        style, guides = kit.kit_exemplar()
        return str(style), str(guides), None
    style = resolve_path(settings.exemplar_style, "exemplar Painting")
    guides = resolve_path(settings.exemplar_guide_dir, "Exemplar Guides folder")
    if not os.path.isfile(style):
        raise FileNotFoundError(f"The exemplar painting '{style}' does not exist.")
    if not os.path.isdir(guides):
        raise FileNotFoundError(f"The exemplar guide folder '{guides}' does not exist "
                                "(render the exemplar scene's guides first).")
    return style, guides, settings.exemplar_frame or None


def output_dir(settings):
    return resolve_path(settings.output_dir, "Output Folder")
