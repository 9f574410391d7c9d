"""Makes docs/images/noisy_user_scene.png: Temporal Noise on a scene made
only with Blender's operators (scenes/noisy_turning_suzanne.py), run from the
panel's operator as blender_tests/test_noisy_user_scene.py runs it. Rows: the
guide cache's render (FULL, 2 samples), the coherent StyLit frames R (bundled kit), Temporal Noise 8 (f = 4.3), and
|frame - next frame| x 3 of each row's first frames (dark = changed).

    blender -b --factory-startup --python docs/make_noisy_user_scene_figure.py -- \
        --addon-zip dist/tempera-addon-0.1.0.zip
"""
import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "tools"), str(ROOT / "scenes")]
import blender_env  # noqa: E402
import noisy_turning_suzanne  # noqa: E402

SIZE = (128, 96)
FRAMES = (3, 7)
SHOWN = (3, 5, 7)
SCALE = 2  # nearest-neighbour, so the texture stays visible


def frame(folder, f):
    import tempera

    return np.asarray(tempera.read_image(str(folder / f"frame_{f:04d}.png")), np.float32)[:, :, :3]


def tile(img):
    return np.repeat(np.repeat(np.clip(img, 0, 1), SCALE, 0), SCALE, 1)


def row(images, gap=6):
    tiles = []
    for img in images:
        tiles += [tile(img), np.ones((img.shape[0] * SCALE, gap, 3), np.float32)]
    return np.concatenate(tiles[:-1], 1)


def make(work):
    import tempera
    from tempera.app import guide_cache
    from tempera.engine.guides import tonemap

    scene = bpy.context.scene
    for o in list(scene.objects):
        bpy.data.objects.remove(o)
    noisy_turning_suzanne.build(scene, SIZE)
    s = scene.tempera
    s.output_dir, s.guide_dir = str(work / "out"), str(work / "guides")
    s.guide_frame_range, (s.guide_frame_start, s.guide_frame_end) = "CUSTOM", FRAMES
    s.guide_samples, s.quality, s.temporal_weight = 2, "preview", 0.5
    s.make_video, s.load_result, s.noise_level = False, "NONE", 8
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    r = [frame(work / "out" / "frames", f) for f in SHOWN]
    t = [frame(work / "out" / "noisy", f) for f in SHOWN]
    diff = [1 - 3 * np.abs(frame(d, SHOWN[0]) - frame(d, SHOWN[0] + 1)).mean(2, keepdims=True).repeat(3, 2)
            for d in (work / "out" / "frames", work / "out" / "noisy")]
    full = [tonemap(guide_cache.read_frame(work / "guides", f, ["FULL"])["FULL"])[:, :, :3] for f in SHOWN]
    rows = [row(full + [np.ones_like(full[0])]), row(r + [diff[0]]), row(t + [diff[1]])]
    gap = np.ones((6, rows[0].shape[1], 3), np.float32)
    sheet = np.concatenate([rows[0], gap, rows[1], gap, rows[2]], 0)
    out = ROOT / "docs" / "images" / "noisy_user_scene.png"
    tempera.write_image(str(out), np.ascontiguousarray(sheet, np.float32))
    print("wrote", out)


def main():
    parser = argparse.ArgumentParser(prog="make_noisy_user_scene_figure.py")
    parser.add_argument("--addon-zip", required=True)
    args = parser.parse_args(blender_env.script_args())
    scripts_dir = blender_env.install_addon_zip(args.addon_zip)
    try:
        with tempfile.TemporaryDirectory() as work:
            make(Path(work))
    finally:
        shutil.rmtree(scripts_dir, ignore_errors=True)


if __name__ == "__main__":
    main()
