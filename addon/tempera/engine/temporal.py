"""Temporal behaviour of a stylized sequence from rendered motion, without
Blender: per-frame motion and visibility (Bénard et al. 2013's χ−) from
Blender's Vector passes, and the flicker figure of two stylized frames.

The temporal guide itself (the previous stylized frame advected along the
motion, weighted by χ−) is part of StyLit per frame: tempera.methods.stylit.stylize
(native/src/methods/stylit/stylit.cpp); flicker() here is the same native figure.
"""
import numpy as np

from .. import _native
from . import guides
from ..app.guide_cache import velocities_from_vector_pass


def motion(vector_pass, previous_vector_pass, epsilon=2.0):
    """(velocity_backward, χ−) of a frame from its Vector pass and the previous
    frame's (Blender's layout, see guide_cache.velocities_from_vector_pass)."""
    backward, _ = velocities_from_vector_pass(vector_pass)
    _, previous_forward = velocities_from_vector_pass(previous_vector_pass)
    return backward, guides.occlusion_backward(backward, previous_forward, epsilon)


def flicker(previous_stylized, stylized, velocity_backward, visible):
    """Mean absolute colour change along valid motion between two stylized
    frames (0 = the paint moves perfectly with the surface)."""
    def image(a):
        a = np.ascontiguousarray(a, dtype=np.float32)
        return a[:, :, None] if a.ndim == 2 else a

    visible = np.asarray(visible)
    return _native.flicker(image(previous_stylized), image(stylized), image(velocity_backward),
                           image((visible != 0).astype(np.float32)))


# --------------------------------------------------------------------------- noise measurements
# Color Me Noisy (Fišer et al. 2014, §4.1.1) measures noise as the temporal
# power spectrum at motion-compensated pixels: flat (white) spectra whose
# total energy rises with the low-pass width f.

def _tracks(frames, velocity_forward, occlusion_forward):
    """Per tracked point of frame 0, its colour in every frame: (T, N, C).
    Points follow V+ (bilinear) and are dropped once χ+ says they vanish."""
    frames = [np.asarray(f, dtype=np.float64) for f in frames]
    frames = [f[:, :, None] if f.ndim == 2 else f for f in frames]
    h, w, _ = frames[0].shape
    ys, xs = np.mgrid[0:h, 0:w]
    x, y = xs.ravel().astype(np.float64), ys.ravel().astype(np.float64)
    alive = np.ones(x.shape, bool)
    out = []
    for t, frame in enumerate(frames):
        xi = np.clip(np.rint(x), 0, w - 1).astype(int)
        yi = np.clip(np.rint(y), 0, h - 1).astype(int)
        out.append(frame[yi, xi])
        if velocity_forward is None or t + 1 == len(frames):
            continue
        v = np.asarray(velocity_forward[t], dtype=np.float64)
        if occlusion_forward is not None:
            alive &= np.asarray(occlusion_forward[t])[yi, xi] != 0
        x, y = x + v[yi, xi, 0], y + v[yi, xi, 1]
        alive &= (x >= 0) & (x <= w - 1) & (y >= 0) & (y <= h - 1)
    return np.stack(out)[:, alive]


def temporal_power_spectrum(frames, velocity_forward=None, occlusion_forward=None):
    """Mean temporal power spectrum of a sequence (frequencies 0 .. T/2), over
    every pixel of frame 0 followed along the rendered forward motion
    (velocity_forward[t]: frame t's V+, (H, W, 2) pixels, x right, y down;
    occlusion_forward[t]: its χ+). Without motion, pixels stay put (a static
    shot). Entry 0 is the DC power."""
    tracks = _tracks(frames, velocity_forward, occlusion_forward)
    if tracks.shape[1] == 0:
        raise ValueError("no pixel stays visible over the whole sequence")
    spectrum = np.abs(np.fft.rfft(tracks, axis=0)) ** 2 / tracks.shape[0]
    return spectrum.mean(axis=(1, 2))


def noise_energy(spectrum):
    """Non-DC temporal power: how much a sequence boils."""
    return float(np.sum(spectrum[1:]))


def spectral_flatness(spectrum):
    """Geometric over arithmetic mean of the non-DC power (1 = white noise)."""
    p = np.asarray(spectrum[1:], dtype=np.float64)
    p = np.maximum(p, 1e-30)
    return float(np.exp(np.mean(np.log(p))) / np.mean(p))


def box_consistency_error(output, reference, width):
    """RMSE between box_f * output and box_f * reference (Color Me Noisy's
    low-frequency term, eq. 2): how well the noise keeps R's large shapes."""
    def box(a):
        a = np.asarray(a, dtype=np.float32)
        a = a[:, :, None] if a.ndim == 2 else a
        return _native.box_blur(np.ascontiguousarray(a), float(width))

    return float(np.sqrt(np.mean((box(output) - box(reference)) ** 2)))
