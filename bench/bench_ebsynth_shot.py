#!/usr/bin/env python3
"""StyLit along a shot against ebsynth stylizing each frame cold (issue 32):
the same painting and the same four light-path guides, frame after frame.
ebsynth (jamriska/ebsynth, built for the CPU: build-linux-cpu_only.sh) reads
PNGs, so its guides are Tempera's own tone map of the guide cache
(tempera.engine.guides.tonemap, written as 8-bit PNGs) and its exemplar
guides the PNGs as given. Tempera runs as an artist does: `--temporal 0.5`
warm-started (the default since issue 32's step 6) and cold (`--warm-start
off`), and with temporal 0 (each frame on its own, the job ebsynth does).
Within a frame the runs alternate, so all see the same machine load.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_ebsynth_shot.py --ebsynth ebsynth/bin/ebsynth \\
        --guides GUIDE_CACHE --exemplar source_style.png --exemplar-pngs ebsynth/examples/stylit \\
        [--exemplar-shrink 2] [--frames 1-8] [--threads 2] [--work DIR] [--json out.json]

Per frame and run: seconds (ebsynth: the whole process, reading and writing
its PNGs included; Tempera: stylize_frame), warp error (the flicker: mean
colour change along the motion where visible) and detail (mean gradient
magnitude).
"""
import argparse
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from tempera import read_image, write_image
from tempera.app import guide_cache
from tempera.app.frames import parse_frames
from tempera.engine import temporal
from tempera.engine.guides import tonemap
from tempera.methods.stylit.stylize import stylize_frame

from bench_warm_start import EBSYNTH_PNGS, GUIDES, MOTION, detail, exemplar_from_pngs, shrink

# Tempera's runs: name -> stylize_frame options (the chained ones get the previous frame).
TEMPERA_RUNS = {"tempera t0": dict(temporal_weight=0.0, warm_start="off"),
                "tempera t0.5 cold": dict(temporal_weight=0.5, warm_start="off"),
                "tempera t0.5 warm": dict(temporal_weight=0.5, warm_start="on")}


def write_png(path, image):
    write_image(str(path), np.ascontiguousarray(np.clip(image, 0.0, 1.0), np.float32))


def ebsynth_frame(ebsynth, work, style_png, target, frame, threads):
    """ebsynth on one frame, cold: its seconds and image. ebsynth_cpu uses OpenMP."""
    args = [ebsynth, "-style", str(style_png)]
    for name, file in EBSYNTH_PNGS.items():
        target_png = work / f"target_{name}_{frame:04d}.png"
        write_png(target_png, tonemap(target[name]))
        args += ["-guide", str(work / file), str(target_png), "-weight", "0.5"]
    out = work / f"ebsynth_{frame:04d}.png"
    args += ["-output", str(out), "-backend", "cpu"]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    started = time.monotonic()
    subprocess.run(args, check=True, env=env, stdout=subprocess.DEVNULL)
    seconds = time.monotonic() - started
    return seconds, np.asarray(read_image(str(out)), np.float32)[:, :, :3]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ebsynth", required=True)
    parser.add_argument("--guides", required=True)
    parser.add_argument("--exemplar", required=True)
    parser.add_argument("--exemplar-pngs", required=True)
    parser.add_argument("--exemplar-shrink", type=int, default=1)
    parser.add_argument("--frames", default="1-8")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--work", help="folder for ebsynth's PNGs and every run's frames (default: a temporary one)")
    parser.add_argument("--json")
    args = parser.parse_args()
    work = Path(args.work or tempfile.mkdtemp(prefix="tempera-ebsynth-"))
    work.mkdir(parents=True, exist_ok=True)
    k = max(1, args.exemplar_shrink)
    style = shrink(np.asarray(read_image(args.exemplar), np.float32)[:, :, :3], k)
    style_png = work / "source_style.png"
    write_png(style_png, style)
    exemplar = {name: shrink(v, k) for name, v in exemplar_from_pngs(args.exemplar_pngs).items()}
    for name, file in EBSYNTH_PNGS.items():  # ebsynth's exemplar guides: the same pixels Tempera matches
        write_png(work / file, tonemap(exemplar[name]))
    last = {}  # run -> its previous frame's image and matches (ebsynth: no matches)
    rows = []
    print("| frame | run | seconds | warp error | detail |")
    print("| ---: | --- | ---: | ---: | ---: |")
    for frame in parse_frames(args.frames):
        target = guide_cache.read_frame(args.guides, frame, GUIDES + MOTION)
        motion = (target["velocity_backward"], target["occlusion_backward"])
        seconds, image = ebsynth_frame(args.ebsynth, work, style_png, target, frame, args.threads)
        results = {"ebsynth": (seconds, image, None)}
        for run, options in TEMPERA_RUNS.items():
            chained = {}
            if run in last and (options["temporal_weight"] > 0 or options["warm_start"] == "on"):
                chained = dict(previous=last[run]["image"], previous_field=last[run]["field"],
                               velocity_backward=motion[0], occlusion_backward=motion[1])
            started = time.monotonic()
            image, stats = stylize_frame(style, exemplar, {g: target[g] for g in GUIDES}, threads=args.threads,
                                         **options, **chained)
            results[run] = (time.monotonic() - started, image, stats["field"])
        for run, (seconds, image, field) in results.items():
            warp = temporal.flicker(last[run]["image"], image, *motion) if run in last else float("nan")
            last[run] = {"image": image, "field": field}
            write_png(work / f"{run.replace(' ', '_')}_{frame:04d}.png", image)
            rows.append(dict(frame=frame, run=run, seconds=seconds, warp=warp, detail=detail(image)))
            print(f"| {frame} | {run} | {seconds:.2f} | {warp:.4f} | {detail(image):.4f} |", flush=True)
    first = parse_frames(args.frames)[0]
    means = {}
    for run in ["ebsynth", *TEMPERA_RUNS]:
        mine = [r for r in rows if r["run"] == run]
        means[run] = dict(seconds=float(np.mean([r["seconds"] for r in mine])),
                          warp=float(np.mean([r["warp"] for r in mine if r["frame"] != first])),
                          detail=float(np.mean([r["detail"] for r in mine])))
    print("\nmeans (seconds and detail over all frames, warp error over the frames after the first):")
    for run, m in means.items():
        print(f"  {run}: {m['seconds']:.2f} s ({means['ebsynth']['seconds'] / m['seconds']:.2f}x ebsynth), "
              f"warp error {m['warp']:.4f}, detail {m['detail']:.4f}")
    print(f"frames in {work}")
    if args.json:
        Path(args.json).write_text(json.dumps({"args": vars(args), "rows": rows, "means": means}, indent=1))


if __name__ == "__main__":
    main()
