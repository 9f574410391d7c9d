#!/usr/bin/env python3
"""Seconds per frame of the rigid-body method (tempera.methods.rigid.rigid, Dvorožňák
2017) at the demo's 640 x 360 and at 1280 x 720: fitting the drawn exemplar
(per drawn frame), matching and blending the deformations (the whole target
track), and making the RGBA frames of one object (per target frame).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_rigid.py --json docs/bench_rigid.json

The exemplar is the demo's generated thrown ball (60 drawn frames); the
target another thrown ball of 96 frames, its radius scaled with the frame.
Results in docs/benchmarks.md."""
import argparse
import json
import os
import platform
import time

from tempera import _native
from tempera.methods.rigid import rigid

SIZES = {"640 x 360": (640, 360), "1280 x 720": (1280, 720)}
TARGET_FRAMES = 96


def _timed(fn):
    started = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", help="write the results here")
    args = parser.parse_args()
    rows = []
    for name, (w, h) in SIZES.items():
        s = w / 640  # the demo's scene, scaled
        source = _native.bouncing_ball((60 * s, 60 * s), (5.0 * s, 0), 20 * s, 1.0 * s, h - 30 * s, 0.65, 0.05, 60)
        target = _native.bouncing_ball((500 * s, 40 * s), (-4.0 * s, 0), 18 * s, 0.9 * s, h - 20 * s, 0.7, -0.04,
                                       TARGET_FRAMES)
        drawings = rigid.generated_exemplar(source, w, h)
        exemplar, fit = _timed(lambda: rigid.fit_exemplar(source, drawings))
        _, match = _timed(lambda: rigid.deformations([exemplar], target))
        _, frames = _timed(lambda: rigid.stylize([exemplar], target, w, h))
        rows.append({"size": name, "width": w, "height": h, "drawn_frames": len(drawings),
                     "target_frames": TARGET_FRAMES, "fit_seconds_per_drawn_frame": round(fit / len(drawings), 3),
                     "match_seconds": round(match, 3), "seconds_per_frame": round(frames / TARGET_FRAMES, 3)})
        r = rows[-1]
        print(f"{name}: fit {r['fit_seconds_per_drawn_frame']} s per drawn frame, matching {r['match_seconds']} s "
              f"for {TARGET_FRAMES} frames, stylize {r['seconds_per_frame']} s per frame (one object)", flush=True)
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"machine": f"{platform.platform()}, {os.cpu_count()} cores", "results": rows}, out, indent=1)


if __name__ == "__main__":
    main()
