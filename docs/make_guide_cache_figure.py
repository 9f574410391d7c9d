#!/usr/bin/env python3
"""Regenerates docs/images/guide_cache_frame.png: every guide of one cached
frame of the demo scene (scenes/demo_scene.py) side by side.

    PYTHONPATH=addon blender -b --factory-startup --python docs/make_guide_cache_figure.py

Renders frames 3-5 at half the demo's resolution into a temporary guide cache
(tempera.blender.guide_render) and shows frame 4. Tiles, left to right:
row 1  FULL, LDE, LSE, LDDE (L.*DDE), LD12E (tone-mapped), alpha, inverse depth, normal;
row 2  velocity forward, velocity backward (x -> red, y -> green, 0 = grey),
       occlusion backward, occlusion forward, orientation (hue = angle from
       the tensor, brightness = edge strength, its trace), lines, line distance,
       object masks (one colour per object).
"""
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "addon"))
import demo_scene  # noqa: E402
import tempera  # noqa: E402
from tempera.app import guide_cache
from tempera.engine import guides  # noqa: E402
from tempera.blender.guide_render import render_guides  # noqa: E402
from tempera.engine.guides import tonemap  # noqa: E402

OUT = ROOT / "docs" / "images" / "guide_cache_frame.png"
FRAME = 4


def gray(a):
    return np.repeat(np.clip(a, 0, 1)[:, :, None], 3, axis=2)


def hsv_to_rgb(h, s, v):
    """h in [0, 1); numpy arrays of one shape."""
    k = (np.stack([5.0, 3.0, 1.0])[None, None, :] + h[:, :, None] * 6) % 6
    return v[:, :, None] - v[:, :, None] * s[:, :, None] * np.clip(np.minimum(k, 4 - k), 0, 1)


def velocity(v, scale):
    return np.dstack([0.5 + v[:, :, 0] / scale, 0.5 + v[:, :, 1] / scale, np.full(v.shape[:2], 0.5)])


def tiles(frame, manifest):
    inverse_depth = np.where(frame["alpha"] > 0.5, 1 / np.maximum(frame["depth"], 1e-6), 0)
    speed = max(np.abs(frame["velocity_forward"]).max(), np.abs(frame["velocity_backward"]).max(), 1e-3)
    angle, _coherence = guides.orientation(frame["tensor"], tensor=True)
    trace = frame["tensor"][:, :, 0] + frame["tensor"][:, :, 2]  # edge strength
    strength = np.sqrt(np.clip(trace / max(np.percentile(trace, 99), 1e-9), 0, 1))
    masks = np.zeros(frame["FULL"].shape, np.float32)
    objects = [g for g, m in manifest["masks"].items() if m["kind"] == "object"]
    for i, guide in enumerate(objects):
        colour = hsv_to_rgb(np.full((1, 1), i / max(len(objects), 1)), np.ones((1, 1)), np.ones((1, 1)))[0, 0]
        masks += frame[guide][:, :, None] * colour
    return [
        [tonemap(frame[g]) for g in ("FULL", "LDE", "LSE", "LDDE", "LD12E")]
        + [gray(frame["alpha"]), gray(inverse_depth / inverse_depth.max()),
           np.clip(0.5 + 0.5 * frame["normal"], 0, 1) * frame["alpha"][:, :, None]],
        [velocity(frame["velocity_forward"], 2 * speed), velocity(frame["velocity_backward"], 2 * speed),
         gray(frame["occlusion_backward"]), gray(frame["occlusion_forward"]),
         hsv_to_rgb(angle / np.pi, np.ones_like(angle), strength),
         gray(1 - frame["lines"]), gray(frame["line_distance"]), masks],
    ]


def grid(rows, gap=4):
    h, w = rows[0][0].shape[:2]
    out = np.ones((len(rows) * (h + gap) - gap, len(rows[0]) * (w + gap) - gap, 3), np.float32)
    for r, row in enumerate(rows):
        for c, tile in enumerate(row):
            out[r * (h + gap):r * (h + gap) + h, c * (w + gap):c * (w + gap) + w] = tile
    return out


def main():
    scene = bpy.data.scenes.new("Guide cache figure")
    demo_scene.build_scene(scene)
    scene.render.resolution_x, scene.render.resolution_y = demo_scene.RESOLUTION
    scene.render.resolution_percentage = 50
    with tempfile.TemporaryDirectory() as tmp:
        render_guides(scene, (FRAME - 1, FRAME, FRAME + 1), tmp, {"samples": 32, "ld12e_samples": 32})
        manifest = guide_cache.read_manifest(tmp)
        frame = guide_cache.read_frame(tmp, FRAME)
    tempera.write_image(str(OUT), grid(tiles(frame, manifest)))
    print(f"wrote {OUT}")


main()
