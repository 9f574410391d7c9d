"""Stylize Frame / Stylize Animation: StyLit over the scene's frames.

    bpy.ops.tempera.stylize(mode="ANIMATION")   # or mode="FRAME": the current frame

One run has two phases, each a step per frame (tempera.blender.job_operator
runs them: modal with progress and Esc in the UI, all at once in background):

1. guides: the scene's guide cache is brought up to date (frames already
   current are skipped, see guide_operator.GuideJob);
2. stylize: tempera.methods.stylit.stylize.StylizeJob, the native sequence driver, stylizes
   one frame per step in a worker thread (the solver releases the GIL), with
   the previous stylized frame as temporal guide. Frames already stylized
   with the same settings are skipped, so a rerun resumes where a stopped
   run ended; every file is written atomically.

After the last frame of an animation: a contact sheet, an mp4 (when ffmpeg
is present) and the result loaded back into Blender (Load Result).

Every other method has a module of its own (tempera.blender.methods.NAME)
and makes its run there (run(scene, frames, mode); None: per-frame StyLit,
as the coherent method and the rigid bodies answer for Stylize Frame).
StylizeRun is also the base of the coherent method's run and of MethodRun
below (a registry method's job, a frame per step: the rigid bodies), and
RgbaRun of the runs that make RGBA frames from a medium. A run whose
over_render is true (RGBA frames) is also shown over the render, in a
composite scene.
"""
import os
import time

import bpy
from bpy.types import Operator
from bpy.props import EnumProperty, StringProperty

from ..app import settings as limits
from .guide_operator import (ETA_AFTER_FRAMES, GuideJob, estimate_guide_seconds, format_duration, guide_frames,
                             long_run_question)
from .guide_render import GuideRenderError
from .job_operator import JobOperator
from .noise_pass import NoisePass
from .properties import MEDIA_EXEMPLAR_KINDS, WEIGHT_PROPERTIES
from .setting_paths import FRAMES_DIR, exemplar_paths, output_dir, resolve_path
from . import methods, results

# Rough stylizing cost per megapixel on a 2-core machine (docs/benchmarks.md).
STYLIZE_SECONDS_PER_MPIX = {"final": 40.0, "preview": 8.0}
CONTACT_SHEET = "contact_sheet.png"
VIDEO = "stylized.mp4"


# --------------------------------------------------------------------------- settings -> job

def stylize_options(settings):
    """The StylizeJob options of Scene.tempera (everything but paths and frames)."""
    return {
        "weights": {guide: float(getattr(settings, prop)) for guide, prop in WEIGHT_PROPERTIES.items()},
        "temporal_weight": float(settings.temporal_weight),
        "warm_start": settings.warm_start,
        "quality": settings.quality,
        "usage": settings.usage,
        "patch_size": limits.odd_patch_size(settings.patch_size),
        "seed": int(settings.seed),
        "format": settings.output_format,
    }


def megapixels(scene):
    """The render's size in megapixels (at its resolution percentage)."""
    r = scene.render
    return r.resolution_x * r.resolution_y * (r.resolution_percentage / 100.0) ** 2 / 1e6


def require_consecutive(frames, method):
    """ValueError unless `frames` follow each other (a method that carries
    each frame on to the next)."""
    if any(b != a + 1 for a, b in zip(frames, frames[1:])):
        raise ValueError(f"{method} needs consecutive frames: set the scene's Frame Step to 1.")


