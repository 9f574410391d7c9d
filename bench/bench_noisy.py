#!/usr/bin/env python3
"""Seconds per frame of Color Me Noisy (tempera.noisy.noisy_frame) at 0.25
and 1 Mpix, for the calm and the lively end of the slider (f = 2.2, 4.3).
The paper: about 30 s per Mpix on one core of a 3.5 GHz Xeon (§4).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_noisy.py --json docs/bench_noisy.json

The exemplar is a synthetic grain medium 1.25x the frame's sides; R is a
crop of it (as a texture synthesis makes R out of S). Results in
docs/benchmarks.md."""
import argparse
import json
import os
import platform
import time

import numpy as np

from tempera import noisy

SIZES = {"0.25 Mpix": (576, 432), "1 Mpix": (1152, 864)}


def medium(rng, h, w):
    n = rng.random((h, w, 3)).astype(np.float32)
    for _ in range(2):
        n = sum(np.roll(np.roll(n, a, 0), b, 1) for a in (-1, 0, 1) for b in (-1, 0, 1)) / 9
    return np.clip(0.5 + 2.5 * (n - 0.5), 0, 1).astype(np.float32)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", help="write the results here")
    parser.add_argument("--widths", default="2.2,4.3")
    parser.add_argument("--threads", type=int, default=0, help="0 = all cores")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    rows = []
    for name, (w, h) in SIZES.items():
        style = medium(rng, int(h * 1.25), int(w * 1.25))
        reference = np.ascontiguousarray(style[: h, : w])
        for f in map(float, args.widths.split(",")):
            started = time.perf_counter()
            noisy.noisy_frame(style, reference, 1, noise=f, threads=args.threads)
            seconds = time.perf_counter() - started
            rows.append({"size": name, "width": w, "height": h, "noise": f, "seconds_per_frame": round(seconds, 2),
                         "seconds_per_mpix": round(seconds / (w * h / 1e6), 2)})
            print(f"{name} ({w}x{h}), f = {f}: {seconds:.1f} s per frame ({rows[-1]['seconds_per_mpix']} s/Mpix)",
                  flush=True)
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"machine": f"{platform.platform()}, {os.cpu_count()} cores", "threads": args.threads,
                       "results": rows}, out, indent=1)


if __name__ == "__main__":
    main()
