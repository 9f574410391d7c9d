"""`tempera.trace_lpe`: light-path-expression guides by path tracing.

StyLit matches light-path classes (thesis §8.3.2) that Cycles cannot isolate,
e.g. caustics ``LS*DE`` or the second diffuse bounce alone. This renders any
number of expressions in one pass with the native Embree tracer. The scene is
a plain dict of arrays (see ``docs/lpe_guides.md``, "Scene format"); the
Blender exporter builds it.
"""
from __future__ import annotations

from typing import Callable, Optional, Sequence

import numpy as np

from . import _native

# The guides of the StyLit paper (thesis fig. 8.4), by name.
STYLIT_EXPRESSIONS = {
    "FULL": "L.*E",
    "LDE": "LDE",
    "LSE": "LSE",
    "LDDE": "L.*DDE",
    "LD12E": "LD{1,2}E",
}

_FLOAT_ARRAYS = ("vertices", "normals", "uvs")
_INT_ARRAYS = ("triangles", "triangle_materials")


def _int_array(value, what: str) -> np.ndarray:
    a = np.asarray(value)
    if a.size and a.dtype.kind not in "iu":
        raise ValueError(f"scene '{what}' must be an integer array, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.int64)


def _prepare_scene(scene: dict) -> dict:
    """A shallow copy with arrays made contiguous in the dtypes the native side reads."""
    if not isinstance(scene, dict):
        raise ValueError(f"scene must be a dict, got {type(scene).__name__}")
    out = dict(scene)
    for key in _FLOAT_ARRAYS:
        if key in out:
            out[key] = np.ascontiguousarray(out[key], dtype=np.float32)
    for key in _INT_ARRAYS:
        if key in out:
            out[key] = _int_array(out[key], key)
    if isinstance(out.get("materials"), (list, tuple)):
        out["materials"] = [_prepare_material(m) for m in out["materials"]]
    if isinstance(out.get("textures"), (list, tuple)):
        out["textures"] = [np.ascontiguousarray(t, dtype=np.float32) for t in out["textures"]]
    if "triangle_visibility" in out:
        out["triangle_visibility"] = _int_array(out["triangle_visibility"], "triangle_visibility")
    return out


def _prepare_material(material):
    if not isinstance(material, dict) or "base_color_texture" not in material:
        return material
    m = dict(material)
    m["base_color_texture"] = np.ascontiguousarray(m["base_color_texture"], dtype=np.float32)
    return m


def check_lpe(expression: str) -> None:
    """Raise ValueError naming the 0-based position if ``expression`` is malformed."""
    _native.check_lpe(str(expression))


def lpe_matches(expression: str, events: str) -> bool:
    """Whether the light-to-eye event string (e.g. ``"LDDE"``) matches ``expression``."""
    return _native.lpe_matches(str(expression), str(events))


def trace_lpe(
    scene: dict,
    expressions: Sequence[str],
    *,
    samples: int = 64,
    seed: int = 0,
    threads: int = 0,
    max_bounces: int = 8,
    progress: Optional[Callable[[float], Optional[bool]]] = None,
    diffuse_bounces: int = 1024,
    glossy_bounces: int = 1024,
    transmission_bounces: int = 1024,
    transparent_bounces: int = 1024,
    caustics_reflective: bool = True,
    caustics_refractive: bool = True,
):
    """Render one linear radiance image per light path expression.

    ``expressions`` are written light-to-eye: ``L`` emitter (lights, emissive
    surfaces, world), ``D`` diffuse, ``S`` (or ``G``) glossy/specular
    reflection, ``T`` transmission, ``E`` eye; operators ``. * + ? {m} {m,}
    {m,n} [..] [^..] | ( )``. The result depends only on ``seed``, not on
    ``threads``. ``max_bounces`` counts indirect bounces as Cycles does, and
    so do the per-kind limits (``diffuse_bounces`` ...; transparent surfaces
    count separately). ``caustics_reflective``/``caustics_refractive`` False
    drop glossy/refractive lobes after a diffuse bounce, as Cycles' options do.
    ``progress(fraction)`` returning False cancels (raises ``tempera.Cancelled``).

    Returns ``(images, alpha)``: a list of float32 (H, W, 3) arrays in the
    order of ``expressions`` and the float32 (H, W) fraction of camera rays
    that hit geometry.
    """
    if isinstance(expressions, str):
        raise ValueError("expressions must be a list of strings, not one string")
    expressions = [str(e) for e in expressions]

    def report(fraction: float) -> bool:
        return True if progress is None else progress(fraction) is not False

    return _native.trace_lpe(_prepare_scene(scene), expressions, samples=int(samples), seed=int(seed),
                             threads=int(threads), max_bounces=int(max_bounces), progress=report,
                             diffuse_bounces=int(diffuse_bounces), glossy_bounces=int(glossy_bounces),
                             transmission_bounces=int(transmission_bounces),
                             transparent_bounces=int(transparent_bounces),
                             caustics_reflective=bool(caustics_reflective),
                             caustics_refractive=bool(caustics_refractive))
