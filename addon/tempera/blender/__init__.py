"""Tempera's Blender UI: preferences, scene settings and the Output panel.

The only part of the `tempera` package that imports bpy. register() and
unregister() are symmetric: after unregister() no Tempera class is left in
bpy.types and Scene.tempera is gone (the values stored in .blend files stay,
and come back when the add-on is enabled again).
"""
import bpy

from . import job_operator, kit_operators, methods
from .guide_operator import TEMPERA_OT_render_guides
from .panels import TEMPERA_PT_output
from .preferences import TemperaPreferences
from .properties import TemperaSettings
from .stylize_operator import TEMPERA_OT_stylize

# Registration order: property groups before the pointers and panels using
# them; each method's own (tempera.blender.methods) before Scene.tempera's group.
CLASSES = (
    TemperaPreferences,
    *methods.classes(),
    TemperaSettings,
    TEMPERA_OT_render_guides,
    TEMPERA_OT_stylize,
    *kit_operators.CLASSES,
    TEMPERA_PT_output,
)


def register(addon_id="tempera"):
    """`addon_id`: the module name Blender knows the add-on by ('tempera', or
    'bl_ext.<repository>.tempera' for the extension); the preferences are
    registered under it."""
    TemperaPreferences.bl_idname = addon_id
    job_operator._set_running(None, False)  # a run cut short by disabling the add-on is over
    methods.add_properties(TemperaSettings)  # each method's own (tempera.blender.methods), before registering
    registered = []
    try:
        for cls in CLASSES:
            bpy.utils.register_class(cls)
            registered.append(cls)
        bpy.types.Scene.tempera = bpy.props.PointerProperty(
            type=TemperaSettings, name="Tempera", description="Tempera stylization settings"
        )
        kit_operators.register_previews()
    except Exception:
        # Leave nothing half-registered behind: Blender does not call
        # unregister() when register() fails.
        for cls in reversed(registered):
            bpy.utils.unregister_class(cls)
        raise


def unregister():
    kit_operators.unregister_previews()
    if hasattr(bpy.types.Scene, "tempera"):
        del bpy.types.Scene.tempera
    for cls in reversed(CLASSES):
        if cls.is_registered:
            bpy.utils.unregister_class(cls)
