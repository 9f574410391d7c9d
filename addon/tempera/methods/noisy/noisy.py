"""Color Me Noisy (Fišer et al. 2014; thesis ch. 4): a controllable amount of
temporal noise ("boiling") on a coherent stylized sequence.

``noisy_frame`` makes one frame T_i from the coherent frame R_i and the
medium's exemplar S; ``NoisySequence`` runs a folder of frames with resume.
The method lives in native/src/methods/noisy/noisy.cpp; docs/noisy.md explains the slider.
"""
from __future__ import annotations

import numpy as np

from ... import _native
from ...app.frame_job import FrameJob
from ...engine.synthesis import method_options

NoisyOptions = _native.NoisyOptions
# The paper's tested widths f (thesis fig. 4.11), the panel's slider steps.
TESTED_NOISE = (1.3, 1.6, 1.9, 2.2, 2.6, 3.1, 3.6, 4.3)


def options(**values) -> "NoisyOptions":
    """NoisyOptions from keywords: its own (noise, lattice_spacing, shift_min,
    shift_max, deform, consistency, rotations, reflections) and engine options
    (SynthesisOptions names, starting from Color Me Noisy's defaults: patch 7,
    mode voting, 4 EM x 2 PM)."""
    return method_options(NoisyOptions, _native.noisy_defaults(), values, "Color Me Noisy")


def _image(a, what):
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{what} must be (H, W) or (H, W, C), got shape {a.shape}")
    return a


def noisy_frame(style, reference, frame: int, *, noise_map=None, progress=None, guides=None, **values):
    """One noisy frame: ``reference`` (R_i) with its fine texture synthesized
    again from the freshly deformed exemplar ``style`` above the width
    ``noise`` (f, px). ``frame`` seeds the frame's randomness (the same frame
    and seed give the same result). ``noise_map`` (R's size) scales f per
    pixel: 0 keeps R, 1 the full amount. ``guides``: for guided noise
    (``noise_guides`` > 0), {name: (exemplar guide, frame guide, weight)},
    tone-mapped, the exemplar's undeformed at S's size."""
    opts = options(**values)
    nm = None if noise_map is None else _image(noise_map, "noise map")
    report = None if progress is None else (lambda f: progress(f) is not False)
    pairs = [(str(name), _image(src, f"exemplar guide {name}"), _image(tgt, f"frame guide {name}"), float(w))
             for name, (src, tgt, w) in (guides or {}).items()]
    return _native.noisy_frame(_image(style, "exemplar"), _image(reference, "reference frame"), int(frame), opts,
                               nm, report, pairs)


def noise_width(level: int) -> float:
    """The panel's Temporal Noise step (0 = off, 1..8) as the width f."""
    if not 0 <= int(level) <= len(TESTED_NOISE):
        raise ValueError(f"Temporal Noise must be 0 (off) to {len(TESTED_NOISE)}, got {level}")
    return 0.0 if int(level) == 0 else TESTED_NOISE[int(level) - 1]


class NoisySequence(FrameJob):
    """The noise pass over a folder of coherent frames (native/src/methods/noisy/noisy_sequence.cpp),
    what ``tempera stylize --noise`` and the panel run after the coherent pass.

    exemplar   the medium S (the painting)
    reference  folder of the coherent frames R (<prefix>0001.png ...)
    frames     frame numbers, in order
    out        output folder; frames are written as out/<prefix>0001.png
    noise_map  optional: an image file of R's size, or the name of a guide of
               ``guides`` ("alpha", "mask.OB_Cube", an AOV), read per frame;
               f_p = noise * map (0 keeps R, 1 the full amount)
    exemplar_guides, exemplar_frame, guide_weights
               for guided noise (``noise_guides`` > 0): the exemplar render's
               guide cache, its frame (default: the only one) and StyLit's
               light-path guide weights {name: weight} (default: StyLit's);
               ``guides`` is then the frames' guide cache
    **values   Color Me Noisy and engine options (see ``options``)

    Construction checks every file up front (FileNotFoundError, ValueError).
    ``run_frame(i)`` makes frames[i] or skips it when current (resume)."""

    def __init__(self, exemplar, reference, frames, out, *, noise_map=None, guides=None, prefix="frame_",
                 resume=True, exemplar_guides=None, exemplar_frame=None, guide_weights=None, **values):
        config = _native.NoisySequenceConfig(exemplar=exemplar, reference=reference, frames=[int(f) for f in frames],
                                             out=out, prefix=prefix, resume=resume, noise_map=noise_map or "",
                                             guides=guides or "", exemplar_guides=exemplar_guides or "",
                                             exemplar_frame=exemplar_frame)
        if guide_weights is not None:
            config.guide_weights = [(str(k), float(v)) for k, v in dict(guide_weights).items()]
        self._job = _native.NoisySequence(config, options(**values))


# Where the panel's noise map comes from: (enum item, label, description).
NOISE_MAP_SOURCES = (
    ("NONE", "Everywhere", "The same amount of noise everywhere"),
    ("IMAGE", "Painted Image", "A greyscale image of the render's size: black keeps the coherent frame, "
                               "white boils by the full amount"),
    ("OBJECT", "Object", "Noise only on an object (its mask guide; 'Object Masks' must include it)"),
    ("COLLECTION", "Collection", "Noise only on a collection (its mask guide)"),
    ("GUIDE", "Attribute / AOV", "Any guide of the guide cache by name, e.g. an AOV rendered into it"),
)


def noise_map_spec(source, image="", object_name="", collection_name="", guide=""):
    """The NoisySequence noise_map of the panel's choice: None, an image path,
    or a guide name (mask.OB_<name>, mask.CO_<name>, or the given guide)."""
    from ...app import guide_cache

    def need(value, what):
        if not value:
            raise ValueError(f"Choose the noise map's {what} (Temporal Noise), or set the map to Everywhere.")
        return value

    if source == "NONE":
        return None
    if source == "IMAGE":
        return need(image, "image")
    if source == "OBJECT":
        return guide_cache.mask_guide("OB", need(object_name, "object"))
    if source == "COLLECTION":
        return guide_cache.mask_guide("CO", need(collection_name, "collection"))
    if source == "GUIDE":
        return need(guide, "guide name")
    raise ValueError(f"unknown noise map source {source!r}")
