"""Render Guides: the operator behind the Guides box of the Output panel.

    bpy.ops.tempera.render_guides()

renders the guide cache (tempera.app.guide_cache) of the scene's frames as set in
Scene.tempera (folder, frame range, parameters). In the UI it is modal: a
window-manager timer renders one frame per step, with a progress cursor and
"Tempera: guides frame i/N, ETA ..." in the status bar; Esc stops after the
frame being rendered (finished frames stay in the cache). In background mode
(blender -b), where timers do not run, execute() renders every frame in one
go. Both go through GuideJob.step(), which renders one frame with
render_guide_frame(); frames already current in the cache are skipped by
render_guides itself.
"""
import functools
import json
import os
import time

import bpy
from bpy.props import StringProperty
from bpy.types import Operator

from ..app import guide_cache
from .guide_render import (LPE_PROBLEMS, GuideRenderError, check_lpe_expressions, check_scene, render_guides,
                           scene_fingerprint)
from .job_operator import JobOperator
from .properties import GUIDE_MASK_MODES


# --------------------------------------------------------------------------- settings -> job

def guide_params(settings):
    """The render_guides parameters of Scene.tempera: DEFAULT_PARAMS with the
    settings the panel shows (one Samples for both renders)."""
    return {
        **guide_cache.DEFAULT_PARAMS,
        "samples": settings.guide_samples,
        "ld12e_samples": settings.guide_samples,
        "occlusion_epsilon": float(settings.guide_occlusion_epsilon),
        "line_d_max": float(settings.guide_line_d_max),
        "masks": GUIDE_MASK_MODES[settings.guide_masks],
        "orientation_aov": settings.guide_orientation_aov.strip(),
        "lpe": guide_cache.split_expressions(settings.guide_lpe),
        "lpe_samples": settings.guide_lpe_samples,
    }


def guide_frames(scene, settings):
    """The frames to render, in order, for the Frames setting."""
    mode = settings.guide_frame_range
    if mode == "CURRENT":
        return [scene.frame_current]
    if mode == "SCENE":
        first, last = scene.frame_start, scene.frame_end
    else:
        first, last = settings.guide_frame_start, settings.guide_frame_end
    if last < first:
        raise ValueError(f"The guide frame range {first}-{last} is empty: End is before Start.")
    return list(range(first, last + 1))


def resolve_guide_dir(path_setting, blend_filepath=None):
    """Absolute guide folder of the Guide Folder setting. '//' is relative to
    the .blend file; an unsaved file has none, so that is refused."""
    blend_filepath = bpy.data.filepath if blend_filepath is None else blend_filepath
    path = path_setting.strip()
    if not path:
        raise ValueError("Set a Guide Folder in Output Properties > Tempera > Guides.")
    if path.startswith("//"):
        if not blend_filepath:
            raise ValueError(f"Save the .blend file first: the Guide Folder '{path_setting}' is relative to it "
                             "('//'). Or choose an absolute folder.")
        path = bpy.path.abspath(path, start=os.path.dirname(blend_filepath))
    return os.path.normpath(path)


def render_guide_frame(scene, frame, folder, params, progress=None):
    """Renders (or skips, if current) the guides of one frame: the single
    step of both the modal and the background run."""
    return render_guides(scene, [frame], folder, params, progress)


# A run asks before it starts when it is longer than this (UI only).
CONFIRM_FRAMES = 50
CONFIRM_SECONDS = 600.0
# Rough costs on a 2-core machine (docs/benchmarks.md), per megapixel.
CYCLES_SECONDS_PER_MPIX_SAMPLE = 0.06  # each of the two guide renders
TRACER_SECONDS_PER_MPIX_SAMPLE = 0.03  # each light path expression


def estimate_guide_seconds(scene, params, frames):
    """A rough duration of rendering `frames` guide frames from scratch."""
    r = scene.render
    mpix = r.resolution_x * r.resolution_y * (r.resolution_percentage / 100.0) ** 2 / 1e6
    per_frame = mpix * CYCLES_SECONDS_PER_MPIX_SAMPLE * (params["samples"] + params["ld12e_samples"])
    per_frame += mpix * TRACER_SECONDS_PER_MPIX_SAMPLE * params["lpe_samples"] * len(params["lpe"])
    return per_frame * frames


def long_run_question(frames, seconds, what):
    """The confirmation text of a run of `frames` frames taking about
    `seconds` (frames already current are skipped, so it may be shorter), or
    None if the run is short enough to start at once."""
    if frames <= CONFIRM_FRAMES and seconds <= CONFIRM_SECONDS:
        return None
    return (f"This will {what} {frames} frames, {rough_duration(seconds)} on a 2-core machine.\n"
            "Frames already done are skipped; Esc stops after the frame at hand.\nStart?")


def rough_duration(seconds):
    """'about 40 seconds', 'about 12 minutes', 'about 3 hours 5 minutes'."""
    if seconds < 90:
        return f"about {max(1, round(seconds))} seconds"
    if seconds < 2 * 3600:
        return f"about {round(seconds / 60)} minutes"
    hours, minutes = divmod(round(seconds / 60), 60)
    return f"about {hours} hours {minutes} minutes"


def format_duration(seconds):
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


ETA_AFTER_FRAMES = 2  # frames actually computed before an ETA is shown


