"""Stroke re-synthesis of the rigid-body method (Dvorožňák et al. 2017, §6
(iv), optional in the paper): the drawn bodies' lines re-made by the
synthesis engine from a stroke exemplar, guided by one grayscale
stroke-position guide G = 1 - distance-to-ink / d_max. The method lives in
native/src/methods/rigid/stroke_resynthesis.cpp (where the rigid-body job
calls it too); these are its Python names.

The exemplar is an RGBA image of strokes on transparent paper (a brush pen,
charcoal...); ``generated_stroke_exemplar`` is the project's own (a blue
brush pen with a dry-brush grain), for the tests, the demo and users without
a scan.
"""
from __future__ import annotations

import numpy as np

from ... import _native

STROKE_COLOUR = _native.GENERATED_STROKE_COLOUR  # the generated exemplar's blue-black brush pen
GENERATED = "generated"  # the stroke exemplar named so is generated_stroke_exemplar()


def stroke_guide(rgba, d_max):
    """G of an RGBA drawing: 1 on its ink (alpha > 0.5), falling to 0 at
    d_max px from it; (H, W) float32."""
    return _native.stroke_guide(np.ascontiguousarray(rgba, np.float32), float(d_max))[:, :, 0]


def segment_distance(xs, ys, a, b):
    """Distance of the pixel grid (xs, ys) to the segment a-b (px)."""
    d = b - a
    t = np.clip(((xs - a[0]) * d[0] + (ys - a[1]) * d[1]) / max(float(d @ d), 1e-9), 0, 1)
    return np.hypot(xs - (a[0] + t * d[0]), ys - (a[1] + t * d[1]))


def generated_stroke_exemplar(size=160, width=4.0, seed=0):
    """The project's stroke exemplar: arcs and loops of a blue-black brush
    pen `width` px wide, its pressure swelling along each stroke, with a
    dry-brush grain in the ink (RGBA, straight alpha, transparent paper)."""
    return _native.generated_stroke_exemplar(int(size), float(width), int(seed))


def resynthesize(rgba, exemplar, d_max=4.0, weight=4.0, seed=1, progress=None):
    """The drawing `rgba` (straight alpha) with its strokes re-made from the
    stroke `exemplar` by the engine on the stroke-position guide; weight 0 =
    the exemplar's texture with no guide. Only the box around the ink (with
    a margin of d_max and a patch) is synthesized; the rest stays blank.
    progress(fraction) returning False cancels (tempera.Cancelled)."""
    return _native.resynthesize_strokes(np.ascontiguousarray(rgba, np.float32),
                                        np.ascontiguousarray(exemplar, np.float32), float(d_max), float(weight),
                                        int(seed), progress)


def load_stroke_exemplar(spec):
    """The stroke exemplar `spec` names: GENERATED, or an image file (an image
    without alpha is read as dark ink on white paper, alpha = 1 - luminance)."""
    return _native.load_stroke_exemplar(str(spec))


def restyle(rgba, exemplar, values, progress=None):
    """resynthesize() with the stroke options of the RigidOptions keywords
    `values`; progress(fraction) returning False cancels (tempera.Cancelled)."""
    from .rigid import RigidOptions

    o = RigidOptions(**values)
    return resynthesize(rgba, exemplar, d_max=o.stroke_d_max, weight=o.stroke_weight, progress=progress)
