"""The rigid-body method in the panel (Dvorožňák et al. 2017,
docs/rigid_bodies.md): drawn examples blended around the collisions of a
rigid-body world, a frame per step, into Output Folder/rigid/frames (each
frame resumable; Esc stops within a frame and nothing of it is written).
Stylize Frame stays per-frame StyLit."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ... import _native
from ...methods.rigid import rigid_strokes
from ..guide_operator import estimate_guide_seconds
from ..layout import wide_prop
from ..setting_paths import resolve_path
from ..stylize_operator import MethodRun

MEDIUM = False
EXEMPLAR_MASKS = False
OPTIONS = {row["name"]: row for row in _native.RigidOptions.table()}
SHAPES = (
    ("circle", "Circle", "The bodies and the drawn examples are balls"),
    ("box", "Box", "The bodies and the drawn examples are boxes (4-fold symmetric)"),
)
STROKES = (
    ("NONE", "As Drawn", "The examples' own lines"),
    ("GENERATED", "Brush Pen", "Lines re-made by the engine from the bundled blue brush-pen strokes"),
    ("IMAGE", "Stroke Image", "Lines re-made by the engine from your scan of strokes (RGBA, or dark ink on white)"),
)
OUTPUTS = (
    ("RGBA", "Over the Render", "Transparent RGBA frames of the drawn bodies, to lay over the render"),
    ("PAPER", "On Paper", "Opaque frames: the drawn bodies on paper"),
)
PROPERTIES = {
    "rigid_examples": StringProperty(
        name="Examples",
        description="The drawn examples: a folder with a source simulation's tracks.json and its drawn frames "
        "drawn/NNNN.png (as `tempera stylize --method rigid --exemplar` takes them), or a folder of such folders; "
        "'//' is relative to the .blend file. Empty: the project's own drawn bouncing ball",
        subtype="DIR_PATH", default=""),
    "rigid_collection": PointerProperty(
        name="Targets", type=bpy.types.Collection,
        description="The rigid bodies to draw; empty: every active body of the scene's rigid-body world"),
    "rigid_shape": EnumProperty(name="Shape", items=SHAPES, default="circle",
                                description="The proxy shape of the bodies and of the drawn examples"),
    "rigid_output": EnumProperty(name="Result", items=OUTPUTS, default="RGBA",
                                 description="What the drawn bodies are drawn on"),
    "rigid_k": IntProperty(
        name="Blended Examples", default=OPTIONS["k"]["default"], min=int(OPTIONS["k"]["min"]),
        max=int(OPTIONS["k"]["max"]), soft_max=8,
        description="K: how many of the closest drawn sub-sequences are blended around each collision"),
    "rigid_augment": BoolProperty(
        name="Augment Examples", default=OPTIONS["augment"]["default"],
        description="Also match the examples rotated, scaled and flipped (more close matches from few drawings)"),
    "rigid_damp": BoolProperty(
        name="Damp by Speed", default=OPTIONS["damp"]["default"],
        description="Slower bodies than the examples' deform less (the speed ratio, clamped)"),
    "rigid_strokes": EnumProperty(name="Strokes", items=STROKES, default="NONE",
                                  description="Re-synthesize the lines with the engine on a stroke-position guide"),
    "rigid_stroke_image": StringProperty(
        name="Stroke Image", subtype="FILE_PATH", default="",
        description="Your strokes (RGBA ink on transparent paper, or dark ink on white); '//' is relative to the "
        ".blend file"),
    "rigid_stroke_weight": FloatProperty(
        name="Stroke Guide", default=OPTIONS["stroke_weight"]["default"], min=OPTIONS["stroke_weight"]["min"],
        soft_max=16.0,
        description="How closely the re-made strokes keep to the drawn lines (the stroke-position guide's weight)"),
}


def draw(box, settings):
    """The drawn examples, the targets, the result, the method's options
    (from its option table) and the strokes."""
    col = box.column()
    col.prop(settings, "rigid_examples")
    col.prop(settings, "rigid_collection")
    col.prop(settings, "rigid_shape")
    col.prop(settings, "rigid_output")
    col.prop(settings, "rigid_k")
    col.prop(settings, "rigid_augment")
    col.prop(settings, "rigid_damp")
    col.prop(settings, "rigid_strokes")
    if settings.rigid_strokes == "IMAGE":
        col.prop(settings, "rigid_stroke_image")
    if settings.rigid_strokes != "NONE":
        wide_prop(col, settings, "rigid_stroke_weight")


SECONDS_PER_FRAME = 0.2  # per object and frame at 640 x 360, loaded machine (docs/benchmarks.md)


def rigid_options(settings, objects):
    """The panel's settings as the method's command-line flags (make_job's
    options): OBJECTS are the target bodies (None: every tracked one)."""
    flags = [("shape", settings.rigid_shape), ("paper", settings.rigid_output == "PAPER"),
             ("k", int(settings.rigid_k)), ("augment", bool(settings.rigid_augment)),
             ("damp", bool(settings.rigid_damp)), ("stroke-weight", float(settings.rigid_stroke_weight))]
    if settings.rigid_strokes == "GENERATED":  # the engine's own blue brush pen
        flags.append(("strokes", rigid_strokes.GENERATED))
    elif settings.rigid_strokes == "IMAGE":
        strokes = resolve_path(settings.rigid_stroke_image, "rigid-body Stroke Image")
        rigid_strokes.load_stroke_exemplar(strokes)  # a named error now, not after the guides
        flags.append(("strokes", strokes))
    return flags + [("object", name) for name in objects or ()]


class RigidRun(MethodRun):
    """Guides of every frame (they write the bodies' tracks.json), then the
    rigid-body method's job (native/src/methods/rigid/rigid_job.cpp) a frame
    per step: every target body drawn, laid far to near, into
    Output Folder/rigid/frames."""

    folder = "rigid"
    method_label = "rigid-body"

    def __init__(self, scene, frames, mode="ANIMATION"):
        from ..rigid_tracks import rigid_body_objects

        settings = scene.tempera
        exemplar = _native.JOB_MADE_EXEMPLAR  # empty: the project's own drawn ball, written beside the frames
        if settings.rigid_examples.strip():
            exemplar = resolve_path(settings.rigid_examples, "rigid-body Examples folder")
            _native.rigid_exemplar_folders(exemplar)  # a named error now, not after the guides
        bodies = {o.name for o in rigid_body_objects(scene)}
        if not bodies:
            raise ValueError("Rigid Bodies needs a rigid-body world with active bodies in the scene.")
        objects = None  # every body the tracks hold
        if settings.rigid_collection is not None:
            objects = sorted(o.name for o in settings.rigid_collection.all_objects if o.name in bodies)
            if not objects:
                raise ValueError(f"The collection '{settings.rigid_collection.name}' holds no active rigid body.")
        self.objects = objects
        self.over_render = settings.rigid_output == "RGBA"  # on paper: opaque frames, shown alone
        super().__init__(scene, frames, mode, exemplar, rigid_options(settings, objects), "png")

    def estimate_seconds(self, scene):
        return estimate_guide_seconds(scene, self.guides.params, len(self.frames)) + SECONDS_PER_FRAME * len(
            self.frames) * (len(self.objects) if self.objects else 1)


def run(scene, frames, mode):
    """Stylize Animation's run; Stylize Frame stays per-frame StyLit (None)."""
    return RigidRun(scene, frames, mode) if mode == "ANIMATION" else None
