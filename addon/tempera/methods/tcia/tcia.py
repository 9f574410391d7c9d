"""Stylizing Animation by Example (Bénard et al. 2013): a whole shot at once,
coarse to fine with forward and backward sweeps along the rendered motion, so
the paint stays on the surfaces (native/src/methods/tcia/tcia.cpp, docs/engine.md).

Painted keyframes are hard constraints and extra exemplars. Layers
(objects or collections) are solved separately, each with its motion
extrapolated into its background, and composited (native/src/methods/tcia/tcia_layers.cpp).

`ShotJob` runs the method over a guide cache as `tempera stylize --method
tcia` does (native/src/methods/tcia/tcia_job.cpp): the shot in independent segments from
key to key, each resumable (docs/cli.md).
"""
from __future__ import annotations

import numpy as np

from ... import _native
from ...app.segment_job import SegmentJob
from ...engine.synthesis import method_options

TciaOptions = _native.TciaOptions


def options(**values) -> "TciaOptions":
    """TciaOptions from keywords: its own (temporal_weight, coherence_weight,
    coherence_max, sweep_pairs, ribbons, derivative_weight) and engine options (SynthesisOptions names,
    from the method's defaults: 9 x 9 Gaussian window, centre output,
    histogram usage, automatic levels)."""
    return method_options(TciaOptions, _native.tcia_defaults(), values, "coherent-method")


def _image(a):
    a = np.ascontiguousarray(a, dtype=np.float32)
    return a[:, :, None] if a.ndim == 2 else a


def stylize_shot(style, guides, frames, *, keys=(), progress=None, style_orientation=None, **values):
    """The stylized frames of a shot.

    style   the painting Ŝ, (H, W, C)
    guides  [(name, exemplar guide S (H, W, c), weight), ...]
    frames  per frame a dict: guides (the frame's B_g in the same order),
            velocity_backward, velocity_forward ((h, w, 2), pixels, x right,
            y down), occlusion_backward, occlusion_forward ((h, w) χ−, χ+),
            optionally orientation ((h, w) radians, the edge direction: a
            structure tensor's angle or the artist's AOV)
    style_orientation  O(S) (H, W) radians; with the frames' orientations,
            patches are compared rotated, so hatching follows the frames' field
    keys    painted keyframes [(frame index, painting (h, w, C)[, mask (h, w)]), ...]
            in frame order: each comes out as painted and steers its neighbours
    """
    g, f, k = _frames_and_keys(guides, frames, keys)
    report = None if progress is None else (lambda x: progress(x) is not False)
    o = None if style_orientation is None else _image(style_orientation)
    return _native.stylize_shot(_image(style), g, f, k, options(**values), report, o)


def _frames_and_keys(guides, frames, keys):
    g = [(str(n), _image(s), float(w)) for n, s, w in guides]
    f = [{k: ([_image(x) for x in v] if k == "guides" else _image(v)) for k, v in d.items()} for d in frames]
    k = [(int(key[0]), _image(key[1]), None if len(key) < 3 or key[2] is None else _image(key[2])) for key in keys]
    return g, f, k


def stylize_layers(style, guides, frames, layers, *, keys=(), extrapolate=True, progress=None, **values):
    """Each layer of a shot solved alone (Bénard 2013 Figs. 9, 10): its
    velocities and guides extended past its outline from its nearest pixel,
    χ recomputed from them. Arguments as stylize_shot, and

    layers       [(masks, painting or None[, exemplar mask]), ...]: per frame a coverage
                 mask (h, w), the layer's own painting (the style's shape; None = `style`)
                 and optionally its part of the exemplar (> 0.5), the only place its
                 matches may come from
    extrapolate  False keeps the shot's motion (the Fig. 10(c) baseline)

    Returns per layer its frames; tempera.methods.tcia.tcia.composite stacks them."""
    g, f, k = _frames_and_keys(guides, frames, keys)
    spec = []
    for i, (masks, painting, *part) in enumerate(layers):
        part = part[0] if part else None
        spec.append((f"layer {i}", [_image(m) for m in masks], None if painting is None else _image(painting),
                     None if part is None else _image(part)))
    report = None if progress is None else (lambda x: progress(x) is not False)
    return _native.stylize_shot_layers(_image(style), g, f, k, spec, bool(extrapolate), options(**values), report)


