"""StyLit stylization of animations from guide caches (thesis ch. 8).

``StylizeJob`` drives a whole sequence (what ``tempera stylize`` and the
add-on's operator run); ``stylize_frame`` stylizes one frame from in-memory
guides. Both are thin layers over the native code (native/src/methods/stylit/stylit.cpp,
native/src/methods/stylit/stylize_job.cpp); see docs/cli.md for the job's files and resume.
"""
from __future__ import annotations

from typing import Iterable, Mapping, Optional

import numpy as np

from ... import _native
from ...app.frame_job import ProgressFn, SheetFrameJob
from ...app.settings import DEFAULT_GUIDE_WEIGHTS as DEFAULT_WEIGHTS
from ...app.settings import LIGHT_PATH_GUIDES
from ...engine.synthesis import method_options

GUIDES = tuple(g["name"] for g in LIGHT_PATH_GUIDES)


def options(weights: Optional[Mapping[str, float]] = None, **values) -> "_native.StylitOptions":
    """StylitOptions from keywords: ``weights`` ({guide: weight} overriding
    DEFAULT_WEIGHTS), StyLit's own (temporal_weight, quality) and engine
    options (SynthesisOptions names). None keeps a default; unknown names
    are TypeErrors, bad values ValueErrors naming them."""
    values = {k: v for k, v in values.items() if v is not None}
    opts = method_options(_native.StylitOptions, _native.SynthesisOptions(), values, "stylit")
    if weights is not None:
        opts.weights = {str(k): v for k, v in dict(weights).items()}
    opts.validate()
    return opts


class StylizeJob(SheetFrameJob):
    """Stylization of the frames of a guide cache with one painted exemplar.

    style            the painting (PNG/EXR/...), made on the exemplar render
    exemplar_guides  guide cache folder of the exemplar render
    guides           guide cache folder of the animation
    frames           frame numbers, in order (consecutive frames are chained
                     by the temporal guide and the flicker figure)
    out              output folder; frames are written as out/<prefix>0001.<format>
    exemplar_frame   frame of exemplar_guides to use (default: its only frame)
    weights          {guide: weight} overriding DEFAULT_WEIGHTS (<= 0 leaves a guide out)
    temporal_weight  pull towards the previous stylized frame advected along
                     the motion (0 = frames independent; None = the default,
                     settings.DEFAULT_TEMPORAL_WEIGHT)
    quality          "final" (engine defaults) or "preview" (fast, for interaction)
    warm_start       "auto" (default: with the temporal guide), "on" or "off": frames after the
                     first start from the previous frame's matches (out/tempera_stylize/field_*.exr)
    **engine         engine options (tempera.SynthesisOptions: usage, patch_size, seed, threads, ...)
    resume           skip frames whose output is current (see docs/cli.md)

    Construction checks every file and guide up front (FileNotFoundError,
    ValueError); ``warnings`` lists what was fixed on the way (a resampled
    painting). Call ``run_frame(i)`` for i in range(len(job.frames)).
    """

    def __init__(self, style, exemplar_guides, guides, frames: Iterable[int], out, *, exemplar_frame=None,
                 format="png", prefix="frame_", weights: Optional[Mapping[str, float]] = None,
                 temporal_weight=None, quality=None, resume=True, **engine):
        config = _native.StylizeJobConfig(exemplar=style, exemplar_guides=exemplar_guides, guides=guides,
                                          frames=[int(f) for f in frames], out=out, exemplar_frame=exemplar_frame,
                                          format=format, prefix=prefix, resume=resume)
        self._job = _native.StylizeJob(config, options(weights, temporal_weight=temporal_weight, quality=quality,
                                                       **engine))

    @property
    def report_path(self) -> str:
        """The job's sidecar (out/tempera_stylize.json): settings, key and flicker per frame."""
        return self._job.report_path



def stylize_frame(style, exemplar: Mapping, target: Mapping, *, previous=None, velocity_backward=None,
                  occlusion_backward=None, previous_field=None, weights=None, temporal_weight=None, quality=None,
                  warm_start=None, progress: ProgressFn = None, **engine):
    """One StyLit frame from arrays: ``exemplar`` and ``target`` map guide names
    (FULL, LDE, ...) to linear (H, W, 3) arrays as in a guide cache (they are
    tone-mapped here). Give ``previous`` (the previous stylized frame) with the
    target's ``velocity_backward`` and ``occlusion_backward`` to add the
    temporal guide; when the frame warm-starts (``warm_start`` "on", or "auto"
    with a temporal weight > 0), give the previous frame's
    ``stats["field"]`` as ``previous_field`` (and the motion) to start from its
    matches. Returns (image, stats); stats["field"] holds the final matches
    (H, W, 2 source positions)."""
    temporal = None
    if previous is not None or previous_field is not None:
        if velocity_backward is None or occlusion_backward is None:
            raise ValueError("previous and previous_field need velocity_backward and occlusion_backward")
        temporal = dict(velocity_backward=_float(velocity_backward), occlusion_backward=_float(occlusion_backward))
        if previous is not None:
            temporal["previous"] = _float(previous)
        if previous_field is not None:
            temporal["previous_field"] = _float(previous_field)
    opts = options(weights, temporal_weight=temporal_weight, quality=quality, warm_start=warm_start, **engine)
    return _native.stylize_frame(_float(style), {k: _float(v) for k, v in exemplar.items()},
                                 {k: _float(v) for k, v in target.items()}, opts, temporal, progress)


def _float(array):
    return np.ascontiguousarray(array, dtype=np.float32)
