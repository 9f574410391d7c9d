"""Tempera: stylize 3D animations by example.

This folder is two things at once:

* the legacy Blender add-on "Tempera" (``bl_info``, ``register``,
  ``unregister``; the Blender UI lives in the ``tempera.blender`` subpackage,
  the only place that imports ``bpy``), and
* the plain Python package ``tempera``, importable without Blender, e.g. by
  pytest, render-farm scripts or a pip-installed wheel.
"""

bl_info = {
    "name": "Tempera",
    "author": "Tempera developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Output > Tempera",
    "description": "Stylize 3D animations by example",
    "category": "Render",
}

__version__ = "0.1.0"  # keep equal to project(tempera VERSION ...) in CMakeLists.txt

try:
    from ._native import Cancelled, image_info, read_image, write_image
except ImportError as exc:  # not built, or built for another Python
    raise ImportError(
        f"tempera: the compiled module tempera._native cannot be loaded ({exc}). "
        "Build it with 'make build' in the Tempera source tree "
        "(or install the add-on zip / wheel made by 'make addon-zip' / 'make wheel')."
    ) from exc

# Python API on top of the native module; public entry points are listed in __all__.
from .contact_sheet import contact_sheet
from .lpe import check_lpe, trace_lpe
from .synthesis import USAGE_MODES, SynthesisOptions, synthesize

__all__ = [
    "__version__",
    "Cancelled",
    "check_lpe",
    "contact_sheet",
    "image_info",
    "read_image",
    "synthesize",
    "SynthesisOptions",
    "trace_lpe",
    "USAGE_MODES",
    "write_image",
]


def register():
    from . import blender  # imports bpy; only ever reached inside Blender

    blender.register()


def unregister():
    from . import blender

    blender.unregister()
