"""`tempera.engine.guides`: building blocks for guides and temporal coherence.

Native (multithreaded, GIL released) implementations of the inputs of
Bénard et al. 2013, "Stylizing Animation by Example", on numpy arrays:

* motion (§3.1): occlusion tests χ-/χ+ from rendered velocity fields, and
  backward advection of the previous frame;
* orientation (§3.1): structure tensor of the grayscale image, and the
  angle / coherence it defines;
* lines (§3.2): bounded distance to line pixels, D(I);
* light-path guides (StyLit): radiance tone-mapped to the values matched.

Conventions: images are (H, W) or (H, W, C); x runs to the right and y down
(image rows). Velocities are (H, W, 2) arrays (x, y) in pixels:

* V+_t(p): a point visible at p in frame t moves to p + V+_t(p) in frame t+1;
* V-_t(p): a point visible at p in frame t came from p - V-_t(p) in frame t-1.

Both hold the displacement from the earlier frame to the later one, so along
a consistent motion path V-_t(p) = V+_{t-1}(p - V-_t(p)).
"""
from __future__ import annotations

import numpy as np

from .. import _native

__all__ = [
    "StructureTensor",
    "line_distance",
    "occlusion_backward",
    "occlusion_forward",
    "orientation",
    "structure_tensor",
    "tonemap",
    "warp_backward",
]


