"""Per-scene Tempera settings, stored in the .blend file as Scene.tempera."""
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy.types import PropertyGroup

from ..app import guide_cache
from ..methods import registry
from ..app import settings as limits
from ..app.frames import MAX_FRAME
from . import noise_pass
from .methods import tooltip

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


EXEMPLAR_SOURCES = (
    ("KIT", "Bundled Kit", "The sphere-on-a-table exemplar shipped with the add-on, painted in coloured pencil"),
    ("CUSTOM", "Custom", "Your painting and the guide cache of the exemplar scene it was painted over"),
)
USAGE_ITEMS = (
    ("budget", "Error Budget", "StyLit: every exemplar patch is used about equally, except those that fit "
     "nowhere (no wash-out, no forced misfits). The default"),
    ("uniform", "Uniform", "Every exemplar patch used equally often (LazyFluids); may force misfits"),
    ("penalty", "Occurrence Penalty", "Overused patches cost more (Kaspar et al.); a softer uniformity"),
    ("histogram", "Usage Histogram", "Patches used far more than their share cost more (Bénard et al. 2013): "
     "breaks up repeated blotches while keeping the best fits"),
    ("footprint", "Footprint", "Patches whose area of the exemplar is already covered cost more (Fluidymation): "
     "even coverage for fluids and natural media"),
    ("none", "None", "Plain nearest neighbours: fastest, may wash out into few favourite patches"),
)
QUALITY_ITEMS = (
    ("preview", "Preview", "Fewer solver iterations: quick look at a frame"),
    ("final", "Final", "Full solver iterations"),
)
WARM_START_ITEMS = (
    ("off", "Off", "Solve every frame from scratch, coarse to fine (about 3x slower)"),
    ("auto", "Auto", "Start each frame from the previous one's matches when Temporal Coherence is above 0 "
                     "(the default): about 3x faster and steadier"),
    ("on", "On", "Always start from the previous frame's matches: faster, and less boil at Temporal Coherence 0"),
)
FORMAT_ITEMS = (
    ("png", "PNG", "8-bit sRGB PNG frames"),
    ("exr", "OpenEXR", "32-bit float EXR frames (the painting's values, unclamped)"),
)
RESULT_ITEMS = (
    ("SEQUENCER", "Sequencer Scene", "A scene '<scene> Tempera' whose sequencer plays the stylized frames "
     "(your scene is left untouched)"),
    ("IMAGE", "Image", "An image sequence data-block, for the Image Editor or the compositor's Image node"),
    ("NONE", "Nothing", "Only write the files"),
)
# Guide-cache guide name -> the Scene.tempera property holding its weight
# (one per light-path guide of the native table).
WEIGHT_PROPERTIES = {g["name"]: "weight_" + g["name"].lower() for g in limits.LIGHT_PATH_GUIDES}


def _weight(guide):
    return FloatProperty(name=guide["label"], min=0.0, soft_max=4.0, default=guide["weight"],
                         description=f"Weight of {guide['help']} ({guide['expression']})")


def _keep_patch_size_odd(self, _context):
    size = limits.odd_patch_size(self.patch_size)
    if size != self.patch_size:
        self.patch_size = size  # re-runs this callback once, with an odd value


def _check_lpe_field(self, _context):
    from .guide_render import check_lpe_field  # compiled here, once per text, never in draw()

    check_lpe_field(self.guide_lpe)


def _keep_guide_start_before_end(self, _context):
    if self.guide_frame_end < self.guide_frame_start:
        self.guide_frame_end = self.guide_frame_start


def _keep_guide_end_after_start(self, _context):
    if self.guide_frame_start > self.guide_frame_end:
        self.guide_frame_start = self.guide_frame_end


