#!/usr/bin/env python3
"""Benchmark of the fluid_velocity guide (tempera.app.fluid_velocity) on a large
gas domain seen at HD, with no Blender: a 128 x 64 x 64 grid of random
velocities, half its voxels with density, through an orthographic camera into
a 1920 x 1080 guide whose alpha covers 1300 x 700 pixels (the diffusion fill
then has most pixels to fill: 128 voxels across 1300 pixels).

    PYTHONPATH=addon /usr/bin/python3 bench/bench_fluid_velocity.py [--repeats 3]
"""
import argparse
import time

import numpy as np

from tempera.app import fluid_velocity as fv

WIDTH, HEIGHT = 1920, 1080
RESOLUTION = (128, 64, 64)


def inputs():
    rng = np.random.default_rng(0)
    count = int(np.prod(RESOLUTION))
    velocity = rng.normal(size=3 * count)
    density = np.clip(rng.normal(size=count), 0, None)
    grid = fv.DomainGrid(RESOLUTION, [-1] * 3, [1] * 3, np.eye(4), fps=24)
    clip = np.array([[1 / 2.2, 0, 0, 0], [0, WIDTH / HEIGHT / 2.2, 0, 0], [0, 0, -0.01, 0], [0, 0, 0, 1]])
    alpha = np.zeros((HEIGHT, WIDTH))
    alpha[200:900, 300:1600] = 1
    return velocity, density, grid, clip, alpha


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    velocity, density, grid, clip, alpha = inputs()
    for _ in range(args.repeats):
        start = time.perf_counter()
        points, per_frame, weights = fv.gas_domain_samples(velocity, density, grid)
        samples = time.perf_counter()
        fv.fluid_velocity(points, per_frame, weights, clip, (WIDTH, HEIGHT), alpha)
        done = time.perf_counter()
        print(f"samples {samples - start:.2f} s, guide {done - samples:.2f} s, total {done - start:.2f} s "
              f"({int((weights > 0).sum())} voxels with density, {WIDTH} x {HEIGHT})")


if __name__ == "__main__":
    main()
