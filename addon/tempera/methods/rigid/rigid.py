"""Example-based expressive animation of 2D rigid bodies (Dvorožňák et al.
2017): the squash, stretch, bend and line of drawn exemplars carried onto a
target rigid-body simulation.

``fit_exemplar`` registers drawn frames to their source proxies (one
quadratic map D per frame) and keeps the residuals; ``stylize`` makes the
target frames (RGBA); ``generated_exemplar`` draws the project's own
"hand-drawn" exemplar from a known generator, whose maps applied to the
target (``oracle_maps``) are the exact answer the tests and the demo compare
with. Tracks are the dicts of tempera.methods.rigid.rigid_tracks (tracks.json). The method
lives in native/src/methods/rigid/rigid.cpp; docs/rigid_bodies.md gives every design choice.
"""
from __future__ import annotations

import numpy as np

from ... import _native

RigidOptions = _native.RigidOptions
QuadraticFitOptions = _native.QuadraticFitOptions
ExemplarStyle = _native.ExemplarStyle
# The proxy shapes and their rotational symmetry (Diff's rotation term; 0 = a circle).
SYMMETRY = {"circle": 0, "box": 4}


def _rgba(a, what):
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim != 3 or a.shape[2] != 4:
        raise ValueError(f"{what} must be an (H, W, 4) RGBA image, got shape {a.shape}")
    return a


def generated_track(shape="circle"):
    """The project's own source motion: a ball thrown from the left that
    bounces on a floor (spinning more as a box, which tumbles as it goes)."""
    return _native.bouncing_ball((60, 60), (5.0, 0), 20, 1.0, 330, 0.65, 0.12 if shape == "box" else 0.05, 60)


def generated_exemplar(track, width, height, **style):
    """The generated drawings of every frame of `track` (RGBA, graphite on
    transparent paper), with the ExemplarStyle keywords (stretch, squash,
    squash_frames, bend, wobble, line_width, shape, seed)."""
    s = ExemplarStyle(**style)
    return [_native.draw_exemplar_frame(track, f, s, width, height) for f in range(len(track["centre"]))]


def oracle_maps(track, **style):
    """D_gen of every frame of `track`: what a perfect transfer of the
    generated exemplar gives (2 x 6 arrays, radius-normalized)."""
    s = ExemplarStyle(**style)
    return [_native.generator_map(track, f, s) for f in range(len(track["centre"]))]


def fit_exemplar(track, drawings, shape="circle", masks=None, **fit):
    """(track, maps, residuals) of a drawn exemplar: for each frame the
    quadratic map D from the proxy (its mask, or the proxy `shape` drawn from
    the track) to the drawing's ink, and the residual f^r = D^-1(f^e).
    `fit` takes QuadraticFitOptions keywords (fit_blurs, fit_iterations,
    fit_chamfer, fit_prior)."""
    n = len(track["centre"])
    if len(drawings) != n:
        raise ValueError(f"the exemplar has {len(drawings)} drawings for {n} track frames")
    options = QuadraticFitOptions(**fit)
    maps, residuals = [], []
    for f, drawing in enumerate(drawings):
        d = _rgba(drawing, f"drawing {f}")
        h, w = d.shape[:2]
        mask = _native.proxy_mask(track, f, shape, w, h) if masks is None else np.asarray(masks[f], np.float32)
        centre, radius = track["centre"][f], track["radius"][f]
        D = _native.fit_quadratic_map(mask.reshape(h, w, 1), np.ascontiguousarray(d[:, :, 3:4]), centre, radius, options)
        maps.append(D)
        residuals.append(_native.extract_residual(d, D, centre, radius))
    return track, maps, residuals


def stylize(exemplars, target, width, height, progress=None, only=None, **values):
    """Every target frame as (rgba, D_hat, contact_shift), or None for frames
    not in `only` (a list of frame indices; None = all). `exemplars` are
    fit_exemplar results; `values` RigidOptions keywords (k, lambda_vel,
    lambda_dir, lambda_rot, symmetry, augment, scales, flip, damp,
    fold_min_det, contact_fade, overlap_blend). progress(frame) returning False cancels
    (tempera._native.Cancelled)."""
    options = RigidOptions(**values)
    prepared = [(t, list(m), [_rgba(r, "residual") for r in rs]) for t, m, rs in exemplars]
    return _native.rigid_stylize(prepared, target, options, int(width), int(height), progress,
                                 None if only is None else [int(f) for f in only])


def deformations(exemplars, target, **values):
    """D_hat, xi and the matched residuals per target frame, without images."""
    return _native.rigid_deformations([(t, list(m)) for t, m, _ in exemplars], target, RigidOptions(**values))


def stretch_along(D, direction):
    """|J_D(0) d| for the unit direction d: the stretch at the centroid."""
    D = np.asarray(D)
    d = np.asarray(direction, float)
    n = np.linalg.norm(d)
    return 1.0 if n < 1e-9 else float(np.linalg.norm(D[:, :2] @ (d / n)))
