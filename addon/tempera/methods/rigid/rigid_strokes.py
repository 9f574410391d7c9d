"""Stroke re-synthesis of the rigid-body method (Dvorožňák et al. 2017, §6
(iv), optional in the paper): the drawn bodies' lines re-made by the
synthesis engine from a stroke exemplar, guided by one grayscale
stroke-position guide G = 1 - distance-to-ink / d_max (method notes; the
paper's text is cut off before saying how G is made).

The exemplar is an RGBA image of strokes on transparent paper (a brush pen,
charcoal...); its own G comes from its ink the same way, so the engine puts
the exemplar's stroke cores on the body's lines and its blank paper away
from them: the line keeps its place and takes the exemplar's look.
``generated_stroke_exemplar`` is the project's own (a blue brush pen with a
dry-brush grain), for the tests, the demo and users without a scan.
"""
from __future__ import annotations

import math

import numpy as np

from ... import _native
from ...engine import guides, synthesis

INK = 0.5  # alpha above which a pixel is ink, for the guide
STROKE_COLOUR = (0.12, 0.17, 0.48)  # the generated exemplar's blue-black brush pen
# Engine settings of the re-synthesis. Plain nearest neighbours: a usage
# term would push the exemplar's ink patches into the blank paper (most of a
# frame is blank), which is exactly what the guide must prevent.
ENGINE = {"usage": "none", "patch_size": 5}


def stroke_guide(rgba, d_max):
    """G of an RGBA drawing: 1 on its ink (alpha > 0.5), falling to 0 at
    d_max px from it; (H, W) float32."""
    alpha = np.asarray(rgba, np.float32)[:, :, 3]
    return 1.0 - guides.line_distance(alpha > INK, d_max)


def segment_distance(xs, ys, a, b):
    """Distance of the pixel grid (xs, ys) to the segment a-b (px)."""
    d = b - a
    t = np.clip(((xs - a[0]) * d[0] + (ys - a[1]) * d[1]) / max(float(d @ d), 1e-9), 0, 1)
    return np.hypot(xs - (a[0] + t * d[0]), ys - (a[1] + t * d[1]))


def generated_stroke_exemplar(size=160, width=4.0, seed=0):
    """The project's stroke exemplar: arcs and loops of a blue-black brush
    pen `width` px wide, its pressure swelling along each stroke, with a
    dry-brush grain in the ink (RGBA, straight alpha, transparent paper)."""
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:size, 0:size].astype(np.float32)
    alpha = np.zeros((size, size), np.float32)
    for _ in range(7):
        centre = rng.uniform(0.25, 0.75, 2) * size
        radius = rng.uniform(0.12, 0.3) * size
        start, sweep = rng.uniform(0, 2 * math.pi), rng.uniform(1.2, 2 * math.pi)
        t = np.linspace(start, start + sweep, 48)
        points = centre + radius * np.stack([np.cos(t), np.sin(t) * rng.uniform(0.6, 1.0)], 1)
        pressure = 0.6 + 0.4 * np.sin(np.linspace(0, math.pi, len(t)))
        for a, b, p in zip(points, points[1:], pressure):
            d = segment_distance(xs, ys, a, b)
            alpha = np.maximum(alpha, np.clip(width * p / 2 + 0.5 - d, 0, 1))
    grain = rng.uniform(0.55, 1.0, (size, size)).astype(np.float32)
    rgba = np.zeros((size, size, 4), np.float32)
    rgba[:, :, :3] = STROKE_COLOUR
    rgba[:, :, 3] = alpha * grain
    return rgba


def _ink_box(alpha, margin):
    rows, cols = np.nonzero(alpha > 1e-3)
    if len(rows) == 0:
        return None
    h, w = alpha.shape
    return (max(0, rows.min() - margin), min(h, rows.max() + margin + 1),
            max(0, cols.min() - margin), min(w, cols.max() + margin + 1))


def resynthesize(rgba, exemplar, d_max=4.0, weight=4.0, seed=1, progress=None):
    """The drawing `rgba` (straight alpha) with its strokes re-made from the
    stroke `exemplar` by the engine on the stroke-position guide; weight 0 =
    the exemplar's texture with no guide. Only the box around the ink (with
    a margin of d_max and a patch) is synthesized; the rest stays blank."""
    rgba = np.asarray(rgba, np.float32)
    exemplar = np.asarray(exemplar, np.float32)
    if exemplar.ndim != 3 or exemplar.shape[2] != 4:
        raise ValueError(f"the stroke exemplar must be an RGBA image, got shape {exemplar.shape}")
    if not (exemplar[:, :, 3] > INK).any():
        raise ValueError("the stroke exemplar has no ink (alpha > 0.5)")
    out = np.zeros_like(rgba)
    box = _ink_box(rgba[:, :, 3], int(math.ceil(d_max)) + ENGINE["patch_size"])
    if box is None:
        return out
    y0, y1, x0, x1 = box
    target = rgba[y0:y1, x0:x1]
    style = np.concatenate([exemplar[:, :, :3] * exemplar[:, :, 3:], exemplar[:, :, 3:]], axis=2)
    pair = (stroke_guide(exemplar, d_max)[:, :, None], stroke_guide(target, d_max)[:, :, None], float(weight))
    made, _ = synthesis.synthesize(style, [pair] if weight > 0 else [], target_shape=target.shape[:2], seed=int(seed),
                                   progress=progress, **ENGINE)
    made = np.clip(made, 0, 1)
    a = made[:, :, 3:]
    out[y0:y1, x0:x1] = np.concatenate([made[:, :, :3] / np.maximum(a, 1e-6), a], axis=2)
    return out


def read_stroke_exemplar(path):
    """An RGBA stroke exemplar from a file; an image without alpha is read as
    dark ink on white paper (alpha = 1 - luminance)."""
    image = np.asarray(_native.read_image(str(path), None), np.float32)
    if image.ndim == 2:
        image = image[:, :, None]
    if image.shape[2] == 4:
        return image
    grey = image[:, :, :3].mean(axis=2) if image.shape[2] >= 3 else image[:, :, 0]
    rgba = np.zeros(image.shape[:2] + (4,), np.float32)
    rgba[:, :, 3] = np.clip(1.0 - grey, 0, 1)
    return rgba


GENERATED = "generated"  # the stroke exemplar named so is generated_stroke_exemplar()


def load_stroke_exemplar(spec):
    """The stroke exemplar `spec` names: GENERATED, or an image file."""
    if spec == GENERATED:
        return generated_stroke_exemplar()
    from pathlib import Path

    if not Path(spec).is_file():
        raise FileNotFoundError(f"the stroke exemplar '{spec}' does not exist (an RGBA image of strokes, "
                                f"or '{GENERATED}')")
    return read_stroke_exemplar(spec)


def restyle(rgba, exemplar, values, progress=None):
    """resynthesize() with the stroke options of the RigidOptions keywords
    `values`; progress(fraction) returning False cancels (tempera.Cancelled)."""
    from .rigid import RigidOptions

    o = RigidOptions(**values)
    return resynthesize(rgba, exemplar, d_max=o.stroke_d_max, weight=o.stroke_weight, progress=progress)
