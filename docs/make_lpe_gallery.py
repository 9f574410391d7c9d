"""Regenerates docs/images/lpe_gallery.png and docs/lpe_gallery.json (Blender
3.x; other Blenders write lpe_gallery_X.Y.png and lpe_gallery_X.Y.json): every
scene of the validation gallery (scenes/lpe_gallery.py) rendered by Cycles
and traced by Tempera at the test's settings (blender_tests/test_lpe_gallery.py:
80 x 60, 128 samples each but the test's SCENE_SAMPLES, caustics off), with the test's figures.

    PYTHONPATH=addon blender -b --factory-startup --python docs/make_lpe_gallery.py
    PYTHONPATH=addon ~/.cache/tempera/venv-bpy45/bin/python docs/make_lpe_gallery.py  # PyPI bpy 4.5

One row per scene; columns: FULL, LDE, LSE, L.*DDE, each as Cycles then the
tracer, every buffer scaled by the same gain in both (its Cycles 99th
percentile to 0.8), sRGB-encoded.
"""
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "blender_tests"))

import bpy  # noqa: E402  (before the scene scripts: PyPI's bpy provides bmesh once imported)
import lpe_gallery  # noqa: E402
import tempera  # noqa: E402
import test_lpe_gallery as gallery  # noqa: E402
from tempera.engine.color import linear_to_srgb  # noqa: E402

_SUFFIX = "" if bpy.app.version < (4, 0, 0) else "_{}.{}".format(*bpy.app.version[:2])
OUT = ROOT / "docs" / "images" / f"lpe_gallery{_SUFFIX}.png"
FIGURES = ROOT / "docs" / f"lpe_gallery{_SUFFIX}.json"


def show(image, gain):
    return linear_to_srgb(np.clip(np.nan_to_num(image) * gain, 0, 1)).astype(np.float32)


def main():
    tiles, figures = [], {}
    for key in lpe_gallery.SCENES:
        scene = lpe_gallery.build(key)
        try:
            with tempfile.TemporaryDirectory() as tmp:
                cycles = gallery.cycles_buffers(scene, tmp, gallery.samples_for(key))
            traced, warnings = gallery.traced_buffers(scene, gallery.samples_for(key))
        finally:
            lpe_gallery.remove(scene)
        result, _ = gallery.gallery_figures(cycles, traced)
        figures[key] = {b: {"mean_error": e, "correlation": c, "cycles_mean": r, "tracer_mean": t}
                        for b, (e, c, r, t) in result.items()}
        figures[key]["warnings"] = warnings
        for buffer in gallery.BUFFERS:
            lum = cycles[buffer] @ gallery.LUMINANCE
            p99 = float(np.percentile(lum, 99))
            gain = 0.8 / p99 if p99 > 0 else 1.0
            tiles += [show(cycles[buffer], gain), show(traced[buffer], gain)]
        print(key, {b: (round(v["mean_error"], 4) if v["mean_error"] is not None else None,
                        round(v["correlation"], 4) if v["correlation"] is not None else None)
                    for b, v in figures[key].items() if b != "warnings"})
    sheet = tempera.contact_sheet(tiles, columns=8, gap=2, margin=2, background=1.0)
    tempera.write_image(str(OUT), sheet.astype(np.float32))
    FIGURES.write_text(json.dumps(figures, indent=1) + "\n")
    print(f"wrote {OUT} and {FIGURES}")


main()
