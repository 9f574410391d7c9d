#!/usr/bin/env python3
"""Seconds per frame of Color Me Noisy (tempera.methods.noisy.noisy.noisy_frame) at 0.25
and 1 Mpix, for the calm and the lively end of the slider (f = 2.2, 4.3).
The paper: about 30 s per Mpix on one core of a 3.5 GHz Xeon (§4).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_noisy.py --json docs/bench_noisy.json
    PYTHONPATH=addon /usr/bin/python3 bench/bench_noisy.py --compare main --json docs/bench_noisy.json

With --compare REV it builds REV's native module in a temporary worktree
(bench_synthesis.build_revision) and runs REV and this checkout on the same
inputs one after the other, per size and width, so both see the same load.

The exemplar is a synthetic grain medium 1.25x the frame's sides; R is a
crop of it (as a texture synthesis makes R out of S). Results in
docs/benchmarks.md."""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SIZES = {"0.25 Mpix": (576, 432), "1 Mpix": (1152, 864)}


def medium(rng, h, w):
    n = rng.random((h, w, 3)).astype(np.float32)
    for _ in range(2):
        n = sum(np.roll(np.roll(n, a, 0), b, 1) for a in (-1, 0, 1) for b in (-1, 0, 1)) / 9
    return np.clip(0.5 + 2.5 * (n - 0.5), 0, 1).astype(np.float32)


def run_one(size, f, threads):
    """One frame of one size and width: wall and CPU seconds."""
    from tempera.methods.noisy import noisy

    w, h = SIZES[size]
    rng = np.random.default_rng(1)
    style = medium(rng, int(h * 1.25), int(w * 1.25))
    reference = np.ascontiguousarray(style[: h, : w])
    started, cpu = time.perf_counter(), time.process_time()
    noisy.noisy_frame(style, reference, 1, noise=f, threads=threads)
    seconds, cpu = time.perf_counter() - started, time.process_time() - cpu
    return {"size": size, "width": w, "height": h, "noise": f, "threads": threads,
            "seconds_per_frame": round(seconds, 2), "cpu_seconds": round(cpu, 2),
            "seconds_per_mpix": round(seconds / (w * h / 1e6), 2)}


def child(addon, size, f, threads):
    """run_one in a fresh interpreter that imports tempera from `addon`."""
    code = (f"import json, sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import bench_noisy; "
            f"print(json.dumps(bench_noisy.run_one({size!r}, {f!r}, {threads!r})))")
    env = dict(os.environ, PYTHONPATH=str(addon))
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", help="write the results here")
    parser.add_argument("--widths", default="2.2,4.3")
    parser.add_argument("--sizes", default=",".join(SIZES), help="comma-separated: " + ", ".join(SIZES))
    parser.add_argument("--threads", type=int, default=0, help="0 = all cores")
    parser.add_argument("--compare", metavar="REV", help="also run git revision REV, alternating with this one")
    args = parser.parse_args()
    root = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory(prefix="tempera-bench-noisy-") as tmp:
        builds = {"this": root / "addon"}
        if args.compare:
            from bench_synthesis import build_revision

            builds[args.compare] = build_revision(args.compare, Path(tmp))
        rows = []
        try:
            for size in args.sizes.split(","):
                for f in map(float, args.widths.split(",")):
                    for name, addon in builds.items():
                        row = dict(child(addon, size, f, args.threads), revision=name)
                        rows.append(row)
                        print(f"{name:>8}  {size} f = {f}: {row['seconds_per_frame']:.1f} s wall, "
                              f"{row['cpu_seconds']:.1f} s CPU per frame", flush=True)
        finally:
            if args.compare:
                subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(Path(tmp) / "tree")])
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"machine": f"{platform.platform()}, {os.cpu_count()} cores", "threads": args.threads,
                       "load_average": os.getloadavg(), "results": rows}, out, indent=1)


if __name__ == "__main__":
    main()