def composite(images, masks, depth=None):
    """One frame of layers stacked back to front: in list order, or with
    `depth` (h, w) farthest first by each mask's median depth. The back-most
    is opaque; each next one goes over it with its mask as alpha."""
    return _native.composite_layers([_image(i) for i in images], [_image(m) for m in masks],
                                    None if depth is None else _image(depth))


def segments(frames, key_frames=()):
    """The segments [(first, last), ...] of a shot of consecutive `frames`:
    from key to key and to the shot's ends, by the job core's one rule
    (native/include/tempera/app/segments.hpp), as the job solves them."""
    frames = sorted(int(f) for f in frames)
    return [(first, last) for first, last, _ in _native.key_segments(frames, [int(k) for k in key_frames])]


def _key(key):
    """A TciaKey of (frame, painting path[, mask path or None])."""
    return _native.TciaKey(frame=int(key[0]), painting=key[1], mask=(key[2] or "") if len(key) > 2 else "")


class ShotJob(SegmentJob):
    """The coherent method over a guide cache, segment by segment.

    style, exemplar_guides, exemplar_frame, guides, frames (consecutive), out,
    format, weights ({guide: weight}, the others keep their default), resume: as tempera.methods.stylit.stylize.StylizeJob;
    keys      [(frame, painting path[, mask path]), ...]
    segment   (first, last): only that segment (a farm task)
    lines     {weight, d_max, ink}: the line term of eq. 9 (tcia_job.hpp TciaLineOptions;
              weight > 0 needs the cache's line_distance)
    layers    [(name, mask guide, painting path or None[, keys]), ...]: solved separately
              (frames RGBA in OUT/layers/NAME/) and composited into the frames; keys as
              `keys`, the layer's own, in place of the shot's at their frames (--layer-key)
    layer_order  "depth" (per frame, by the cache's depth) or "given" (first at the back)
    orientation  True: patches turn with the cache's orientation, its `tensor` guide of every
              frame and of the exemplar (tcia_job.hpp TciaOrientationOptions; `--orientation`)
    **values  the method's and engine options (tempera.methods.tcia.tcia.options)

    Construction checks every file, key and guide (FileNotFoundError,
    ValueError). ``run_segment(i)`` for i in ``selected``.
    """

    def __init__(self, style, exemplar_guides, guides, frames, out, *, exemplar_frame=None, keys=(), segment=None,
                 weights=None, format="png", resume=True, lines=None, layers=(), layer_order="depth", orientation=False,
                 **values):
        config = _native.TciaJobConfig(
            exemplar=style, exemplar_guides=exemplar_guides, guides=guides, frames=[int(f) for f in frames], out=out,
            format=format, resume=resume, exemplar_frame=exemplar_frame, weights=dict(weights or {}),
            keys=[_key(k) for k in keys], segment=None if segment is None else (int(segment[0]), int(segment[1])), lines=_native.TciaLineOptions(**dict(lines or {})),
            layers=[_native.TciaLayer(name=l[0], mask=l[1], painting=(l[2] or "") if len(l) > 2 else "",
                                      keys=[_key(k) for k in (l[3] if len(l) > 3 else ())]) for l in layers],
            layer_order=layer_order, orientation=_native.TciaOrientationOptions(from_cache=bool(orientation)))
        self._job = _native.TciaJob(config, options(**values))

    def output_path(self, frame: int) -> str:
        return self._job.output_path(int(frame))

    def layer_path(self, layer: int, frame: int) -> str:
        """Layer `layer`'s RGBA frame (its mask as alpha)."""
        return self._job.layer_path(int(layer), int(frame))

    def run_segment(self, index: int, progress=None) -> dict:
        """Solves segment `index` (or skips it when current) and writes its
        frames. ``progress(dict(level, levels, direction, frame, fraction))``
        after each frame visit; returning False cancels (tempera.Cancelled),
        nothing written. Returns dict(status "stylized" | "skipped", seconds)."""
        report = None if progress is None else (lambda d: progress(d) is not False)
        status, seconds = self._job.run_segment(int(index), report)
        return {"status": status, "seconds": seconds}
