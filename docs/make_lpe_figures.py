#!/usr/bin/env python3
"""Regenerates docs/images/lpe_side_by_side.png: Cycles' light-path guides
above the same paths from Tempera's tracer, for one small scene
(scenes/lpe_scene.py: a mirror sphere lit by a disk light from the side).

    PYTHONPATH=addon blender -b --factory-startup --python docs/make_lpe_figures.py

Both come from one render_guides run (tempera.blender.guide_render), 256
samples each. Tiles, tone-mapped with tempera.engine.guides.tonemap:
row 1 (Cycles)  FULL, DiffDir x DiffCol, GlossDir x GlossCol, DiffInd x DiffCol
                (caustics off), and an empty tile: Cycles cannot isolate caustics;
row 2 (tracer)  L.*E, LDE, LSE, L.*DDE, LS+DE (caustics, x 4 to be visible).
"""
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "addon"))
import lpe_scene  # noqa: E402
import tempera  # noqa: E402
from tempera.app import guide_cache  # noqa: E402
from tempera.blender.guide_render import render_guides  # noqa: E402
from tempera.engine.guides import tonemap  # noqa: E402

OUT = ROOT / "docs" / "images" / "lpe_side_by_side.png"
SIZE = (192, 144)
SAMPLES = 256
CAUSTIC_GAIN = 4.0
EXPRESSIONS = ["L.*E", "LDE", "LSE", "L.*DDE", "LS+DE"]


def main():
    scene = lpe_scene.build_scene("LPE figure", SIZE, sphere="mirror", light="CAUSTIC")
    with tempfile.TemporaryDirectory() as tmp:
        report = render_guides(scene, [1], tmp, {"samples": SAMPLES, "ld12e_samples": 1, "masks": "none",
                                                 "lpe": EXPRESSIONS, "lpe_samples": SAMPLES})
        frame = guide_cache.read_frame(tmp, 1)
    for warning in report["warnings"]:
        print(f"warning: {warning}")
    traced = [frame[guide_cache.lpe_guide(e)] for e in EXPRESSIONS]
    traced[-1] = traced[-1] * CAUSTIC_GAIN
    empty = np.full((SIZE[1], SIZE[0], 3), 0.2, np.float32)  # no Cycles pass holds the caustics alone
    tiles = [tonemap(frame[g]) for g in ("FULL", "LDE", "LSE", "LDDE")] + [empty] + [tonemap(t) for t in traced]
    sheet = tempera.contact_sheet(tiles, columns=5, gap=4, margin=4, background=1.0)
    tempera.write_image(str(OUT), sheet.astype(np.float32))
    print(f"wrote {OUT}")


main()
