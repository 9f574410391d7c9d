#!/usr/bin/env python3
"""Thin-stroke retention of Color Me Noisy (docs/noisy.md, "Not done yet"):
the share of R's red-hatching pixels (red above green and blue by 0.15) that
a noisy frame still has, for the default settings and one change at a time.
R is a folder of coherent frames, e.g. the OUT/frames of
blender_tests/test_noisy_user_scene.py or of `make demo`; S is the kit's
painting (make kit).

With --guides (R's guide cache) the last rows are guided noise itself
(noise_guides 0.5 and 1), after a probe of it: StyLit's light-path guides (tonemapped, scaled by
sqrt(weight) and by the probe's scale) appended to S's and R's colour as
further channels, so the search, the MLS warp and the low-frequency term
see them. They are voted like colour and dropped afterwards.

    PYTHONPATH=addon /usr/bin/python3 tools/measure_noisy_thin_strokes.py --reference DIR/frames \
        --guides DIR/guides --frames 3-5
"""
import argparse
from pathlib import Path

import numpy as np

import tempera
from tempera.app import guide_cache
from tempera.methods.noisy import noisy
from tempera.app.settings import DEFAULT_GUIDE_WEIGHTS
from tempera.engine.guides import tonemap

ROOT = Path(__file__).resolve().parent.parent
PAINTING = ROOT / "build" / "kit" / "sphere_on_table" / "style.png"
KIT_GUIDES = ROOT / "build" / "kit" / "sphere_on_table" / "guides"
PROBE_SCALES = (0.5, 1.0)
GUIDED_NOISE = (0.5, 1.0)  # noise_guides rows
VARIANTS = [("default (f = 2.2)", {}), ("f = 1.01 (finest level only)", dict(noise=1.01)),
            ("f = 4.3", dict(noise=4.3)), ("no MLS", dict(deform=False)), ("consistency 0", dict(consistency=0.0)),
            ("consistency 8", dict(consistency=8.0)), ("patch 5", dict(patch_size=5)),
            ("patch 3", dict(patch_size=3)), ("centre vote", dict(output="centre"))]


def red(image):
    image = np.asarray(image, np.float32)
    return (image[:, :, 0] > image[:, :, 1] + 0.15) & (image[:, :, 0] > image[:, :, 2] + 0.15)


def rgb(path):
    return np.ascontiguousarray(np.asarray(tempera.read_image(str(path)), np.float32)[:, :, :3])


def light_path_stack(folder, frame):
    """The frame's light-path guides (StyLit's default weights > 0) as one
    image: tonemapped, each scaled by sqrt(weight) (squared distances add up
    as StyLit's weighted guide terms do)."""
    names = [n for n, w in DEFAULT_GUIDE_WEIGHTS.items() if w > 0]
    g = guide_cache.read_frame(str(folder), frame, names)
    return np.concatenate([tonemap(g[n]).reshape(g[n].shape[0], g[n].shape[1], -1)[:, :, :3]
                           * np.sqrt(DEFAULT_GUIDE_WEIGHTS[n]) for n in names], 2)


def light_path_guides(folder, frame):
    """{name: tonemapped guide} of StyLit's default guides, for guided noise."""
    names = [n for n, w in DEFAULT_GUIDE_WEIGHTS.items() if w > 0]
    g = guide_cache.read_frame(str(folder), frame, names)
    return {n: np.ascontiguousarray(tonemap(g[n]).reshape(g[n].shape[0], g[n].shape[1], -1)[:, :, :3]) for n in names}


def with_guides(image, guides, scale):
    return np.ascontiguousarray(np.concatenate([image, scale * guides], 2), np.float32)


def main():
    parser = argparse.ArgumentParser(prog="measure_noisy_thin_strokes.py")
    parser.add_argument("--reference", required=True, type=Path)
    parser.add_argument("--frames", required=True, help="A-B")
    parser.add_argument("--exemplar", type=Path, default=PAINTING)
    parser.add_argument("--guides", type=Path, help="R's guide cache: also run the guided-noise probe")
    parser.add_argument("--exemplar-guides", type=Path, default=KIT_GUIDES)
    args = parser.parse_args()
    first, last = map(int, args.frames.split("-"))
    frames = range(first, last + 1)
    style = rgb(args.exemplar)
    references = {f: rgb(args.reference / f"frame_{f:04d}.png") for f in frames}
    strokes = sum(int(red(r).sum()) for r in references.values())
    print(f"R: {strokes / sum(red(r).size for r in references.values()):.4f} of the pixels are red hatching; "
          f"S: {red(style).mean():.4f}")
    for label, values in VARIANTS:
        options = {"noise": 2.2, "threads": 2, **values}
        kept = sum(int(red(noisy.noisy_frame(style, references[f], f, **options)).sum()) for f in frames)
        print(f"{label:30s} red kept {kept / strokes:.2f}")
    if args.guides:
        exemplar_frame = int(sorted(args.exemplar_guides.glob("frame_*.exr"))[0].stem[-4:])
        style_guides = light_path_stack(args.exemplar_guides, exemplar_frame)
        for scale in PROBE_SCALES:
            kept = 0
            for f in frames:
                r = with_guides(references[f], light_path_stack(args.guides, f), scale)
                t = noisy.noisy_frame(with_guides(style, style_guides, scale), r, f, noise=2.2, threads=2)
                kept += int(red(t[:, :, :3]).sum())
            print(f"{'probe: guides x ' + str(scale):30s} red kept {kept / strokes:.2f}")
        source = light_path_guides(args.exemplar_guides, exemplar_frame)
        for weight in GUIDED_NOISE:  # the implementation: noise_guides
            kept = 0
            for f in frames:
                target = light_path_guides(args.guides, f)
                guides = {n: (source[n], target[n], DEFAULT_GUIDE_WEIGHTS[n]) for n in source}
                t = noisy.noisy_frame(style, references[f], f, noise=2.2, threads=2, noise_guides=weight, guides=guides)
                kept += int(red(t).sum())
            print(f"{'guided noise ' + str(weight):30s} red kept {kept / strokes:.2f}")


if __name__ == "__main__":
    main()
