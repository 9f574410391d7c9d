#!/usr/bin/env python3
"""One run of the bench scene (bench_synthesis.py's inputs and default
settings): prints CPU and wall seconds, the forward search's own seconds and
SHA-1 hashes of the output image and field, so that two builds can be checked
for bit-identical results and timed in turn:

    PYTHONPATH=addon /usr/bin/python3 bench/search_identity.py SIZE [THREADS [FEATURE_PRECISION]]
"""
import hashlib
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_synthesis as bs  # noqa: E402
from tempera.engine.synthesis import synthesize  # noqa: E402


def digest(a):
    return hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()[:12]


def main():
    size = int(sys.argv[1])
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    extra = {"feature_precision": sys.argv[3]} if len(sys.argv) > 3 else {}
    src, tgt, style = bs.benchmark_scene(size)
    guides = [(a, b, 1.0) for a, b in zip(src, tgt)]
    t0, cpu0 = time.perf_counter(), time.process_time()
    image, stats = synthesize(style, guides, usage="budget", threads=threads, em_iterations=6, pm_iterations=2,
                              guide_variance=0.999, seed=1, **extra)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - t0
    search = sum(level["search_seconds"] for level in stats["levels"])
    print(f"cpu {cpu:.2f} wall {wall:.2f} search {search:.2f} image {digest(image)} field {digest(stats['nnf'])} "
          f"energy {stats['levels'][-1]['energy'][-1]}")


if __name__ == "__main__":
    main()
