#!/usr/bin/env python3
"""Benchmark of the native LPE tracer (tempera.trace_lpe) on a 1 Mpix frame.

The scene is procedural (no outside data): StyLit's "sphere on a table" with
a diffuse sphere, a slightly glossy sphere and a mirror sphere (about 100k
triangles in all) on a table in front of a wall, lit by one area light and a
dim world. It traces the five StyLit guides in one pass: FULL L.*E, LDE, LSE,
L.*DDE and LD{1,2}E.

Prints and optionally writes JSON: wall and CPU seconds, seconds per sample
per pixel, peak memory (max RSS). With --noise it instead measures the
relative RMS error of each guide against a high-sample reference for a range
of sample counts (on a smaller frame), which is how the default was chosen.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_tracer.py [--size 1024] [--samples 64] [--json out.json]
    PYTHONPATH=addon /usr/bin/python3 bench/bench_tracer.py --noise [--size 256]
"""
import argparse
import json
import platform
import resource
import time

import numpy as np

import tempera
from tempera.tracer.lpe import LIGHT_PATH_EXPRESSIONS


def sphere(center, radius, rings, segments):
    """A UV sphere: (vertices, triangles) with outward-facing triangles."""
    theta = np.pi * np.arange(rings + 1) / rings
    phi = 2 * np.pi * np.arange(segments) / segments
    t, p = np.meshgrid(theta, phi, indexing="ij")
    v = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a = (i * segments + j).ravel()
    b = (i * segments + (j + 1) % segments).ravel()
    c, d = a + segments, b + segments
    tris = np.concatenate([np.stack([a, c, d], -1), np.stack([a, d, b], -1)])
    return np.asarray(center) + radius * v, tris


def quad(a, b, c, d):
    return np.array([a, b, c, d], float), np.array([[0, 1, 2], [0, 2, 3]])


def look_at(eye, target, up=(0, 0, 1)):
    """camera_to_world for a camera at eye looking at target (local -Z forward, +Y up)."""
    eye, target, up = (np.asarray(x, float) for x in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, np.cross(back, right), back, eye
    return m


def make_scene(size):
    parts = [  # (vertices, triangles, material)
        (*quad((-3, -2, 0), (3, -2, 0), (3, 2, 0), (-3, 2, 0)), 0),  # table top
        (*quad((-3, 2, 0), (3, 2, 0), (3, 2, 3), (-3, 2, 3)), 0),  # wall behind
        (*sphere((0, 0.2, 0.6), 0.6, 128, 256), 1),  # diffuse sphere, 65k triangles
        (*sphere((-1.2, -0.3, 0.35), 0.35, 64, 128), 2),  # glossy sphere
        (*sphere((1.2, -0.3, 0.4), 0.4, 64, 128), 3),  # mirror sphere
    ]
    vertices, triangles, materials = [], [], []
    base = 0
    for v, t, m in parts:
        vertices.append(v)
        triangles.append(t + base)
        materials.append(np.full(len(t), m))
        base += len(v)
    h = w = size
    tan_half = np.tan(np.radians(40) / 2)
    return {
        "vertices": np.concatenate(vertices).astype(np.float32),
        "triangles": np.concatenate(triangles).astype(np.int32),
        "triangle_materials": np.concatenate(materials).astype(np.int32),
        "materials": [
            {"base_color": [0.8, 0.7, 0.55], "roughness": 0.6},
            {"base_color": [0.8, 0.2, 0.15], "roughness": 0.5},
            {"base_color": [0.2, 0.4, 0.8], "roughness": 0.2},
            {"base_color": [0.95, 0.95, 0.95], "metallic": 1.0, "roughness": 0.0},
        ],
        "lights": [{"type": "area", "center": [-1.5, -2.0, 3.0], "axis_u": [1.0, 0.0, 0.0],
                    "axis_v": [0.0, 0.8, 0.6], "normal": [0.0, 0.6, -0.8], "size_u": 1.0, "size_v": 1.0,
                    "radiance": [12.0, 12.0, 12.0]}],
        "world": {"radiance": [0.05, 0.05, 0.06]},
        "camera": {"type": "perspective", "camera_to_world": look_at((0, -5, 2.2), (0, 0, 0.5)),
                   "width": w, "height": h, "tan_half_fov_x": tan_half, "tan_half_fov_y": tan_half * h / w},
    }


def trace(scene, samples, threads, seed=0):
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    images, alpha = tempera.trace_lpe(scene, list(LIGHT_PATH_EXPRESSIONS.values()), samples=samples, threads=threads,
                                      seed=seed)
    return images, alpha, time.perf_counter() - start_wall, time.process_time() - start_cpu


def noise_table(size, threads, reference_samples, sample_counts):
    """Relative RMS error of each guide per sample count, against a reference."""
    scene = make_scene(size)
    reference, _, seconds, _ = trace(scene, reference_samples, threads, seed=12345)
    rows = {"size": size, "reference_samples": reference_samples, "reference_seconds": seconds, "rel_rmse": {}}
    for n in sample_counts:
        images, _, seconds, _ = trace(scene, n, threads)
        # RMS error over the RMS of the reference: fair to sparse guides (LSE
        # highlights) where the mean is tiny.
        errors = {name: float(np.sqrt(np.mean((img - ref) ** 2) / max(float(np.mean(ref * ref)), 1e-24)))
                  for name, img, ref in zip(LIGHT_PATH_EXPRESSIONS, images, reference)}
        rows["rel_rmse"][n] = errors
        print(n, f"{seconds:.1f} s", {k: round(v, 4) for k, v in errors.items()}, flush=True)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024, help="side of the square frame")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--noise", action="store_true", help="measure noise against sample count instead")
    parser.add_argument("--reference-samples", type=int, default=1024)
    parser.add_argument("--sample-counts", default="4,16,32,64,128,256", help="for --noise")
    parser.add_argument("--save", help="write the guides to this .npz (to look at them)")
    parser.add_argument("--json")
    args = parser.parse_args()

    if args.noise:
        result = noise_table(args.size, args.threads, args.reference_samples,
                             [int(n) for n in args.sample_counts.split(",")])
    else:
        scene = make_scene(args.size)
        images, alpha, wall, cpu = trace(scene, args.samples, args.threads)
        pixels = args.size * args.size
        result = {
            "size": args.size,
            "samples": args.samples,
            "triangles": int(len(scene["triangles"])),
            "expressions": LIGHT_PATH_EXPRESSIONS,
            "wall_seconds": wall,
            "cpu_seconds": cpu,
            "seconds_per_sample_per_pixel": wall / (args.samples * pixels),
            "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "guide_means": {name: float(img.mean()) for name, img in zip(LIGHT_PATH_EXPRESSIONS, images)},
            "alpha_mean": float(alpha.mean()),
        }
        if args.save:
            np.savez(args.save, alpha=alpha, **dict(zip(LIGHT_PATH_EXPRESSIONS, images)))
    result["machine"] = {"cpu": platform.processor() or platform.machine(), "python": platform.python_version()}
    print(json.dumps(result, indent=1))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
