"""`tempera.synthesize`: the synthesis engine on numpy arrays.

Guided patch-based synthesis (StyLit's image analogies, thesis ch. 8): given
an exemplar ``style`` (A') with source guides (A_g) and the target guides
(B_g), find B' whose patches come from A' where the guides agree.
"""
from __future__ import annotations

from typing import Callable, Iterable, Optional, Sequence

import numpy as np

from . import _native

USAGE_MODES = ("none", "penalty", "uniform", "budget")


def _as_image(array, what: str) -> np.ndarray:
    a = np.asarray(array)
    if a.dtype.kind not in "fiub":
        raise ValueError(f"{what} must be a numeric array, got dtype {a.dtype}")
    a = np.ascontiguousarray(a, dtype=np.float32)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{what} must be an (H, W) or (H, W, C) array, got shape {a.shape}")
    return a


def _guide_tuple(index: int, guide) -> tuple:
    """Accepts (source, target), (source, target, weight) or a dict with keys
    source, target and optional weight, name, target_weight_map."""
    if isinstance(guide, dict):
        unknown = set(guide) - {"source", "target", "weight", "name", "target_weight_map"}
        if unknown:
            raise ValueError(f"guide {index}: unknown keys {sorted(unknown)}")
        name = guide.get("name", f"guide{index}")
        source, target = guide["source"], guide["target"]
        weight = guide.get("weight", 1.0)
        weight_map = guide.get("target_weight_map")
    else:
        items = tuple(guide)
        if len(items) not in (2, 3):
            raise ValueError(f"guide {index}: expected (source, target[, weight]), got {len(items)} items")
        source, target = items[0], items[1]
        weight = items[2] if len(items) == 3 else 1.0
        name, weight_map = f"guide{index}", None
    return (
        str(name),
        _as_image(source, f"guide '{name}' source"),
        _as_image(target, f"guide '{name}' target"),
        float(weight),
        None if weight_map is None else _as_image(weight_map, f"guide '{name}' target weight map"),
    )


def synthesize(
    style,
    guides: Iterable = (),
    *,
    usage: str = "budget",
    patch_size: int = 5,
    levels: int = 0,
    em_iterations: int = 6,
    pm_iterations: int = 2,
    style_weight: float = 1.0,
    penalty_weight: float = 1.0,
    guide_variance: float = 0.999,
    axial_orientation: bool = True,
    budget_coverage: float = 0.95,
    budget_max_rounds: int = 16,
    seed: int = 1,
    threads: int = 0,
    source_mask=None,
    target_mask=None,
    source_orientation=None,
    target_orientation=None,
    source_segments=None,
    target_segments=None,
    target_shape: Optional[Sequence[int]] = None,
    progress: Optional[Callable[[float], Optional[bool]]] = None,
):
    """Synthesize B' from the exemplar ``style`` and guide pairs.

    ``guides``: (source, target[, weight]) tuples or dicts (see _guide_tuple);
    all sources are the size of ``style``, all targets the size of the output.
    ``usage``: ``none``, ``penalty`` (occurrence penalty, ``penalty_weight``),
    ``uniform`` (every source patch used equally; per ``*_segments`` label) or
    ``budget`` (StyLit's error budget, the default).
    ``guide_variance``: fraction of the weighted guide variance kept when the
    guide channels are compressed by PCA (1.0 = exact matching, slower).
    Orientations are per-pixel angles in radians (direction (cos a, sin a), x
    right, y down); giving either enables rotation-aware patches. With
    ``axial_orientation`` (default) they are taken modulo pi, like stroke
    directions, and patches turn by the smallest angle that aligns them.
    ``progress(fraction)`` is called during the run; returning False cancels it
    (raises ``tempera.Cancelled``).

    Returns ``(image, stats)``: the float32 (H, W, C) result and a dict with the
    energy per level and iteration, seconds per stage, source coverage and the
    final NNF (``stats["nnf"]``, (H, W, 2) source x, y per target pixel).
    See docs/engine.md.
    """
    if usage not in USAGE_MODES:
        raise ValueError(f"unknown patch usage '{usage}' (choose {', '.join(USAGE_MODES)})")
    style = _as_image(style, "style")
    guide_list = [_guide_tuple(i, g) for i, g in enumerate(guides)]
    if target_shape is not None:
        target_shape = (int(target_shape[0]), int(target_shape[1]))
    elif not guide_list:
        raise ValueError("give at least one guide pair or target_shape=(height, width)")
    options = dict(usage=usage, patch_size=int(patch_size), levels=int(levels), em_iterations=int(em_iterations),
                   pm_iterations=int(pm_iterations), style_weight=float(style_weight),
                   penalty_weight=float(penalty_weight), guide_variance=float(guide_variance),
                   axial_orientation=bool(axial_orientation), budget_coverage=float(budget_coverage),
                   budget_max_rounds=int(budget_max_rounds), seed=int(seed), threads=int(threads))
    given_maps = dict(source_mask=source_mask, target_mask=target_mask, source_orientation=source_orientation,
                      target_orientation=target_orientation, source_segments=source_segments,
                      target_segments=target_segments)
    maps = {name: _as_image(m, name.replace("_", " ")) for name, m in given_maps.items() if m is not None}

    def report(fraction: float) -> bool:
        return True if progress is None else progress(fraction) is not False

    return _native.synthesize(style, guide_list, options, maps, target_shape, report)
