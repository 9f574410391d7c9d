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

def _load_native():
    """The compiled engine: tempera._native next to this file (source tree,
    legacy add-on zip), else the one of the self-contained wheel
    (tempera_native._native, with its own OpenImageIO, Embree and TBB),
    which is then also importable as tempera._native."""
    import importlib
    import sys

    errors = []
    for name in (__name__ + "._native", "tempera_native._native"):
        try:
            module = importlib.import_module(name)
        except ImportError as exc:
            errors.append(f"{name}: {exc}")
            continue
        sys.modules[__name__ + "._native"] = module
        return module
    raise ImportError(
        "tempera: the compiled module tempera._native cannot be loaded (" + "; ".join(errors) + "). "
        "Build it with 'make build' in the Tempera source tree "
        "(or install the add-on zip / extension / wheel made by 'make addon-zip' / 'make extension' / 'make wheel')."
    )


_native = _load_native()
Cancelled, image_info, read_image, write_image = (
    _native.Cancelled, _native.image_info, _native.read_image, _native.write_image)
max_image_pixels, set_max_image_pixels = _native.max_image_pixels, _native.set_max_image_pixels

# Python API on top of the native module; public entry points are listed in __all__.
from .app.contact_sheet import contact_sheet
from .tracer.lpe import TraceOptions, check_lpe, trace_lpe
from .engine.synthesis import USAGE_MODES, SynthesisOptions, synthesize

__all__ = [
    "__version__",
    "Cancelled",
    "check_lpe",
    "contact_sheet",
    "image_info",
    "max_image_pixels",
    "read_image",
    "set_max_image_pixels",
    "synthesize",
    "SynthesisOptions",
    "trace_lpe",
    "TraceOptions",
    "USAGE_MODES",
    "write_image",
]


def register(addon_id=None):
    """Blender's entry point. `addon_id` is the module name Blender knows the
    add-on by: 'tempera' for the legacy add-on (the default), or the
    extension's 'bl_ext.<repository>.tempera' when the extension shim calls it."""
    from . import blender  # imports bpy; only ever reached inside Blender

    blender.register(addon_id or __name__)


def unregister():
    from . import blender

    blender.unregister()
