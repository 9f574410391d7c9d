#!/usr/bin/env python3
"""Regenerates the pictures of docs/rigid_bodies.md from the generated
exemplar (no Blender):

    PYTHONPATH=addon /usr/bin/python3 docs/make_rigid_figures.py

rigid_exemplar.png  source frames 10-18 around the first bounce: the proxy
                    (grey) and the generated drawing (graphite);
rigid_residual.png  one squashed frame: the drawing f^e, its residual
                    f^r = D^-1(f^e), D applied to f^r again;
rigid_transfer.png  target frames around two bounces: the output (graphite)
                    over the oracle's outline (D_gen of the target, red);
rigid_onion.png     the whole target sequence, every second frame, on paper;
rigid_strokes.png   stroke re-synthesis (tempera.methods.rigid.rigid_strokes): the drawn
                    line, the stroke exemplar, the line re-made on the
                    stroke-position guide, and the same with the guide off.

With --demo DIR (the output of `make demo-rigid`, out/demo-rigid) it
makes rigid_demo.png only: demo frames 20, 40, 60, the output (top) and
the oracle (bottom), at half size.

docs/make_rigid_user_scene_figure.py makes rigid_user_scene.png (Blender).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
from tempera import _native
from tempera.methods.rigid import rigid, rigid_strokes  # noqa: E402

W, H = 320, 200
OUT = ROOT / "docs" / "images"


def over_paper(rgba, paper=(0.97, 0.96, 0.92)):
    a = rgba[:, :, 3:4]
    return rgba[:, :, :3] * a + np.asarray(paper, np.float32) * (1 - a)


def tint(mask, colour, base):
    m = mask[:, :, :1] if mask.ndim == 3 else mask[:, :, None]
    return base * (1 - m) + np.asarray(colour, np.float32) * m


def crop(img, centre, half=40):
    x, y = int(round(centre[0])), int(round(centre[1]))
    padded = np.pad(img, ((half, half), (half, half), (0, 0)), mode="edge")
    return padded[y:y + 2 * half, x:x + 2 * half]


def oracle_outline(track, f, D):
    """The target's proxy circle through D_gen, as a thin red ink mask."""
    c, r = np.asarray(track["centre"][f]), track["radius"][f]
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    u = np.stack([np.cos(t), np.sin(t)], 1)
    mono = np.stack([u[:, 0], u[:, 1], u[:, 0] ** 2, u[:, 1] ** 2, u[:, 0] * u[:, 1], np.ones(len(t))], 1)
    p = c + r * (mono @ np.asarray(D).T)
    mask = np.zeros((H, W), np.float32)
    ix, iy = np.clip(np.round(p[:, 0]).astype(int), 0, W - 1), np.clip(np.round(p[:, 1]).astype(int), 0, H - 1)
    mask[iy, ix] = 1
    return mask


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    source_track = _native.bouncing_ball((40, 50), (4.5, 0), 18, 1.2, 180, 0.6, 0.05, 48)
    drawings = rigid.generated_exemplar(source_track, W, H)
    source = rigid.fit_exemplar(source_track, drawings)
    tiles = []
    for f in range(10, 19):
        proxy = _native.proxy_mask(source_track, f, "circle", W, H)
        base = tint(proxy * 0.35, (0.6, 0.6, 0.6), np.full((H, W, 3), 0.97, np.float32))
        a = drawings[f][:, :, 3:4]
        img = drawings[f][:, :, :3] * a + base * (1 - a)
        tiles.append(crop(img, source_track["centre"][f]))
    _native.write_image(str(OUT / "rigid_exemplar.png"), np.concatenate(tiles, 1).astype(np.float32), [])

    f = source_track["events"][0]["frame"]
    c = source_track["centre"][f]
    residual = source[2][f]
    # D applied to f^r again: the self-reproduction of that frame.
    recon = rigid.stylize([source], source_track, W, H, k=1, augment=False)[f][0]
    row = [crop(over_paper(x), c) for x in (drawings[f], residual, recon)]
    _native.write_image(str(OUT / "rigid_residual.png"), np.concatenate(row, 1).astype(np.float32), [])

    target = _native.bouncing_ball((290, 30), (-3.5, 1), 16, 1.0, 185, 0.7, -0.08, 64)
    frames = rigid.stylize([source], target, W, H)
    oracle = rigid.oracle_maps(target)
    tiles = []
    for e in target["events"][:2]:
        for g in range(e["frame"] - 3, e["frame"] + 4):
            img = tint(oracle_outline(target, g, oracle[g]), (0.85, 0.1, 0.1), over_paper(frames[g][0]))
            tiles.append(crop(img, target["centre"][g]))
    strip = np.concatenate([np.concatenate(tiles[:7], 1), np.concatenate(tiles[7:14], 1)], 0)
    _native.write_image(str(OUT / "rigid_transfer.png"), strip.astype(np.float32), [])

    onion = np.zeros((H, W, 4), np.float32)
    for g in range(0, len(frames), 2):
        rgba = frames[g][0]
        onion[:, :, :3] = rgba[:, :, :3] * rgba[:, :, 3:4] + onion[:, :, :3] * (1 - rgba[:, :, 3:4])
        onion[:, :, 3] = np.maximum(onion[:, :, 3], rgba[:, :, 3])
    img = over_paper(onion)
    img[185:187, :, :] = 0.3  # the floor
    _native.write_image(str(OUT / "rigid_onion.png"), img.astype(np.float32), [])
    strokes_figure(frames[target["events"][0]["frame"]][0], target["centre"][target["events"][0]["frame"]])
    print("wrote", ", ".join(p.name for p in sorted(OUT.glob("rigid_*.png"))))


def strokes_figure(drawn, centre):
    exemplar = rigid_strokes.generated_stroke_exemplar()
    made = rigid_strokes.resynthesize(drawn, exemplar)
    unguided = rigid_strokes.resynthesize(drawn, exemplar, weight=0)
    big = lambda img: np.repeat(np.repeat(img, 2, 0), 2, 1)  # noqa: E731
    tiles = [big(crop(over_paper(x), centre)) for x in (drawn, made, unguided)]
    ex = over_paper(exemplar)[:160, :160]
    strip = np.concatenate([tiles[0], ex, tiles[1], tiles[2]], 1)
    _native.write_image(str(OUT / "rigid_strokes.png"), strip.astype(np.float32), [])


def demo_figure(folder):
    half = lambda img: img[::2, ::2, :3]  # noqa: E731
    read = lambda name: np.asarray(_native.read_image(str(Path(folder) / name), None), np.float32)  # noqa: E731
    rows = [np.concatenate([half(read(f"{kind}_{f:04d}.png")) for f in (20, 40, 60)], 1)
            for kind in ("frame", "oracle")]
    _native.write_image(str(OUT / "rigid_demo.png"), np.ascontiguousarray(np.concatenate(rows, 0)), [])
    print("wrote rigid_demo.png")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="the pictures of docs/rigid_bodies.md")
    parser.add_argument("--demo", help="make rigid_demo.png from this `make demo-rigid` output folder")
    args = parser.parse_args()
    demo_figure(args.demo) if args.demo else main()