class StylizeRun:
    """The steps of one Stylize run: guides of every frame, then StyLit per frame."""

    over_render = False  # True: RGBA frames, shown over the render in a composite scene

    def __init__(self, scene, frames, mode="ANIMATION"):
        settings = scene.tempera
        self.mode = mode
        self.frames = list(frames)
        self.out = output_dir(settings)
        self.result_dir = self.out  # where the contact sheet and the mp4 go
        style, exemplar_guides, exemplar_frame = exemplar_paths(settings)
        self.guides = GuideJob.from_settings(scene, self.frames)
        self.config = dict(stylize_options(settings), style=style, exemplar_guides=exemplar_guides,
                           guides=self.guides.folder, frames=self.frames,
                           out=os.path.join(self.out, FRAMES_DIR))
        if exemplar_frame is not None:
            self.config["exemplar_frame"] = exemplar_frame
        self.noise = NoisePass.from_settings(settings, self.out, self.config)  # None: no Temporal Noise pass
        self.job = None  # the native StylizeJob, made once the guides exist
        self.index = 0
        self.results = []
        self.stylize_seconds = 0.0
        self.warnings = []

    @classmethod
    def from_settings(cls, scene, mode="ANIMATION"):
        frames = [scene.frame_current] if mode == "FRAME" else guide_frames(scene, scene.tempera)
        side = methods.side(scene.tempera.method)  # a method with its own module (tempera.blender.methods)
        run = side.run(scene, frames, mode) if side is not None else None
        return run if run is not None else cls(scene, frames, mode)

    @property
    def stylize_steps(self):
        return len(self.frames)  # one per frame; CoherentRun: one per segment

    @property
    def total(self):
        return len(self.frames) + self.stylize_steps + (len(self.frames) if self.noise else 0)

    @property
    def finished(self):
        return self.index >= self.total

    @property
    def in_guide_phase(self):
        return self.index < len(self.frames)

    @property
    def in_noise_phase(self):
        return self.index >= len(self.frames) + self.stylize_steps

    @property
    def noise_results(self):
        return self.noise.results if self.noise else []

    def threaded(self):
        return not self.in_guide_phase  # the solver needs no bpy

    def step(self, progress=None):
        if self.in_guide_phase:
            self.guides.step(progress)
        elif self.in_noise_phase:
            self.noise.step(self.index - len(self.frames) - self.stylize_steps, progress)
        else:
            self._stylize(progress)
        self.index += 1

    def _stylize(self, progress):
        from ..methods.stylit.stylize import StylizeJob

        if self.job is None:
            self.job = StylizeJob(**self.config)
            self.warnings = list(self.job.warnings)
            for warning in self.warnings:
                print(f"Tempera: {warning}", flush=True)
        started = time.monotonic()
        result = self.job.run_frame(self.index - len(self.frames), progress)
        seconds = time.monotonic() - started
        if result["status"] == "stylized":
            self.stylize_seconds += seconds
        self.results.append(result)
        if bpy.app.background:  # the console is the only progress display
            flicker = result.get("flicker")
            note = f", flicker {flicker:.3f}" if flicker is not None and flicker == flicker else ""
            print(f"Tempera: frame {result['frame']} {result['status']} in {seconds:.1f} s{note}", flush=True)

    def current_frame(self):
        index = min(self.index, self.total - 1)
        if self.in_noise_phase:
            index -= len(self.frames) + self.stylize_steps
        return self.frames[index % len(self.frames)]

    def failure(self, exc):
        what = "Guides" if self.in_guide_phase else "Temporal Noise" if self.in_noise_phase else "Stylizing"
        return f"{what} of frame {self.current_frame()} failed: {exc}"

    def eta_seconds(self):
        """Time left stylizing, once it means something: two frames actually
        stylized (the first also reads the painting and guides) and more to do."""
        stylized = [r for r in self.results if r["status"] != "skipped"]
        left = len(self.frames) - len(self.results)
        if len(stylized) < ETA_AFTER_FRAMES or left <= 0:
            return None
        return self.stylize_seconds / len(stylized) * left

    def status_text(self):
        if self.in_guide_phase:
            return self.guides.status_text()
        if self.in_noise_phase:
            return self.noise.status_text()
        eta = self.eta_seconds()
        current = min(len(self.results) + 1, len(self.frames))
        eta_text = "" if eta is None else f", ETA {format_duration(eta)}"
        return f"Tempera: stylizing frame {current}/{len(self.frames)}{eta_text} (Esc to stop)"

    def estimate_seconds(self, scene):
        """A rough duration of the whole run from scratch (guides and stylizing)."""
        per_frame = megapixels(scene) * STYLIZE_SECONDS_PER_MPIX.get(self.config["quality"],
                                                                     STYLIZE_SECONDS_PER_MPIX["final"])
        return estimate_guide_seconds(scene, self.guides.params, len(self.frames)) + per_frame * len(self.frames)

    def mean_flicker(self):
        values = [r["flicker"] for r in self.results if r.get("flicker") is not None and r["flicker"] == r["flicker"]]
        return sum(values) / len(values) if values else None

    def summary(self):
        done = [r for r in self.results if r["status"] != "skipped"]  # "stylized"; the noise job's "made"
        parts = [f"{len(done)} stylized"]
        skipped = len(self.results) - len(done)
        if skipped:
            parts.append(f"{skipped} already done")
        left = len(self.frames) - len(self.results)
        if left:
            parts.append(f"{left} not done")
        flicker = self.mean_flicker()
        tail = f". {flicker_text(flicker)}" if flicker is not None else ""
        if self.noise:
            parts.append(self.noise.summary())
        return f"Tempera: {', '.join(parts)} in {self.config['out']}{tail}"


