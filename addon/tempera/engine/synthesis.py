"""`tempera.synthesize`: the synthesis engine on numpy arrays.

Guided patch-based synthesis (StyLit's image analogies, thesis ch. 8): given
an exemplar ``style`` (A') with source guides (A_g) and the target guides
(B_g), find B' whose patches come from A' where the guides agree.
"""
from __future__ import annotations

from typing import Callable, Iterable, Optional, Sequence

import numpy as np

from .. import _native



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


def _option_help() -> str:
    lines = []
    for row in _native.SynthesisOptions.table():
        choices = f" ({', '.join(row['choices'])})" if row["choices"] else ""
        lines.append(f"    {row['name']} = {row['default']!r}{choices}: {row['help']}")
    return "\n".join(lines)


def _exemplar(index: int, exemplar) -> dict:
    if not isinstance(exemplar, dict):
        raise ValueError(f"exemplar {index}: expected a dict with 'style' and 'guides', got {type(exemplar).__name__}")
    out = dict(exemplar)
    for key in ("style", "mask", "orientation", "segments"):
        if out.get(key) is not None:
            out[key] = _as_image(out[key], f"exemplar {index} {key}")
    out["guides"] = [_as_image(g, f"exemplar {index} guide {k}") for k, g in enumerate(out.get("guides", ()))]
    return out


def synthesize(
    style,
    guides: Iterable = (),
    *,
    exemplars: Sequence[dict] = (),
    reference=None,
    fixed: Optional[dict] = None,
    source_mask=None,
    target_mask=None,
    source_orientation=None,
    target_orientation=None,
    source_segments=None,
    target_segments=None,
    target_shape: Optional[Sequence[int]] = None,
    options=None,
    progress: Optional[Callable[[float], Optional[bool]]] = None,
    **option_values,
):
    """Synthesize B' from the exemplar ``style`` and guide pairs.

    ``guides``: (source, target[, weight]) tuples or dicts (see _guide_tuple);
    all sources are the size of ``style``, all targets the size of the output.
    ``exemplars``: further exemplars of the source set (painted keyframes, the
    frames of a video exemplar), dicts with ``style``, ``guides`` (one source
    per guide pair, in order) and optional ``mask``, ``orientation``,
    ``segments``, ``sequence`` and ``time``.
    ``reference``: B' to start the coarsest level from (Color Me Noisy).
    ``fixed``: hard constraints, dict(mask=, values=[, matches=(H, W, 3)
    exemplar index, x, y]): those pixels keep their values and their
    neighbours continue them.
    Orientations are per-pixel angles in radians (direction (cos a, sin a), x
    right, y down); giving either enables rotation-aware patches.
    ``progress(fraction)`` is called during the run; returning False cancels it
    (raises ``tempera.Cancelled``).
    Engine options are keywords (or ``options=tempera.SynthesisOptions(...)``);
    unknown names are errors. They are, with their defaults:

    {options}

    Returns ``(image, stats)``: the float32 (H, W, C) result and a
    ``SynthesisStats`` (also readable as ``stats["name"]``): energy per level
    and iteration, seconds per stage, source coverage, and the final match per
    pixel: ``nnf`` ((H, W, 2) int source x, y), ``exemplar`` ((H, W), 0 =
    ``style``) and ``field`` ((H, W, 2) sub-pixel positions). See docs/engine.md.
    """
    opts = _native.SynthesisOptions() if options is None else options
    for name, value in option_values.items():
        if not hasattr(opts, name):
            known = ", ".join(row["name"] for row in _native.SynthesisOptions.table())
            raise TypeError(f"synthesize() got an unexpected keyword argument '{name}' (engine options: {known})")
        setattr(opts, name, value)
    opts.validate()
    style = _as_image(style, "style")
    guide_list = [_guide_tuple(i, g) for i, g in enumerate(guides)]
    if target_shape is not None:
        target_shape = (int(target_shape[0]), int(target_shape[1]))
    elif not guide_list:
        raise ValueError("give at least one guide pair or target_shape=(height, width)")
    given_maps = dict(source_mask=source_mask, target_mask=target_mask, source_orientation=source_orientation,
                      target_orientation=target_orientation, source_segments=source_segments,
                      target_segments=target_segments)
    maps = {name: _as_image(m, name.replace("_", " ")) for name, m in given_maps.items() if m is not None}
    exemplar_list = [_exemplar(i + 1, e) for i, e in enumerate(exemplars)]
    if reference is not None:
        reference = _as_image(reference, "reference")
    if fixed is not None:
        fixed = {k: (None if v is None else _as_image(v, f"fixed {k}")) for k, v in dict(fixed).items()}

    def report(fraction: float) -> bool:
        return True if progress is None else progress(fraction) is not False

    return _native.synthesize(style, guide_list, opts, maps, target_shape, exemplar_list, reference, fixed, report)


def method_options(options_class, engine_defaults, values: dict, method: str):
    """A method's options from keywords: the method's own (the fields of
    `options_class`) and engine options (SynthesisOptions names), starting
    from the method's engine defaults; unknown names are TypeErrors."""
    own = {row["name"] for row in options_class.table()}
    opts = options_class(**{k: v for k, v in values.items() if k in own})
    engine = engine_defaults
    for name, value in values.items():
        if name in own:
            continue
        if not hasattr(engine, name):
            raise TypeError(f"unknown {method} option '{name}'")
        setattr(engine, name, value)
    engine.validate()
    opts.synthesis = engine
    return opts


synthesize.__doc__ = synthesize.__doc__.replace("    {options}", _option_help())
USAGE_MODES = tuple(next(r["choices"] for r in _native.SynthesisOptions.table() if r["name"] == "usage"))
SynthesisOptions = _native.SynthesisOptions