METHOD_ITEMS = registry.panel_items()  # the method registry (native/include/tempera/methods/registry.hpp)
MEDIA_EXEMPLAR_KINDS = (
    ("STILL", "Still Image", "One RGBA image (not for Natural Media, which needs the medium's motion)"),
    ("SEQUENCE", "Image Sequence", "A folder of frames, or the first file of a numbered sequence (ink_0001.png)"),
    ("MOVIE", "Movie", "A movie file, decoded to PNG frames once by ffmpeg (into Output Folder/exemplar_frames)"),
)
class TemperaSettings(PropertyGroup):
    output_dir: StringProperty(
        name="Output Folder",
        description="Where Stylize writes its results: the stylized frames (in frames/, with their resume "
        "record), contact_sheet.png and stylized.mp4. The guide passes go to the Guide Folder. "
        "'//' is relative to the .blend file",
        subtype="DIR_PATH",
        default=limits.DEFAULT_OUTPUT_DIR,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed of the synthesis: the same seed and inputs give the same frames",
        default=limits.SEED_DEFAULT,
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
        description="Frames of Stylize Animation and Render Guides (frames already done and current are skipped)",
        items=GUIDE_FRAME_RANGES,
        default="SCENE",
    )
    guide_frame_start: IntProperty(
        name="Start",
        description="First frame of the custom range",
        default=1,
        min=0,
        max=MAX_FRAME,
        update=_keep_guide_start_before_end,
    )
    guide_frame_end: IntProperty(
        name="End",
        description="Last frame of the custom range (included)",
        default=250,
        min=0,
        max=MAX_FRAME,
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
        description="How far (in squared pixels) a pixel's motion may disagree with the neighbouring frame's "
        "before it counts as hidden or newly revealed. There the temporal guide lets go and fresh paint "
        "is made. Lower: more fresh paint at edges (more flicker); higher: paint smears across "
        "occlusions. Typical 1-4 (default 2)",
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
        update=_check_lpe_field,
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

    # Exemplar and stylization (Stylize operator, tempera.blender.stylize_operator).
    exemplar_source: EnumProperty(name="Exemplar", items=EXEMPLAR_SOURCES, default="KIT",
                                  description="Where the style comes from")
    exemplar_style: StringProperty(
        name="Painting",
        description="Your painted exemplar (PNG, JPEG, TIFF or EXR), painted over the exemplar scene's render; "
        "'//' is relative to the .blend file",
        subtype="FILE_PATH",
        default="",
    )
    exemplar_guide_dir: StringProperty(
        name="Exemplar Guides",
        description="Guide cache of the exemplar scene (Render Guides on that scene, or `tempera render-guides`)",
        subtype="DIR_PATH",
        default="",
    )
    exemplar_frame: IntProperty(
        name="Exemplar Frame",
        description="Frame of the exemplar guide cache the painting matches; 0: the cache's only frame",
        default=0,
        min=0,
    )
    for _guide in limits.LIGHT_PATH_GUIDES:
        __annotations__[WEIGHT_PROPERTIES[_guide["name"]]] = _weight(_guide)
    del _guide
    usage: EnumProperty(name="Patch Usage", items=USAGE_ITEMS, default=limits.ENGINE_OPTIONS["usage"]["default"],
                        description="How evenly the exemplar's patches are used")
    quality: EnumProperty(name="Quality", items=QUALITY_ITEMS, default=limits.DEFAULT_QUALITY,
                          description=tooltip(limits.STYLIT_OPTIONS["quality"]))
    temporal_weight: FloatProperty(
        name="Temporal Coherence",
        description=tooltip(limits.STYLIT_OPTIONS["temporal_weight"]),
        default=limits.PANEL_TEMPORAL_WEIGHT,
        min=limits.STYLIT_OPTIONS["temporal_weight"]["min"],
        soft_max=2.0,
    )
    warm_start: EnumProperty(name="Warm Start", items=WARM_START_ITEMS,
                             default=limits.STYLIT_OPTIONS["warm_start"]["default"],
                             description=tooltip(limits.STYLIT_OPTIONS["warm_start"]))
    output_format: EnumProperty(name="Format", items=FORMAT_ITEMS, default="png",
                                description="File format of the stylized frames")
    make_video: BoolProperty(name="Video (mp4)", default=True,
                             description="Also encode the stylized animation as an mp4 (needs ffmpeg)")
    load_result: EnumProperty(name="Load Result", items=RESULT_ITEMS, default="SEQUENCER",
                              description="What to load into Blender after Stylize Animation")
    # Temporal Noise, the pass after the frames (tempera.blender.noise_pass).
    __annotations__.update(noise_pass.PROPERTIES)

    # The method (tempera.methods.registry); its own settings come from its module.
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default=registry.default_name().upper(),
                         description="How Stylize Animation paints the shot")

    # The exemplar of a medium, for the methods whose module says MEDIUM
    # (tempera.blender.methods); each method's own properties come from its
    # module (methods.add_properties, at registration).
    media_exemplar_kind: EnumProperty(name="Exemplar", items=MEDIA_EXEMPLAR_KINDS, default="SEQUENCE",
                                      description="What the exemplar of the medium is")
    media_exemplar: StringProperty(
        name="File", subtype="FILE_PATH", default="",
        description="The still, the sequence's folder or first file, or the movie; '//' is relative to the "
        ".blend file. Empty: the project's own (a smoke loop for Fluid, an ink drop for Natural Media)")
    media_masks: StringProperty(
        name="Masks", subtype="DIR_PATH", default="",
        description="Optional: a folder of the exemplar's mask frames (white = medium); empty: its alpha")
