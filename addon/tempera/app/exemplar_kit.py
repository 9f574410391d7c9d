"""The exemplar kit bundled with the add-on (no bpy): the light-path
methods' exemplar when an artist has painted none.

`make addon-zip` renders StyLit's "sphere on a table" exemplar
(scenes/exemplar_kit.py), paints it with tempera.methods.stylit.exemplar_paint and packs
it into the add-on as

    tempera/kit/<variant>/style.png       the painted exemplar (A')
    tempera/kit/<variant>/guides/         its guide cache (A), one frame
    tempera/kit/<variant>/render.png      the plain render, for reference

so that an artist can stylize a scene before painting an exemplar of their own.
"""
import os
from pathlib import Path

# The legacy add-on zip carries the kit inside the package; the extension
# carries it beside its own __init__.py, which points KIT_DIR there.
# Either way the kit folder is tempera/kit, the package above this file;
# $TEMPERA_KIT_DIR points elsewhere (a studio's own kits, laid out the same).
KIT_DIR = Path(os.environ.get("TEMPERA_KIT_DIR") or Path(__file__).resolve().parents[1] / "kit")
DEFAULT_VARIANT = "sphere_on_table"
STYLE_NAME = "style.png"
GUIDES_NAME = "guides"


def kit_exemplar(variant=DEFAULT_VARIANT, kit_dir=None):
    """(painting path, guide cache folder) of a bundled kit variant (in
    `kit_dir`, default KIT_DIR); raises FileNotFoundError naming what is
    missing and how to get it."""
    kit_dir = KIT_DIR if kit_dir is None else kit_dir
    folder = Path(kit_dir) / variant
    style, guides = folder / STYLE_NAME, folder / GUIDES_NAME
    if not (style.is_file() and (guides / "manifest.json").is_file()):
        available = sorted(p.name for p in Path(kit_dir).iterdir() if p.is_dir()) if Path(kit_dir).is_dir() else []
        raise FileNotFoundError(
            f"The bundled exemplar kit '{variant}' is not in this build of the add-on ({folder}); "
            f"kits present: {', '.join(available) or 'none'}. Build the add-on with 'make addon-zip', "
            "or choose your own exemplar (a painting and its guide cache).")
    return style, guides