EXEMPLAR_FRAMES_DIR = "exemplar_frames"  # decoded movies and linked sequences, in the Output Folder
RENDER_DIR = "render"  # the render under an RGBA result (tempera.app.beauty), in the method's folder


class MethodRun(StylizeRun):
    """Guides of every frame, then a method's job (its registry entry's job
    factory, tempera.methods.registry.make_job) a frame per step, into
    Output Folder/FOLDER/frames (its contact sheet and mp4 beside them)."""

    folder = None  # the method's registry name, and its folder in the Output Folder
    method_label = None  # the method's name in messages

    def __init__(self, scene, frames, mode, exemplar, options, format):
        """EXEMPLAR and OPTIONS (by command-line flag) as make_job takes them."""
        self.mode = mode
        self.frames = list(frames)
        self.out = output_dir(scene.tempera)
        self.method_out = self.result_dir = os.path.join(self.out, self.folder)
        self.exemplar = exemplar
        self.guides = GuideJob.from_settings(scene, self.frames)
        self.config = {"out": os.path.join(self.method_out, FRAMES_DIR), "format": format,
                       "quality": "final"}  # the one layout: make_job writes the frames to OUT/frames
        self.options = options
        self.noise = None
        self.job = None  # the method's job, made once the guides exist
        self.index = 0
        self.results = []
        self.stylize_seconds = 0.0
        self.warnings = []

    @property
    def in_noise_phase(self):
        return False  # no Temporal Noise after a method of the registry

    def _stylize(self, progress):
        if self.job is None:
            self.job = self.make_method_job()
            self.warnings = list(self.job.warnings)
            for warning in self.warnings:
                print(f"Tempera: {warning}", flush=True)
        i = self.index - len(self.frames)
        result = self.job.run_frame(i, progress)
        if result["status"] != "skipped":
            self.stylize_seconds += result["seconds"]
        self.results.append(result)
        if bpy.app.background:
            print(f"Tempera: {self.method_label} frame {self.frames[i]} {result['status']} "
                  f"in {result['seconds']:.1f} s", flush=True)

    def summary(self):
        said = self.job.summary if self.job is not None else ""  # the method's own ("flow from fluid_velocity")
        return super().summary() + (f"; {said}" if said else "")

    def make_method_job(self):
        from ..methods import registry

        return registry.make_job(self.folder, self.exemplar, self.guides.folder, self.frames, self.method_out,
                                 format=self.config["format"], options=self.options)

    def render_paths(self):
        """The render frames under an RGBA result (made from the guide cache when stale)."""
        from ..app.beauty import write_render_frames

        return write_render_frames(self.guides.folder, self.frames, os.path.join(self.method_out, RENDER_DIR))


class RgbaRun(MethodRun):
    """A method's run that makes RGBA frames from a medium: the frames go
    over the render (tempera.app.beauty) in a composite scene."""

    seconds_per_mpix = None  # a frame's rough cost, for the confirmation of long runs
    kinds = ("STILL", "SEQUENCE", "MOVIE")  # the exemplars the method takes
    over_render = True

    def __init__(self, scene, frames, mode="ANIMATION"):
        from ..app.media_source import exemplar_source

        settings = scene.tempera
        frames = list(frames)
        out = output_dir(settings)
        if settings.media_exemplar.strip():
            label = next(n for k, n, _ in MEDIA_EXEMPLAR_KINDS if k == settings.media_exemplar_kind)
            if settings.media_exemplar_kind not in self.kinds:
                raise ValueError(f"The {self.method_label} method needs a video exemplar: set Exemplar to Image "
                                 f"Sequence or Movie (not {label}).")
            cache = os.path.join(out, EXEMPLAR_FRAMES_DIR)
            exemplar = exemplar_source(settings.media_exemplar_kind,
                                       resolve_path(settings.media_exemplar, f"exemplar {label}"), cache)
        else:  # the project's own (its registry entry's default_exemplar), written once beside the frames
            from ..app.exemplar_cli import generated_folder
            from ..methods import registry

            kind = registry.find(self.folder)["default_exemplar"]
            exemplar = str(generated_folder(os.path.join(out, self.folder), kind))
        require_consecutive(frames, f"The {self.method_label} method")
        options = {"seed": int(settings.seed), **self.job_options(settings)}
        super().__init__(scene, frames, mode, exemplar, options, settings.output_format)

    def estimate_seconds(self, scene):
        return (estimate_guide_seconds(scene, self.guides.params, len(self.frames))
                + megapixels(scene) * self.seconds_per_mpix * len(self.frames))


