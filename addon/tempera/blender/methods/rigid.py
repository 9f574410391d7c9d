"""The rigid-body method in the panel (Dvorožňák et al. 2017,
docs/rigid_bodies.md): drawn examples blended around the collisions of a
rigid-body world, a step per target object and chunk of frames, then the
composites by depth, into Output Folder/rigid/frames (each step resumable;
Esc stops within a step and nothing of it is written). Stylize Frame stays
per-frame StyLit."""
import os
import time

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from ... import _native
from ..guide_operator import GuideJob, estimate_guide_seconds, format_duration
from ..layout import wide_prop
from ..setting_paths import FRAMES_DIR, output_dir, resolve_path
from ..stylize_operator import StylizeRun

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
        "drawn/NNNN.png (as `tempera rigid --exemplar` takes them), or a folder of such folders; "
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


RIGID_DIR = "rigid"  # the method's folder in the Output Folder
SECONDS_PER_FRAME = 0.2  # per object and frame at 640 x 360, loaded machine (docs/benchmarks.md)


def rigid_options(settings):
    """The panel's RigidOptions keywords (names of the method's option table)."""
    return {"k": int(settings.rigid_k), "augment": bool(settings.rigid_augment), "damp": bool(settings.rigid_damp),
            "stroke_weight": float(settings.rigid_stroke_weight)}


class RigidRun(StylizeRun):
    """Guides of every frame, then the rigid-body method (RigidJob), a step
    per object and chunk of frames, then its composites."""

    def __init__(self, scene, frames, mode="ANIMATION"):
        from ..rigid_tracks import rigid_body_objects

        settings = scene.tempera
        self.mode = mode
        self.frames = list(frames)
        self.out = output_dir(settings)
        from ...methods.rigid.rigid_job import exemplar_folders

        self.examples = None  # empty: the project's own drawn exemplar, written with the results
        if settings.rigid_examples.strip():
            self.examples = resolve_path(settings.rigid_examples, "rigid-body Examples folder")
            exemplar_folders(self.examples)  # a named error now, not after the guides
        bodies = {o.name for o in rigid_body_objects(scene)}
        if not bodies:
            raise ValueError("Rigid Bodies needs a rigid-body world with active bodies in the scene.")
        self.objects = None  # every body the tracks hold
        if settings.rigid_collection is not None:
            self.objects = sorted(o.name for o in settings.rigid_collection.all_objects if o.name in bodies)
            if not self.objects:
                raise ValueError(f"The collection '{settings.rigid_collection.name}' holds no active rigid body.")
        self.guides = GuideJob.from_settings(scene, self.frames)
        self.config = {"out": os.path.join(self.out, RIGID_DIR, FRAMES_DIR), "format": "png", "quality": "final"}
        self.shape, self.paper = settings.rigid_shape, settings.rigid_output == "PAPER"
        self.options = rigid_options(settings)
        self.strokes = None
        if settings.rigid_strokes == "GENERATED":
            from ...methods.rigid.rigid_strokes import GENERATED

            self.strokes = GENERATED
        elif settings.rigid_strokes == "IMAGE":
            from ...methods.rigid.rigid_strokes import load_stroke_exemplar

            self.strokes = resolve_path(settings.rigid_stroke_image, "rigid-body Stroke Image")
            load_stroke_exemplar(self.strokes)  # a named error now, not after the guides
        self.noise = None
        self.job = None  # the RigidJob, made once the guides (and tracks.json) exist
        self.index = 0
        self.results = []
        self.step_results = []
        self.stylize_seconds = 0.0
        self.warnings = []

    def _rigid_job(self):
        from ...methods.rigid.rigid_job import RigidJob

        if self.job is None:
            examples = self.examples
            if examples is None:
                from ...methods.rigid.rigid_cli import generated_exemplar_folder

                examples = os.path.join(self.out, RIGID_DIR, "generated_examples")
                generated_exemplar_folder(examples, self.shape)
            self.job = RigidJob(self.guides.folder, examples, os.path.join(self.out, RIGID_DIR), self.frames,
                                objects=self.objects, shape=self.shape, paper=self.paper, strokes=self.strokes,
                                **self.options)
        return self.job

    @property
    def stylize_steps(self):
        # Known once the first rigid step has read the tracks; until then, an estimate.
        return self.job.total if self.job is not None else len(self.frames)

    @property
    def in_noise_phase(self):
        return False  # no Temporal Noise after the rigid-body method

    def _stylize(self, progress):
        job = self._rigid_job()
        i = self.index - len(self.frames)
        started = time.monotonic()
        result = job.run_step(i, progress)
        if result["status"] != "kept":
            self.stylize_seconds += time.monotonic() - started
        self.step_results.append(result)
        if result["object"] is None:  # a composite step: these frames are the result
            self.results += [{"frame": f, "path": str(job.output_path(f)), "status": result["status"]}
                             for f in result["frames"]]
        if bpy.app.background:
            what = result["object"] or "composite"
            print(f"Tempera: rigid {what} frames {result['frames'][0]}-{result['frames'][-1]} {result['status']} "
                  f"in {time.monotonic() - started:.1f} s", flush=True)

    def current_frame(self):
        if self.in_guide_phase or self.job is None:
            return super().current_frame()
        return self.job.steps[min(self.index - len(self.frames), self.job.total - 1)][1][0]

    def eta_seconds(self):
        done = [r for r in self.step_results if r["status"] == "stylized"]
        left = self.stylize_steps - len(self.step_results)
        if not done or left <= 0:
            return None
        return self.stylize_seconds / len(self.step_results) * left

    def status_text(self):
        if self.in_guide_phase:
            return self.guides.status_text()
        job = self.job
        if job is None:
            return "Tempera: rigid bodies, fitting the drawn examples (Esc to stop)"
        i = min(self.index - len(self.frames), job.total - 1)
        name, frames = job.steps[i]
        eta = self.eta_seconds()
        eta_text = "" if eta is None else f", ETA {format_duration(eta)}"
        what = f"drawing {name}" if name else "compositing"
        return (f"Tempera: rigid bodies, {what} frames {frames[0]}-{frames[-1]} (step {i + 1}/{job.total})"
                f"{eta_text} (Esc to stop)")

    def estimate_seconds(self, scene):
        return estimate_guide_seconds(scene, self.guides.params, len(self.frames)) + SECONDS_PER_FRAME * len(
            self.frames) * (len(self.objects) if self.objects else 1)

    def summary(self):
        made = sum(r["status"] != "kept" for r in self.step_results)
        kept = len(self.step_results) - made
        left = self.stylize_steps - len(self.step_results) if self.job is not None else self.stylize_steps
        parts = [f"{made} rigid-body steps done"] + ([f"{kept} already done"] if kept else []) + (
            [f"{left} not done"] if left > 0 else [])
        return f"Tempera: {', '.join(parts)} in {self.config['out']}"


def run(scene, frames, mode):
    """Stylize Animation's run; Stylize Frame stays per-frame StyLit (None)."""
    return RigidRun(scene, frames, mode) if mode == "ANIMATION" else None
