"""Noise of the tracer's guides against Cycles' at the guide samples.

    PYTHONPATH=addon blender -b --factory-startup --python bench/bench_lpe_noise.py -- \
        [--cycles-samples 16] [--json docs/bench_lpe_noise.json]

For scenes of the validation gallery (scenes/lpe_gallery.py, 80 x 60), each
buffer's noise is the RMS difference of two renders with different seeds,
divided by sqrt(2) and by the buffer's mean, over the pixels Cycles sees
geometry in (alpha > 0.99), unblurred. Cycles renders at the guide cache's
samples (16 by default, guide_cache.DEFAULT_PARAMS["samples"]); the tracer at
8 ... 512 samples. Reported per buffer: the smallest tried sample count at
which the tracer is no noisier than Cycles, and the count a 1/sqrt(samples)
fit from 64 samples predicts.
"""
import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "blender_tests"))

import lpe_gallery  # noqa: E402
import test_lpe_gallery as gallery  # noqa: E402

SCENES = ["public_style", "mix_glossy_diffuse", "area_shapes", "hdri"]
TRACER_SAMPLES = [8, 16, 32, 64, 128, 256, 512]


def noise(a, b, mask):
    la, lb = a @ gallery.LUMINANCE, b @ gallery.LUMINANCE
    mean = 0.5 * (la[mask].mean() + lb[mask].mean())
    if mean <= 0:
        return None
    return float(np.sqrt(np.mean((la[mask] - lb[mask]) ** 2) / 2) / mean)


def traced(scene, samples, seed):
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene, path_settings
    from tempera.tracer.lpe import trace_lpe

    size = (scene.render.resolution_x, scene.render.resolution_y)
    scene_dict, _ = export_scene(scene, evaluated_depsgraph(scene, scene.view_layers[0], 1), size)
    images, _ = trace_lpe(scene_dict, list(gallery.BUFFERS.values()), samples=samples, seed=seed,
                          **path_settings(scene))
    return dict(zip(gallery.BUFFERS, images))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="bench_lpe_noise.py")
    parser.add_argument("--cycles-samples", type=int, default=16)
    parser.add_argument("--json", default=str(ROOT / "docs" / "bench_lpe_noise.json"))
    args = parser.parse_args(argv)
    results = {}
    for key in SCENES:
        scene = lpe_gallery.build(key)
        try:
            with tempfile.TemporaryDirectory() as tmp:
                runs = []
                for seed in (0, 1):
                    scene.cycles.seed = seed
                    from tempera.blender import guide_render
                    layer = scene.view_layers[0]
                    guide_render._configure(scene, layer, args.cycles_samples, gallery.PASSES, seed)
                    path = guide_render._render(scene, Path(tmp) / f"{key}_{seed}.exr", 1)
                    p = guide_render._read_passes(path, layer.name, gallery.PASSES)
                    rgb = {k: v[:, :, :3] for k, v in p.items()}
                    runs.append({"FULL": rgb["Combined"], "LDE": rgb["DiffDir"] * rgb["DiffCol"],
                                 "LSE": rgb["GlossDir"] * rgb["GlossCol"], "LDDE": rgb["DiffInd"] * rgb["DiffCol"],
                                 "alpha": p["Combined"][:, :, 3]})
            mask = runs[0]["alpha"] > 0.99
            cycles_noise = {b: noise(runs[0][b], runs[1][b], mask) for b in gallery.BUFFERS}
            tracer_noise, seconds = {b: {} for b in gallery.BUFFERS}, {}
            for samples in TRACER_SAMPLES:
                start = time.perf_counter()
                a = traced(scene, samples, 0)
                seconds[samples] = time.perf_counter() - start
                b = traced(scene, samples, 1)
                for buffer in gallery.BUFFERS:
                    tracer_noise[buffer][samples] = noise(a[buffer], b[buffer], mask)
        finally:
            lpe_gallery.remove(scene)
        scene_result = {"cycles_samples": args.cycles_samples, "trace_seconds": seconds, "buffers": {}}
        for buffer in gallery.BUFFERS:
            target, curve = cycles_noise[buffer], tracer_noise[buffer]
            if target is None or curve.get(64) is None:
                scene_result["buffers"][buffer] = None
                continue
            reached = next((s for s in TRACER_SAMPLES if curve[s] is not None and curve[s] <= target), None)
            fitted = 64 * (curve[64] / target) ** 2
            scene_result["buffers"][buffer] = {"cycles_noise": target, "tracer_noise": curve,
                                               "matched_samples": reached, "fitted_samples": fitted}
            print(f"{key} {buffer}: Cycles {args.cycles_samples} spp noise {target:.3f}; tracer reaches it at "
                  f"{reached} spp (fit {fitted:.0f}); tracer noise at 64 spp {curve[64]:.3f}")
        results[key] = scene_result
    Path(args.json).write_text(json.dumps(results, indent=1) + "\n")
    print(f"wrote {args.json}")


main()
