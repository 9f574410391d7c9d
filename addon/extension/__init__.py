"""Tempera as a Blender 4.2+ extension (the root module of the extension zip).

The extension zip holds this file, blender_manifest.toml, the bundled
exemplar kit (kit/) and the self-contained wheel (wheels/tempera_native-*.whl).
Blender installs the wheel into its shared site-packages folder for
extensions, which gives the Python package `tempera` with its compiled engine
and libraries. This module only points `tempera` at the kit shipped beside it
and registers the add-on under the extension's own module name
(bl_ext.<repository>.tempera), under which Blender keeps its preferences.
"""
from pathlib import Path


def register():
    import tempera
    from tempera.app import exemplar_kit as kit

    kit.KIT_DIR = Path(__file__).resolve().parent / "kit"
    tempera.register(addon_id=__name__)


def unregister():
    import tempera

    tempera.unregister()
