"""LazyFluids (Jamriška et al. 2015; thesis ch. 5): an RGBA exemplar of a
fluid element carried along a target flow inside a target alpha mask, frame
after frame, with strict uniform patch usage per boundary / interior segment
so that the texture never washes out (native/src/methods/lazyfluids/lazyfluids.cpp,
docs/lazyfluids.md).

`FluidJob` runs the method over a guide cache as `tempera stylize --method
lazyfluids` does (native/src/methods/lazyfluids/lazyfluids_job.cpp): target alpha = the cache's
``alpha``, flow = ``fluid_velocity`` (else ``velocity_forward``, else zero,
with a warning), one resumable frame at a time.
"""
from __future__ import annotations


import numpy as np

from ... import _native
from ...app.frame_job import SheetFrameJob
from ...engine.synthesis import method_options

LazyFluidsOptions = _native.LazyFluidsOptions


def options(**values) -> "LazyFluidsOptions":
    """LazyFluidsOptions from keywords: its own (temporal_weight λ,
    alpha_guide_weight η, alpha_weight, alpha_radius, alpha_lower,
    alpha_upper, rotations, motion_blur, warm_start) and engine options (SynthesisOptions
    names, from the method's defaults: 5 x 5 patches, uniform usage)."""
    return method_options(LazyFluidsOptions, _native.lazyfluids_defaults(), values, "lazyfluids")


def _image(a, channels=None, what="image"):
    a = np.ascontiguousarray(a, dtype=np.float32)
    a = a[:, :, None] if a.ndim == 2 else a
    if a.ndim != 3 or (channels is not None and a.shape[2] != channels):
        raise ValueError(f"{what} must be (H, W{', ' + str(channels) if channels else ''}), got {a.shape}")
    return a


def _exemplar_frames(exemplar):
    frames = [exemplar] if isinstance(exemplar, np.ndarray) and exemplar.ndim == 3 else list(exemplar)
    return [_image(z, 4, "exemplar (RGBA)") for z in frames]


def stylize_sequence(exemplar, alphas, flows, *, progress=None, **values) -> list:
    """The stylized RGBA frames (H, W, 4) of a fluid sequence.

    exemplar  (h, w, 4) RGBA, or a list of such frames (a video exemplar,
              looped when shorter than the sequence)
    alphas    per frame the target alpha X_a (H, W) or (H, W, 1)
    flows     per frame the flow F (H, W, 2) in pixels: p moves to p + F in
              the next frame (x right, y down)
    progress  progress(fraction) returning False cancels (tempera.Cancelled)
    **values  options (tempera.methods.lazyfluids.lazyfluids.options)
    """
    a = [_image(x, 1, "target alpha") for x in alphas]
    f = [_image(x, 2, "flow") for x in flows]
    report = None if progress is None else (lambda x: progress(x) is not False)
    return _native.stylize_fluid_sequence(_exemplar_frames(exemplar), a, f, options(**values), report)


def stylize_frame(style, target_alpha, *, previous_style=None, previous=None, flow_previous=None,
                  previous_field=None, progress=None, **values):
    """One frame of a fluid sequence: returns (image (H, W, 4), stats).

    style           Z^t, (h, w, 4) RGBA
    target_alpha    X_a^t, (H, W) or (H, W, 1)
    previous_style  z^{t-1} (default: style)
    previous        the previous frame's output (RGBA, before motion blur),
                    advected along ``flow_previous`` (F^{t-1}) for the
                    temporal term; None on the first frame
    previous_field  the previous frame's ``stats["field"]``: with
                    ``warm_start=True`` the frame starts from it, advected
    **values        options (tempera.methods.lazyfluids.lazyfluids.options)

    stats: seconds, final_energy (the finest level's mean patch distance),
    levels, source_coverage, field (the final matches, H x W x 2)."""
    style = _image(style, 4, "style (RGBA)")
    alpha = _image(target_alpha, 1, "target alpha")
    if (previous is not None or previous_field is not None) and flow_previous is None:
        raise ValueError("previous and previous_field need flow_previous (F^{t-1})")
    flow = None if flow_previous is None else _image(flow_previous, 2, "flow_previous")
    advected = None if previous is None else advect_output(previous, flow)
    # A frame with nothing to synthesize has no matches: the next one starts cold.
    field = None if previous_field is None or np.size(previous_field) == 0 else _image(previous_field, 2,
                                                                                     "previous_field")
    before = style if previous_style is None else _image(previous_style, 4, "previous style (RGBA)")
    report = None if progress is None else (lambda x: progress(x) is not False)
    return _native.stylize_fluid_frame(style, before, alpha, advected, field, flow, options(**values), report)


def advect_output(previous, flow_previous):
    """X̂^{t-1}: the previous output (any channels) at p − F^{t-1}(p), bilinear, 0 outside the frame."""
    return _native.lazyfluids_advect_output(_image(previous), _image(flow_previous, 2, "flow_previous"))


def temporal_weights(target_alpha, advected, lam: float):
    """λ_q = (1 − max(0, X_a − X̂_a)) λ (eq. 5.6), (H, W, 1); `advected` is
    the advected previous output, RGBA (alpha = channel 3) or alpha."""
    return _native.lazyfluids_temporal_weights(_image(target_alpha, 1, "target alpha"), _image(advected), float(lam))


class FluidJob(SheetFrameJob):
    """LazyFluids over a guide cache, frame by frame.

    exemplar  an RGBA image file, or a folder of RGBA frames (a video exemplar)
    guides    guide cache folder (frame_####.exr with ``alpha``, and
              ``fluid_velocity`` or ``velocity_forward``)
    frames    consecutive frame numbers
    out       output folder: OUT/frame_0001.png ... (``format`` png | exr)
    resume    skip frames whose record is current
    **values  the method's and engine options (tempera.methods.lazyfluids.lazyfluids.options)

    Construction checks every file and guide (FileNotFoundError,
    ValueError). Run ``run_frame(i)`` for i in range(len(frames)), in order.
    """

    def __init__(self, exemplar, guides, frames, out, *, format="png", resume=True, **values):
        config = _native.JobConfig(exemplar=exemplar, guides=guides, frames=[int(f) for f in frames], out=out, format=format,
                                   resume=resume)
        self._job = _native.LazyFluidsJob(config, options(**values))
