"""Scatter over seeds of a gallery scene's buffer mean, Cycles against the tracer.

    PYTHONPATH=addon blender -b --factory-startup --python bench/bench_lpe_mean_scatter.py -- \\
        layer_weight [--buffer LSE] [--samples 128] [--seeds 4] [--converged 4096] [--json out.json]
    PYTHONPATH=addon ~/.cache/tempera/venv-bpy42/bin/python bench/bench_lpe_mean_scatter.py layer_weight

A gallery scene (scenes/lpe_gallery.py) is rendered by Cycles and traced at
`--samples` with seeds 0 .. seeds-1, and once at `--converged` samples (seed
0). For each renderer: the buffer's mean luminance over the pixels Cycles
sees geometry in (as blender_tests/test_lpe_gallery.py measures it), its
relative scatter over the seeds, and the share of the buffer's light in its
brightest pixel at the converged count. A highlight smaller than a pixel shows
as a large scatter at the gallery's samples with converged means that agree.
"""
import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "scenes"), str(ROOT / "blender_tests")]

import bpy  # noqa: E402  (before the scene scripts: PyPI's bpy provides bmesh once imported)
import lpe_gallery  # noqa: E402
import test_lpe_gallery as gallery  # noqa: E402


def summary(means, converged, converged_image):
    means = np.asarray(means)
    return {"means": means.tolist(), "scatter": float(means.std(ddof=1) / means.mean()) if len(means) > 1 else None,
            "converged": converged, "brightest_pixel_share": float(converged_image.max() / converged_image.sum())}


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(prog="bench_lpe_mean_scatter.py")
    parser.add_argument("scene", choices=list(lpe_gallery.SCENES))
    parser.add_argument("--buffer", default="LSE", choices=list(gallery.BUFFERS))
    parser.add_argument("--samples", type=int, default=gallery.SAMPLES)
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--converged", type=int, default=4096)
    parser.add_argument("--json")
    args = parser.parse_args(argv)

    scene = lpe_gallery.build(args.scene)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            cycles = [gallery.cycles_buffers(scene, tmp, args.samples, seed) for seed in range(args.seeds)]
            reference = gallery.cycles_buffers(scene, tmp, args.converged)
        # After Cycles' render set-up (caustics off, as Cycles rendered), as the test traces.
        traced = [gallery.traced_buffers(scene, args.samples, seed)[0] for seed in range(args.seeds)]
        traced_reference = gallery.traced_buffers(scene, args.converged)[0]
    finally:
        lpe_gallery.remove(scene)
    mask = reference["alpha"] > 0.99

    def lum(buffers):
        return buffers[args.buffer] @ gallery.LUMINANCE * mask

    def mean(buffers):
        return float(lum(buffers)[mask].mean())

    result = {"blender": bpy.app.version_string, "scene": args.scene, "buffer": args.buffer,
              "samples": args.samples, "converged_samples": args.converged,
              "cycles": summary([mean(b) for b in cycles], mean(reference), lum(reference)),
              "tracer": summary([mean(b) for b in traced], mean(traced_reference), lum(traced_reference))}
    result["converged_error"] = abs(result["tracer"]["converged"] / result["cycles"]["converged"] - 1)
    print(json.dumps(result, indent=1))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1) + "\n")


main()
