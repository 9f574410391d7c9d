"""Per-scene Tempera settings, stored in the .blend file as Scene.tempera."""
import bpy
from bpy.props import IntProperty, StringProperty
from bpy.types import PropertyGroup

from .. import settings as limits


def _keep_patch_size_odd(self, _context):
    size = limits.odd_patch_size(self.patch_size)
    if size != self.patch_size:
        self.patch_size = size  # re-runs this callback once, with an odd value


class TemperaSettings(PropertyGroup):
    output_dir: StringProperty(
        name="Output Folder",
        description="Folder for Tempera's guide passes and stylized frames; "
        "'//' is relative to the .blend file",
        subtype="DIR_PATH",
        default=limits.DEFAULT_OUTPUT_DIR,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed of the synthesis: the same seed and inputs give the same frames",
        default=0,
        min=0,
    )
    patch_size: IntProperty(
        name="Patch Size",
        description="Side in pixels of the square patches matched between style exemplar and frame. "
        f"Odd values only ({limits.PATCH_SIZE_MIN}, {limits.PATCH_SIZE_MIN + 2}, ... "
        f"{limits.PATCH_SIZE_MAX}); an even value is rounded up. Larger patches keep bigger "
        "brush strokes intact, smaller ones follow the guides more closely",
        default=limits.PATCH_SIZE_DEFAULT,
        min=limits.PATCH_SIZE_MIN,
        max=limits.PATCH_SIZE_MAX,
        step=2,
        update=_keep_patch_size_odd,
    )
