"""Properties editor > Output tab > Tempera."""
import bpy
from bpy.types import Panel

from .. import __version__


class TEMPERA_PT_output(Panel):
    bl_label = "Tempera"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.tempera

        layout.label(text=f"Version {__version__}")
        layout.prop(settings, "output_dir")
        if settings.output_dir.startswith("//") and not bpy.data.filepath:
            layout.label(text="Save the .blend file first: '//' is relative to it", icon="ERROR")
        col = layout.column()
        col.prop(settings, "patch_size")
        col.prop(settings, "seed")
