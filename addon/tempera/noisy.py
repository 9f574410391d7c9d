"""Color Me Noisy (Fišer et al. 2014; thesis ch. 4): a controllable amount of
temporal noise ("boiling") on a coherent stylized sequence.

``noisy_frame`` makes one frame T_i from the coherent frame R_i and the
medium's exemplar S; ``NoisySequence`` runs a folder of frames with resume.
The method lives in native/src/noisy.cpp; docs/noisy.md explains the slider.
"""
from __future__ import annotations

import numpy as np

from . import _native
from .synthesis import method_options

NoisyOptions = _native.NoisyOptions
# The paper's tested widths f (thesis fig. 4.11), the panel's slider steps.
TESTED_NOISE = (1.3, 1.6, 1.9, 2.2, 2.6, 3.1, 3.6, 4.3)


def options(**values) -> "NoisyOptions":
    """NoisyOptions from keywords: its own (noise, lattice_spacing, shift_min,
    shift_max, deform) and engine options (SynthesisOptions names, starting
    from Color Me Noisy's defaults: patch 7, mode voting, 4 EM x 2 PM)."""
    return method_options(NoisyOptions, _native.noisy_defaults(), values, "Color Me Noisy")


def _image(a, what):
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{what} must be (H, W) or (H, W, C), got shape {a.shape}")
    return a


def noisy_frame(style, reference, frame: int, *, noise_map=None, progress=None, **values):
    """One noisy frame: ``reference`` (R_i) with its fine texture synthesized
    again from the freshly deformed exemplar ``style`` above the width
    ``noise`` (f, px). ``frame`` seeds the frame's randomness (the same frame
    and seed give the same result). ``noise_map`` (R's size) scales f per
    pixel: 0 keeps R, 1 the full amount."""
    opts = options(**values)
    nm = None if noise_map is None else _image(noise_map, "noise map")
    report = None if progress is None else (lambda f: progress(f) is not False)
    return _native.noisy_frame(_image(style, "exemplar"), _image(reference, "reference frame"), int(frame), opts,
                               nm, report)
