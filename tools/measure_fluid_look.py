#!/usr/bin/env python3
"""How painted the fluid demos look, in numbers (docs/media_exemplars.md):

    PYTHONPATH=addon /usr/bin/python3 tools/measure_fluid_look.py --out out/demo-fluids

* chimney: the smoke's alpha-weighted contrast against the sky, the mean
  |composite - plate| luma over the stylized frames' alpha > 0.1, and the
  local contrast (std of luma minus its 5x5 mean) inside the smoke
  (alpha > 0.5), beside the exemplar's;
* ink: the local contrast inside the blot (alpha > 0.5, 3 px in from its
  edge) and the rim's darkening (mean luma 3 px deep over the luma of the
  inside, < 1 = a darker rim), the output's beside the exemplar's.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "addon"))
from tempera import read_image  # noqa: E402

LUMA = np.array([0.2126, 0.7152, 0.0722])


def _box(a, r):
    p = np.pad(a, r, mode="edge")
    h, w = a.shape
    return sum(p[dy:dy + h, dx:dx + w] for dy in range(2 * r + 1) for dx in range(2 * r + 1)) / (2 * r + 1) ** 2


def _erode(mask, r):
    return _box(mask.astype(np.float64), r) > 0.999


def local_contrast(luma, mask):
    return float((luma - _box(luma, 2))[mask].std()) if mask.any() else 0.0


def _frames(folder, pattern="frame_*.png"):
    return [read_image(str(p)) for p in sorted(Path(folder).glob(pattern))]


def chimney(out):
    over, plate = _frames(out / "chimney/lazyfluids/frames"), _frames(out / "chimney/plate")
    comp = _frames(out / "chimney/composite")
    contrast, local = [], []
    for o, p, c in zip(over, plate, comp):
        a = o[..., 3]
        diff = np.abs((c[..., :3] - p[..., :3]) @ LUMA)
        contrast.append(float((diff * a)[a > 0.1].sum() / a[a > 0.1].sum()))
        local.append(local_contrast(o[..., :3] @ LUMA, a > 0.5))
    ex = [local_contrast(e[..., :3] @ LUMA, e[..., 3] > 0.5) for e in _frames(out / "exemplars/smoke")]
    return {"smoke vs sky contrast": np.mean(contrast), "smoke local contrast": np.mean(local),
            "exemplar local contrast": np.mean(ex)}


def _ink(rgb, mask):
    luma = rgb[..., :3] @ LUMA
    inside = _erode(mask, 3)
    rim = mask & ~inside
    return local_contrast(luma, inside), float(luma[rim].mean() / luma[inside].mean()) if inside.any() else 1.0


def ink(out):
    frames = _frames(out / "ink/fluidymation/frames")
    got = [_ink(f, f[..., 3] > 0.5) for f in frames[len(frames) // 2:]]
    masks = _frames(out / "exemplars/ink/masks")
    ex = [_ink(e, m[..., 0] > 0.5) for e, m in list(zip(_frames(out / "exemplars/ink"), masks))[len(masks) // 2:]]
    return {"ink local contrast": np.mean([g[0] for g in got]), "ink rim/inside luma": np.mean([g[1] for g in got]),
            "exemplar local contrast": np.mean([e[0] for e in ex]),
            "exemplar rim/inside luma": np.mean([e[1] for e in ex])}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="the demo's output folder (make demo-fluids)")
    out = Path(parser.parse_args(argv).out)
    for name, values in (("chimney", chimney(out)), ("ink", ink(out))):
        print(name + ": " + ", ".join(f"{k} {v:.3f}" for k, v in values.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
