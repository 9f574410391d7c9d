"""Stylizing Animation by Example (Bénard et al. 2013): a whole shot at once,
coarse to fine with forward and backward sweeps along the rendered motion, so
the paint stays on the surfaces (native/src/tcia.cpp, docs/engine.md).

Painted keyframes are hard constraints and extra exemplars; lines, ribbons
and layers are still to come (issue 12).
"""
from __future__ import annotations

import numpy as np

from . import _native
from .synthesis import method_options

TciaOptions = _native.TciaOptions


def options(**values) -> "TciaOptions":
    """TciaOptions from keywords: its own (temporal_weight, coherence_weight,
    coherence_max, sweep_pairs) and engine options (SynthesisOptions names,
    from the method's defaults: 9 x 9 Gaussian window, centre output,
    histogram usage, 4 levels)."""
    return method_options(TciaOptions, _native.tcia_defaults(), values, "coherent-method")


def _image(a):
    a = np.ascontiguousarray(a, dtype=np.float32)
    return a[:, :, None] if a.ndim == 2 else a


def stylize_shot(style, guides, frames, *, keys=(), progress=None, **values):
    """The stylized frames of a shot.

    style   the painting Ŝ, (H, W, C)
    guides  [(name, exemplar guide S (H, W, c), weight), ...]
    frames  per frame a dict: guides (the frame's B_g in the same order),
            velocity_backward, velocity_forward ((h, w, 2), pixels, x right,
            y down), occlusion_backward, occlusion_forward ((h, w) χ−, χ+)
    keys    painted keyframes [(frame index, painting (h, w, C)[, mask (h, w)]), ...]
            in frame order: each comes out as painted and steers its neighbours
    """
    g = [(str(n), _image(s), float(w)) for n, s, w in guides]
    f = [{k: ([_image(x) for x in v] if k == "guides" else _image(v)) for k, v in d.items()} for d in frames]
    k = [(int(key[0]), _image(key[1]), None if len(key) < 3 or key[2] is None else _image(key[2])) for key in keys]
    report = None if progress is None else (lambda x: progress(x) is not False)
    return _native.stylize_shot(_image(style), g, f, k, options(**values), report)
