"""Fluidymation (Platkevič et al. 2021): moving shapes painted with the
motion of a natural medium (ink, watercolour) from a video exemplar with its
masks (native/src/methods/fluidymation/fluidymation.cpp, docs/fluidymation.md).

`MediaJob` runs the method over a guide cache as `tempera stylize --method
fluidymation` does (native/src/methods/fluidymation/fluidymation_job.cpp): frame by frame, each
from the previous frame's matches, resumable per frame.
"""
from __future__ import annotations

import numpy as np

from ... import _native
from ...app.frame_job import SheetFrameJob
from ...engine.synthesis import method_options

FluidymationOptions = _native.FluidymationOptions
FLOW_SOURCES = ("auto", "fluid", "guides", "masks")


def options(**values) -> "FluidymationOptions":
    """FluidymationOptions from keywords: its own (boundary_weight,
    shape_blur, extent_weight, direction_weight, temporal_weight,
    uniformity_weight, ..., see FluidymationOptions.table()) and engine
    options (SynthesisOptions names, from the method's defaults: 5 x 5
    patches, directed orientations, exact guides)."""
    opts = method_options(FluidymationOptions, _native.fluidymation_defaults(), values, "fluidymation")
    opts.validate()
    return opts


def _image(a, channels=None, what="image"):
    a = np.ascontiguousarray(a, dtype=np.float32)
    a = a[:, :, None] if a.ndim == 2 else a
    if a.ndim != 3 or (channels is not None and a.shape[2] != channels):
        raise ValueError(f"{what} must be (H, W{'' if channels == 1 else f', {channels}'}), got {a.shape}")
    return a


def _masks(masks, what):
    return [_image(m, 1, f"{what} {i}") for i, m in enumerate(masks)]


def _flows(flows, what):
    return [_image(f, 2, f"{what} {i}") for i, f in enumerate(flows)]


def flow_from_masks(masks, temporal_radius: float = 3.0) -> list:
    """(H, W, 2) flows of a mask sequence (App. A): pixels per frame, x right,
    y down, forward (p moves to p + F next frame), 0 outside each mask."""
    return _native.flow_from_masks(_masks(masks, "mask"), float(temporal_radius))


def motion_extent(flows, masks) -> tuple:
    """(ext+, ext-): per frame the (H, W, 1) motion accumulated since the
    material appeared and until it goes, zeroed outside each mask (§3.3)."""
    return _native.motion_extent(_flows(flows, "flow"), _masks(masks, "mask"))


def stylize_sequence(exemplar_frames, exemplar_masks, target_masks, target_flows=None, *, progress=None, **values):
    """The target's frames painted by the exemplar video.

    exemplar_frames  S_rgb, (h, w, C) per frame (e.g. RGB or RGBA)
    exemplar_masks   S_mask, (h, w) per frame, > 0.5 = paint (its flow is made from them)
    target_masks     T_mask, (H, W) per frame
    target_flows     optional (H, W, 2) per frame (forward, pixels); None = from the masks
    progress         progress(fraction) -> False cancels (tempera.Cancelled)
    **values         tempera.methods.fluidymation.fluidymation.options

    Returns per frame dict(image (H, W, C), nnf (H, W, 4): exemplar frame,
    x, y, rotation; frame -1 outside the mask, time_shift (H, W, 1): the
    SHIFTNNF delta i, energy)."""
    flows = None if target_flows is None else _flows(target_flows, "target flow")
    report = None if progress is None else (lambda x: progress(x) is not False)
    return _native.stylize_fluid_sequence([_image(f, what="exemplar frame") for f in exemplar_frames],
                                          _masks(exemplar_masks, "exemplar mask"), _masks(target_masks, "target mask"),
                                          flows, options(**values), report)


class MediaJob(SheetFrameJob):
    """Fluidymation over a guide cache, frame by frame.

    exemplar        folder of the exemplar's frames (RGBA, or RGB with exemplar_masks)
    guides          guide cache folder of the animation
    frames          consecutive frame numbers
    out             output folder: frame_0001.png ... (RGBA, alpha = the target mask)
    exemplar_masks  folder of the exemplar's mask frames (first channel > 0.5)
    target_mask     "alpha" or a mask guide "mask.OB_<object>" / "mask.CO_<collection>"
    flow            None or "auto" (the cache's fluid_velocity, else its velocity_forward, else the
                    masks), "fluid" (fluid_velocity), "guides" (velocity_forward) or "masks"
    format          "png" or "exr"
    resume          skip frames whose output and record are current
    **values        tempera.methods.fluidymation.fluidymation.options (bidirectional=True solves the shot both ways)

    Construction reads and checks every input (FileNotFoundError, ValueError).
    """

    def __init__(self, exemplar, guides, frames, out, *, exemplar_masks=None, target_mask="alpha", flow=None,
                 format="png", resume=True, **values):
        if flow is not None and flow not in FLOW_SOURCES:
            raise ValueError(f"flow must be None or one of {', '.join(FLOW_SOURCES)}, got {flow!r}")
        config = _native.FluidymationJobConfig(exemplar=exemplar, guides=guides, frames=[int(f) for f in frames],
                                               out=out, exemplar_masks=exemplar_masks or "", target_mask=target_mask,
                                               flow=flow or "auto", format=format, resume=resume)
        self._job = _native.FluidymationJob(config, options(**values))

    @property
    def flow_guide(self):
        """The guide the target's flow is read from ("fluid_velocity" or
        "velocity_forward"), or None when it is made from the masks."""
        return self._job.flow_guide or None