def _image(array, what: str) -> np.ndarray:
    """Any numeric (H, W) or (H, W, C) array as C-contiguous float32 (H, W, C)."""
    a = np.asarray(array)
    if a.dtype.kind not in "fiub":
        raise ValueError(f"{what} must be a numeric array, got dtype {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{what} must be an (H, W) or (H, W, C) array, got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"{what} is empty (shape {a.shape})")
    return np.ascontiguousarray(a, dtype=np.float32)


def _velocity(array, what: str) -> np.ndarray:
    a = _image(array, what)
    if a.shape[2] != 2:
        raise ValueError(f"{what} must be an (H, W, 2) velocity array (x, y in pixels), got shape "
                         f"{np.shape(array)}")
    return a


def _positive(value, what: str) -> float:
    v = float(value)
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{what} must be a positive finite number, got {value}")
    return v


def occlusion_backward(v_minus_t, v_plus_prev, epsilon: float = 2.0) -> np.ndarray:
    """χ-(p, t): 1 where p was already visible in frame t-1, 0 where it has
    just been disoccluded (or came from outside the frame).

    χ- = 1 if ||V+_{t-1}(p - V-_t(p)) - V-_t(p)||² < epsilon (V+_{t-1} sampled
    bilinearly). ``v_minus_t`` is V-_t and ``v_plus_prev`` is V+_{t-1}, both
    (H, W, 2). ``epsilon`` is in squared pixels (the paper uses 2).
    Returns an (H, W) float32 array of 0 and 1.
    """
    a, b = _velocity(v_minus_t, "v_minus_t"), _velocity(v_plus_prev, "v_plus_prev")
    return _native.occlusion_backward(a, b, _positive(epsilon, "epsilon"))[:, :, 0]


def occlusion_forward(v_plus_t, v_minus_next, epsilon: float = 2.0) -> np.ndarray:
    """χ+(p, t): 1 where p stays visible in frame t+1, 0 where it is about to
    be occluded (or leaves the frame).

    χ+ = 1 if ||V-_{t+1}(p + V+_t(p)) - V+_t(p)||² < epsilon. ``v_plus_t`` is
    V+_t and ``v_minus_next`` is V-_{t+1}, both (H, W, 2).
    Returns an (H, W) float32 array of 0 and 1.
    """
    a, b = _velocity(v_plus_t, "v_plus_t"), _velocity(v_minus_next, "v_minus_next")
    return _native.occlusion_forward(a, b, _positive(epsilon, "epsilon"))[:, :, 0]


def warp_backward(previous, v_minus_t) -> np.ndarray:
    """The previous frame advected to frame t: out(p) = previous(p - V-_t(p)).

    Bilinear, with positions clamped to the frame (edge pixels repeat).
    ``previous`` is (H, W) or (H, W, C) with any C; the result has its shape.
    Disoccluded pixels get stale content: mask them with occlusion_backward.
    """
    image = _image(previous, "previous")
    out = _native.warp_backward(image, _velocity(v_minus_t, "v_minus_t"))
    return out[:, :, 0] if np.ndim(previous) == 2 else out


class StructureTensor(np.ndarray):
    """An (H, W, 3) float32 array of (Jxx, Jxy, Jyy), as returned by
    structure_tensor(). The type only tells orientation() that the array is a
    tensor, not an RGB image; arithmetic on it (``(a + b) / 2``) keeps it."""


def structure_tensor(gray, sigma: float = 2.0) -> StructureTensor:
    """Per-pixel structure tensor (Granlund & Knutsson) of an image.

    The image is made grayscale (mean of the first three channels, or the
    first channel of a 1- or 2-channel image), differentiated with Sobel
    filters, and (gx², gx·gy, gy²) are smoothed with a Gaussian of standard
    deviation ``sigma`` pixels (0: none). Returns (H, W, 3): tensors, unlike
    angles, can be interpolated and averaged.
    """
    sigma = float(sigma)
    if not np.isfinite(sigma) or sigma < 0:
        raise ValueError(f"sigma must be a finite number >= 0, got {sigma}")
    return _native.structure_tensor(_image(gray, "image"), sigma).view(StructureTensor)


def orientation(gray_or_tensor, sigma: float = 2.0, *, tensor: bool | None = None):
    """Dominant edge orientation and its coherence, per pixel.

    Returns ``(angle, coherence)``, two (H, W) float32 arrays: ``angle`` in
    [0, π) is the direction (cos a, sin a) (x right, y down) *along* the
    stripes, perpendicular to the gradient; ``coherence`` in [0, 1] is
    (λ1 - λ2) / (λ1 + λ2), 0 on flat or isotropic areas.

    ``gray_or_tensor`` is an image (then its structure tensor with ``sigma``
    is computed first) or a tensor: a StructureTensor from structure_tensor()
    is recognised, any other array is taken as an image unless
    ``tensor=True`` (e.g. a tensor averaged with np.mean).
    """
    is_tensor = isinstance(gray_or_tensor, StructureTensor) if tensor is None else bool(tensor)
    if is_tensor:
        t = _image(gray_or_tensor, "structure tensor")
        if t.shape[2] != 3:
            raise ValueError(f"structure tensor must be an (H, W, 3) array (Jxx, Jxy, Jyy), got shape "
                             f"{np.shape(gray_or_tensor)}")
    else:
        t = structure_tensor(gray_or_tensor, sigma)
    out = _native.orientation_from_tensor(np.asarray(t))
    return out[:, :, 0], out[:, :, 1]


def line_distance(mask, d_max: float = 10.0) -> np.ndarray:
    """Bounded distance to lines, D(I) of Bénard 2013 §3.2.

    ``mask`` is (H, W) or (H, W, 1); values > 0.5 are line pixels. Returns an
    (H, W) float32 array min(distance, d_max) / d_max: 0 on lines, 1 at d_max
    pixels and beyond (everywhere if there is no line). Exact Euclidean
    distance between pixel centres (Felzenszwalb & Huttenlocher).
    """
    m = _image(mask, "line mask")
    if m.shape[2] != 1:
        raise ValueError(f"line mask must be an (H, W) or (H, W, 1) array, got shape {np.shape(mask)}")
    return _native.line_distance(m, _positive(d_max, "d_max"))[:, :, 0]


def tonemap(linear):
    """Linear radiance -> guide values in [0, 1) as StyLit matches them:
    NaN and negatives to 0, Reinhard x / (1 + x), then the sRGB encoding.
    Per pixel, with no image-dependent normalization, so equal lighting gives
    equal guides in the exemplar and in every frame."""
    a = np.asarray(linear, dtype=np.float32)
    flat = a.reshape(a.shape[0], -1) if a.ndim == 1 else a
    return _native.tonemap_guide(np.ascontiguousarray(flat)).reshape(a.shape)
