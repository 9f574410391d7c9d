"""Per-scene Tempera settings, stored in the .blend file as Scene.tempera."""
import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy.types import PropertyGroup

from .. import guide_cache
from .. import settings as limits

DEFAULT_GUIDE_DIR = "//tempera/guides/"

# Frames the Render Guides operator renders (tempera.blender.guide_operator.guide_frames).
GUIDE_FRAME_RANGES = (
    ("CURRENT", "Current Frame", "Only the scene's current frame"),
    ("SCENE", "Scene Range", "The scene's frame range (Output Properties > Frame Range)"),
    ("CUSTOM", "Custom Range", "The Start and End frames below"),
)
# Enum item -> guide_cache.DEFAULT_PARAMS["masks"] value.
GUIDE_MASK_MODES = {
    "OBJECTS_COLLECTIONS": "objects+collections",
    "OBJECTS": "objects",
    "COLLECTIONS": "collections",
    "NONE": "none",
}
_MASK_ITEMS = (
    ("OBJECTS_COLLECTIONS", "Objects and Collections", "A mask per renderable object and per collection"),
    ("OBJECTS", "Objects", "A mask per renderable object"),
    ("COLLECTIONS", "Collections", "A mask per collection (its objects and its children's)"),
    ("NONE", "None", "No mask guides"),
)
_DEFAULT_MASK_MODE = next(k for k, v in GUIDE_MASK_MODES.items() if v == guide_cache.DEFAULT_PARAMS["masks"])


def _keep_patch_size_odd(self, _context):
    size = limits.odd_patch_size(self.patch_size)
    if size != self.patch_size:
        self.patch_size = size  # re-runs this callback once, with an odd value


def _keep_guide_start_before_end(self, _context):
    if self.guide_frame_end < self.guide_frame_start:
        self.guide_frame_end = self.guide_frame_start


def _keep_guide_end_after_start(self, _context):
    if self.guide_frame_start > self.guide_frame_end:
        self.guide_frame_start = self.guide_frame_end


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

    # Guides (Render Guides operator, tempera.blender.guide_operator). Only the
    # parameters of guide_cache.DEFAULT_PARAMS an artist is expected to change;
    # the defaults are those of DEFAULT_PARAMS.
    guide_dir: StringProperty(
        name="Guide Folder",
        description="Folder of the guide cache (one EXR per frame and manifest.json); "
        "'//' is relative to the .blend file",
        subtype="DIR_PATH",
        default=DEFAULT_GUIDE_DIR,
    )
    guide_frame_range: EnumProperty(
        name="Frames",
        description="Which frames Render Guides renders (frames already in the cache and current are skipped)",
        items=GUIDE_FRAME_RANGES,
        default="SCENE",
    )
    guide_frame_start: IntProperty(
        name="Start",
        description="First frame of the custom guide range",
        default=1,
        min=0,
        update=_keep_guide_start_before_end,
    )
    guide_frame_end: IntProperty(
        name="End",
        description="Last frame of the custom guide range (included)",
        default=250,
        min=0,
        update=_keep_guide_end_after_start,
    )
    guide_samples: IntProperty(
        name="Samples",
        description="Cycles samples of each guide render (more: less noisy light-path guides, slower)",
        default=guide_cache.DEFAULT_PARAMS["samples"],
        min=1,
        soft_max=1024,
    )
    guide_occlusion_epsilon: FloatProperty(
        name="Occlusion Epsilon",
        description="Tolerance of the occlusion guides in squared pixels: a pixel whose motion disagrees "
        "with its neighbour frame's by more than this counts as (dis)occluded",
        default=guide_cache.DEFAULT_PARAMS["occlusion_epsilon"],
        min=0.01,
        soft_max=20.0,
    )
    guide_line_d_max: FloatProperty(
        name="Line Distance Max",
        description="Distance in pixels at which the line-distance guide stops growing",
        default=guide_cache.DEFAULT_PARAMS["line_d_max"],
        min=0.1,
        soft_min=1.0,
        soft_max=100.0,
        subtype="PIXEL",
    )
    guide_masks: EnumProperty(
        name="Masks",
        description="Which mask guides to render (from the object-index pass)",
        items=_MASK_ITEMS,
        default=_DEFAULT_MASK_MODE,
    )
    guide_lpe: StringProperty(
        name="Light Path Expressions",
        description=("Extra light-path guides traced by Tempera's own path tracer, one RGB guide per "
                     "expression, separated by ';' or ','. Written light to eye: L light, D diffuse, "
                     "S glossy/specular, T transmission, E eye; . any, * + ? {m,n} [..] | (..). "
                     "E.g. 'L.*SDE; LD{2}E' (caustics; second diffuse bounce)"),
        default="; ".join(guide_cache.DEFAULT_PARAMS["lpe"]),
    )
    guide_lpe_samples: IntProperty(
        name="LPE Samples",
        description="Path-tracer samples per pixel of each light path expression guide",
        default=guide_cache.DEFAULT_PARAMS["lpe_samples"],
        min=1,
        soft_max=4096,
    )
    guide_orientation_aov: StringProperty(
        name="Orientation AOV",
        description=("Color shader AOV of the view layer in which your materials write the stroke direction "
                     "(R = screen x, G = screen y); empty: orientation computed from the render"),
        default=guide_cache.DEFAULT_PARAMS["orientation_aov"],
    )