def flicker_text(flicker):
    """The flicker figure, said so that an artist can read it."""
    verdict = "steady" if flicker < 0.02 else "some flicker" if flicker < 0.05 else "strong flicker"
    return (f"Flicker {flicker:.3f} ({verdict}: the mean colour change between frames along the motion; "
            "below 0.02 looks steady, raise Temporal Coherence to lower it)")


# --------------------------------------------------------------------------- operator

class TEMPERA_OT_stylize(JobOperator, Operator):
    """Stylize the scene with the exemplar: renders missing guides, then paints every frame
    (frames already done with the same settings are skipped; Esc stops)"""

    bl_idname = "tempera.stylize"
    bl_label = "Stylize"
    bl_options = {"REGISTER"}

    mode: EnumProperty(
        name="Frames",
        items=(("FRAME", "Current Frame", "Stylize the current frame"),
               ("ANIMATION", "Animation", "Stylize the frame range of the Frames setting")),
        default="ANIMATION",
    )

    job_errors = (ValueError, OSError, GuideRenderError)
    question: StringProperty(options={"SKIP_SAVE", "HIDDEN"})  # the confirmation of a long run

    @classmethod
    def description(cls, _context, properties):
        if properties.mode == "FRAME":
            return "Stylize the current frame with the exemplar (renders its guides first if needed)"
        return ("Stylize the frame range with the exemplar: renders missing guides, then paints every frame "
                "(frames already done with the same settings are skipped; Esc stops)")

    def make_job(self, context):
        return StylizeRun.from_settings(context.scene, self.mode)

    def confirmation(self, job):
        if job.mode != "ANIMATION":
            return None
        return long_run_question(len(job.frames), job.estimate_seconds(bpy.data.scenes[job.guides.scene_name]),
                                 "stylize")

    def job_finished(self, context, job):
        scene = context.scene
        settings = scene.tempera
        # With Temporal Noise the noisy frames are the result shown.
        paths = [r["path"] for r in (job.noise_results if job.noise else job.results)]
        results.reload_images_under(job.out)  # images already open show this run's pixels
        shown = []
        if job.mode == "ANIMATION" and hasattr(job.job, "write_contact_sheet"):  # StyLit's frames
            sheet = os.path.join(job.result_dir, CONTACT_SHEET)
            job.job.write_contact_sheet(sheet)
            shown.append(f"contact sheet {sheet}")
            if settings.make_video:
                video = self._encode_video(scene, job)
                if video:
                    shown.append(f"video {video}")
        how = settings.load_result if job.mode == "ANIMATION" else "IMAGE"
        if job.over_render and paths and how != "NONE":  # over the render, whatever is shown
            composite = results.load_composite_scene(scene, job.render_paths(), paths, job.frames)
            loaded = composite if how == "SEQUENCER" else results.load(scene, paths, job.frames, how)
        else:
            loaded = results.load(scene, paths, job.frames, how)
        where = results.show(context, loaded, how)
        if where:
            shown.insert(0, where)
        for warning in job.warnings:
            self.report({"WARNING"}, warning)
        if shown:
            self.report({"INFO"}, "Tempera: " + "; ".join(shown))

    def _encode_video(self, scene, job):
        """Encodes the mp4; its path, or None (reported why)."""
        from ..app.video import encode_video

        if job.config["format"] != "png":
            self.report({"INFO"}, "No mp4: the video is made from PNG frames (Format is OpenEXR)")
            return None
        # A '%' in the folder would be read by ffmpeg as a number of its own.
        pattern = os.path.join(job.config["out"].replace("%", "%%"), "frame_%04d.png")
        fps = scene.render.fps / scene.render.fps_base
        video = os.path.join(job.result_dir, VIDEO)
        if not encode_video(pattern, job.frames[0], video, fps):
            self.report({"WARNING"}, "ffmpeg not found: no mp4 written (the frames are there)")
            return None
        return video