class GuideJob:
    """The frames of one Render Guides run, rendered one step at a time."""

    def __init__(self, scene, frames, folder, params):
        self.scene_name = scene.name
        self.frames = list(frames)
        self.folder = folder
        self.params = params
        self.index = 0  # frames done (rendered or skipped)
        self.rendered, self.skipped = [], []
        self.render_seconds = 0.0  # time spent on rendered frames (skipped ones take none)
        self.warnings = []  # what the light-path tracer approximated, once each

    @classmethod
    def from_settings(cls, scene, frames=None):
        """The job Scene.tempera describes (for `frames`, default its Frames
        setting). Raises ValueError or GuideRenderError (with what to
        change) before anything is rendered."""
        settings = scene.tempera
        folder = resolve_guide_dir(settings.guide_dir)
        frames = guide_frames(scene, settings) if frames is None else list(frames)
        check_scene(scene)
        params = guide_params(settings)
        check_lpe_expressions(params["lpe"])
        return cls(scene, frames, folder, params)

    @property
    def total(self):
        return len(self.frames)

    @property
    def finished(self):
        return self.index >= self.total

    def threaded(self):
        return False  # rendering needs bpy: the main thread

    def failure(self, exc):
        return f"Guides of frame {self.frames[self.index]} failed: {exc}"

    def scene(self):
        scene = bpy.data.scenes.get(self.scene_name)
        if scene is None:
            raise GuideRenderError(f"Scene '{self.scene_name}' no longer exists.")
        return scene

    def step(self, progress=None):
        """Renders the next frame; `progress(fraction)` follows it within the frame."""
        frame = self.frames[self.index]

        def frame_progress(done, total, _message):
            if progress:
                progress(done / max(total, 1))

        start = time.monotonic()
        report = render_guide_frame(self.scene(), frame, self.folder, self.params, frame_progress)
        self.warnings += [w for w in report["warnings"] if w not in self.warnings]
        if report["rendered"]:
            self.rendered.append(frame)
            self.render_seconds += time.monotonic() - start
        else:
            self.skipped.append(frame)
        self.index += 1
        return report

    def eta_seconds(self):
        """Time left if the remaining frames take as long as the rendered
        ones; None until it means something: two frames rendered (the first
        one also pays Cycles' start-up) and at least one still to do."""
        if len(self.rendered) < ETA_AFTER_FRAMES or self.index >= self.total:
            return None
        return self.render_seconds / len(self.rendered) * (self.total - self.index)

    def status_text(self):
        eta = self.eta_seconds()
        eta_text = "" if eta is None else f", ETA {format_duration(eta)}"
        current = min(self.index + 1, self.total)
        return f"Tempera: guides frame {current}/{self.total}{eta_text} (Esc to stop)"

    def summary(self):
        parts = [f"{len(self.rendered)} rendered"]
        if self.skipped:
            parts.append(f"{len(self.skipped)} already current")
        left = self.total - self.index
        if left:
            parts.append(f"{left} not done")
        return f"Tempera guides: {', '.join(parts)} in {self.folder}"


# --------------------------------------------------------------------------- panel status

@functools.lru_cache(maxsize=16)
def _current_frames(folder, manifest_mtime_ns, params_json, fingerprint_json, frames):
    manifest = guide_cache.read_manifest(folder, set_aside=False)  # draw() moves no files
    if not manifest:
        return 0
    params = json.loads(params_json)
    fingerprint = json.loads(fingerprint_json)
    current = 0
    for frame in frames:
        fingerprint["frame"] = frame
        key = guide_cache.frame_key(params, fingerprint)
        if guide_cache.is_frame_current(folder, manifest, frame, key, verify=False):  # size only: draw() is no place to hash files
            current += 1
    return current


def cache_status(scene):
    """(text, icon) for the panel: how many frames of the range are in the
    cache and current. Reads the manifest only (cached per manifest version
    and scene state); never renders, never compiles an expression (a problem
    found by the field's update callback is shown)."""
    settings = scene.tempera
    try:
        problem = LPE_PROBLEMS.get(settings.guide_lpe)
        if problem:
            raise GuideRenderError(problem)
        folder = resolve_guide_dir(settings.guide_dir)
        frames = guide_frames(scene, settings)
        check_scene(scene)
    except (ValueError, GuideRenderError) as exc:
        return str(exc), "ERROR"
    try:
        mtime = os.stat(os.path.join(folder, guide_cache.MANIFEST_NAME)).st_mtime_ns
    except OSError:
        return f"No guides cached yet ({len(frames)} frames to render)", "INFO"
    # A frame's fingerprint differs from the first one's only by its number
    # (checked by blender_tests/test_operator.py), so it is taken once.
    fingerprint = json.dumps(scene_fingerprint(scene, frames[0]), sort_keys=True, default=str)
    params = json.dumps(guide_params(settings), sort_keys=True)
    current = _current_frames(folder, mtime, params, fingerprint, tuple(frames))
    icon = "CHECKMARK" if current == len(frames) else "INFO"
    return f"{current}/{len(frames)} frames cached and current", icon


# --------------------------------------------------------------------------- operator

class TEMPERA_OT_render_guides(JobOperator, Operator):
    """Render the guide passes of the frames set in the Guides box into the guide cache
    (frames already cached and current are skipped; Esc stops after the current frame)"""

    bl_idname = "tempera.render_guides"
    bl_label = "Render Guides"
    bl_options = {"REGISTER"}

    job_errors = (ValueError, GuideRenderError)
    question: StringProperty(options={"SKIP_SAVE", "HIDDEN"})  # the confirmation of a long run

    def make_job(self, context):
        return GuideJob.from_settings(context.scene)

    def confirmation(self, job):
        return long_run_question(len(job.frames), estimate_guide_seconds(job.scene(), job.params, len(job.frames)),
                                 "render the guides of")

    def job_finished(self, context, job):
        for warning in job.warnings:  # approximations of the light-path tracer, e.g. unsupported nodes
            self.report({"WARNING"}, warning)
