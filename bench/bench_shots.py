#!/usr/bin/env python3
"""Seconds a frame of every method along a shot, at 0.25, 1 and 2 Mpix, cold and
warm-started where the method has both (issue 32): what `tempera stylize
--method NAME` costs a farm per frame, run through the same jobs (the method
registry's make_job: run_frame for each frame in order, the coherent
method's shot as one segment), writing its PNG frames as the CLI does.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_shots.py --mpix 0.25,1,2 --frames 24 \\
        [--methods stylit,tcia,...] [--previous OTHER/addon | --compare REV] [--work DIR] [--json out.json]

--previous runs another revision's add-on (its native module built) on the
same inputs, side by side: for every method, size and variant the two runs
follow each other, in alternating order, so both see the same machine load;
--compare REV builds REV's module first (bench_synthesis.build_revision).
Every run is a process of its own, so its peak RSS is its own.

The shot (made once per size under --work, then reused), square frames, one
guide cache for every method:
- the light-path guides (FULL, LDE, LSE, LDDE) of shaded spheres on a table
  under a camera panning side/256 px a frame, with exact V+-, chi+- (bench_tcia's
  panning shot); the exemplar is one sphere under the same light, hatched
  (bench_synthesis.hatching_style), with its guide cache (StyLit, the coherent
  method; Color Me Noisy boils the FULL guide with its own medium);
- 'alpha', a disc of radius 0.4 side, and 'fluid_velocity', its turning at
  0.02 rad a frame (LazyFluids from smoke of side/4, bench_lazyfluids.smoke;
  Fluidymation from 20 frames of spreading ink rings of 0.4 side,
  bench_fluidymation.exemplar);
- tracks.json: a ball thrown across the frame (the rigid-body method, its
  generated drawn exemplar).

Per run: the first frame's seconds (a warm start has no frame before it),
the later frames' mean, CPU seconds a frame, the process's peak RSS and the
job's share of it (the peak less the RSS once Python, numpy and the module
are loaded); the growth of the time and of the job's memory from size to
size, scaled to 4x the pixels (issue 32's target: <= 4.5x). The rigid-body
method's first frame draws its generated exemplar and fits the whole track.
Synthetic inputs measure cost, not look: bench_warm_start.py and
bench_ebsynth_shot.py measure quality on a rendered shot.
"""
import argparse
import importlib
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

LIGHT_PATHS = ("FULL", "LDE", "LSE", "LDDE")
OMEGA = 0.02  # the fluid's turn, radians a frame
# Each method's variants: the options that make them (the command line's flags). StyLit:
# the command line's default (temporal 0: each frame on its own, cold), and with the
# temporal guide cold and warm (what artists run: warm by default with it). A
# method without a warm start (its frames independent: Color Me Noisy, the rigid-body
# method) or without a cold one (Fluidymation's SHIFTNNF) has one; the coherent
# method's sweeps advect by design.
VARIANTS = {
    "stylit": {"each frame": {}, "cold": {"temporal": "0.5", "warm-start": "off"}, "warm": {"temporal": "0.5"}},
    "tcia": {"sweeps": {}},
    "noisy": {"cold": {}},
    "lazyfluids": {"cold": {"warm-start": "false"}, "warm": {"warm-start": "true"}},
    "fluidymation": {"warm": {}},
    "rigid": {"cold": {}},
}


def side_of(mpix):
    return int(round(math.sqrt(mpix * 1e6)))


def make_shot(folder, side, frames):
    """The inputs of every method at side x side (see the docstring); returns the folder."""
    if (folder / "ready").is_file():
        return folder
    from bench_fluidymation import exemplar as ink_rings
    from bench_lazyfluids import rotating_disc, smoke
    from bench_tcia import panning_shot
    from tempera import _native, write_image
    from tempera.app import guide_cache
    from tempera.methods.rigid import rigid_tracks

    shutil.rmtree(folder, ignore_errors=True)
    style, exemplar_guides, shot = panning_shot(side, frames, max(1, round(side / 256)))
    alpha, flow = rotating_disc(side, OMEGA)
    motion = ("velocity_backward", "velocity_forward", "occlusion_backward", "occlusion_forward")
    guides = folder / "guides"
    for t, frame in enumerate(shot):
        channels = dict(zip(LIGHT_PATHS, frame["guides"]), alpha=alpha, fluid_velocity=flow)
        channels.update({k: frame[k] for k in motion})
        guide_cache.write_frame(guides, t + 1, channels)
    names = [*LIGHT_PATHS, *motion, "alpha", "fluid_velocity"]
    guide_cache.write_manifest(guides, {"resolution": [side, side], "guides": names,
                                        "frames": {str(t + 1): {"key": "synthetic"} for t in range(frames)}})
    s = side / 512  # a thrown ball, the rigid-body tests' scaled to the frame
    ball = _native.bouncing_ball((0.8 * side, 0.1 * side), (-3.0 * s, 0), 28 * s, 1.0 * s, 0.9 * side, 0.7, -0.05,
                                 frames)
    rigid_tracks.write_tracks(guides, {"Ball": ball}, 1, (0, 1.0 * s))

    exemplar = folder / "exemplar_guides"
    guide_cache.write_frame(exemplar, 1, {name: g for name, g, _ in exemplar_guides})
    guide_cache.write_manifest(exemplar, {"resolution": [side, side], "guides": list(LIGHT_PATHS),
                                          "frames": {"1": {"key": "synthetic"}}})
    write_image(str(folder / "painting.png"), np.ascontiguousarray(style))
    write_image(str(folder / "smoke.png"), smoke(max(16, side // 4)))
    rgb, masks = ink_rings(side=round(0.4 * side), frames=20)
    (folder / "ink").mkdir()
    for i, (colour, mask) in enumerate(zip(rgb, masks)):
        write_image(str(folder / "ink" / f"frame_{i + 1:04d}.png"), np.dstack([colour, mask]).astype(np.float32))
    (folder / "ready").write_text("")
    return folder


def job_inputs(method, shot):
    """(exemplar, options) of a method on the shot."""
    if method in ("stylit", "tcia"):
        return str(shot / "painting.png"), {"exemplar-guides": str(shot / "exemplar_guides")}
    if method == "lazyfluids":
        return str(shot / "smoke.png"), {}
    if method == "fluidymation":
        return str(shot / "ink"), {}
    return "", {}  # noisy: the first render under a paper grain; rigid: the generated drawn ball


def run_chain(method, variant, shot, frames, out):
    """One method's frames 1..frames in order, in this process: seconds of each frame."""
    from tempera.methods import registry

    exemplar, options = job_inputs(method, shot)
    options.update(VARIANTS[method][variant])
    job = registry.make_job(method, exemplar, str(shot / "guides"), range(1, frames + 1), str(out), resume=False,
                            options=options)
    seconds = []
    if hasattr(job, "run_segment"):  # the coherent method: the shot is one segment (no keys)
        for i in job.selected:
            started = time.perf_counter()
            job.run_segment(i)
            seconds.append(time.perf_counter() - started)
        return [sum(seconds) / frames] * frames
    for i in range(frames):
        started = time.perf_counter()
        job.run_frame(i)
        seconds.append(time.perf_counter() - started)
    return seconds


def resident_mb(field="VmRSS"):
    """This process's resident memory now (VmRSS) or at its peak (VmHWM), MB. Not
    getrusage's ru_maxrss: Linux carries that over exec from the parent (here the
    bench, which made the shot), so a small run would report the bench's peak."""
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith(field + ":")) / 1024


def worker(args):
    importlib.import_module("tempera.methods.registry")  # the module and its libraries: the baseline
    baseline, cpu = resident_mb(), time.process_time()
    seconds = run_chain(args.method, args.variant, Path(args.shot), args.frames, Path(args.out))
    print(json.dumps({"seconds": seconds, "cpu_s": time.process_time() - cpu, "baseline_mb": baseline,
                      "peak_rss_mb": resident_mb("VmHWM")}))


def run(addon, method, variant, shot, frames, scratch):
    """A run in its own process with `addon` first on the path; its figures."""
    out = Path(tempfile.mkdtemp(prefix="out-", dir=scratch))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(addon), str(HERE)]))
    try:
        done = subprocess.run([sys.executable, __file__, "--worker", "--method", method, "--variant", variant,
                               "--shot", str(shot), "--frames", str(frames), "--out", str(out)],
                              env=env, check=True, capture_output=True, text=True)
    except subprocess.CalledProcessError as e:
        raise SystemExit(f"{method} {variant} with {addon} failed:\n{e.stderr}") from None
    finally:
        shutil.rmtree(out, ignore_errors=True)
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    s = figures["seconds"]
    return {"first_s": round(s[0], 3), "later_s": round(float(np.mean(s[1:])), 3) if len(s) > 1 else None,
            "s_per_frame": round(float(np.mean(s)), 3), "cpu_s_per_frame": round(figures["cpu_s"] / len(s), 3),
            "peak_rss_mb": round(figures["peak_rss_mb"], 1),
            "job_mb": round(figures["peak_rss_mb"] - figures["baseline_mb"], 1)}


def run_all(args, methods, revisions, work, scratch):
    """Every size, method and variant, the revisions' runs one after the other
    (their order alternating from one pair to the next): the rows."""
    rows, turn = [], 0
    for mpix in (float(m) for m in args.mpix.split(",")):
        side = side_of(mpix)
        shot = make_shot(work / f"shot_{side}_{args.frames}", side, args.frames)
        for method in methods:
            for variant in VARIANTS[method]:
                if args.variants and variant not in args.variants.split(","):
                    continue
                order = list(revisions.items())
                for name, addon in order[::-1] if turn % 2 else order:
                    row = dict(mpix=round(side * side / 1e6, 3), side=side, method=method, variant=variant,
                               revision=name, **run(addon, method, variant, shot, args.frames, scratch))
                    print(json.dumps(row), flush=True)
                    rows.append(row)
                turn += 1
    return rows


def variant_order(method, variant):
    """Where a method's variant comes in the tables: VARIANTS' order."""
    return list(VARIANTS).index(method), list(VARIANTS[method]).index(variant)


def growth(rows, revision):
    """Time and memory of each method and variant from size to size, scaled to 4x the pixels."""
    out = []
    keys = sorted({(r["method"], r["variant"]) for r in rows if r["revision"] == revision},
                  key=lambda k: variant_order(*k))
    for method, variant in keys:
        mine = sorted((r for r in rows if (r["revision"], r["method"], r["variant"]) == (revision, method, variant)),
                      key=lambda r: r["mpix"])
        for a, b in zip(mine, mine[1:]):
            power = math.log(4) / math.log(b["mpix"] / a["mpix"])
            out.append({"method": method, "variant": variant, "from_mpix": a["mpix"], "to_mpix": b["mpix"],
                        "time_per_4x": round((b["s_per_frame"] / a["s_per_frame"]) ** power, 2),
                        "memory_per_4x": round((b["job_mb"] / a["job_mb"]) ** power, 2)})
    return out


def print_tables(rows, grown, revisions):
    print("| Mpix | method | variant | revision | first frame s | later frames s | s a frame | CPU s a frame "
          "| peak RSS MB | the job's MB |")
    print("| ---: | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        print(f"| {r['mpix']:.2f} | {r['method']} | {r['variant']} | {r['revision']} | {r['first_s']:.2f} "
              f"| {r['later_s'] if r['later_s'] is None else format(r['later_s'], '.2f')} | {r['s_per_frame']:.2f} "
              f"| {r['cpu_s_per_frame']:.2f} | {r['peak_rss_mb']:.0f} | {r['job_mb']:.0f} |")
    if len(revisions) > 1:
        print("\n| Mpix | method | variant | s a frame, " + " / ".join(revisions) + " | speed-up |")
        print("| ---: | --- | --- | ---: | ---: |")
        for r in rows:
            if r["revision"] != revisions[0]:
                continue
            other = next(o for o in rows if o["revision"] == revisions[1]
                         and (o["mpix"], o["method"], o["variant"]) == (r["mpix"], r["method"], r["variant"]))
            print(f"| {r['mpix']:.2f} | {r['method']} | {r['variant']} | {r['s_per_frame']:.2f} / "
                  f"{other['s_per_frame']:.2f} | {other['s_per_frame'] / r['s_per_frame']:.2f}x |")
    if grown:
        print("\n| method | variant | Mpix | time, per 4x the pixels | the job's memory, per 4x the pixels |")
        print("| --- | --- | --- | ---: | ---: |")
        for g in grown:
            print(f"| {g['method']} | {g['variant']} | {g['from_mpix']:.2f} -> {g['to_mpix']:.2f} "
                  f"| {g['time_per_4x']:.2f}x | {g['memory_per_4x']:.2f}x |")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mpix", default="0.25,1,2", help="frame sizes in megapixels (square frames)")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--methods", default=",".join(VARIANTS))
    parser.add_argument("--variants", help="only these variants (e.g. warm)")
    parser.add_argument("--previous", help="another revision's addon folder (its native module built)")
    parser.add_argument("--compare", metavar="REV", help="build REV's native module and run it as --previous")
    parser.add_argument("--work", default=os.path.join(tempfile.gettempdir(), "tempera-bench-shots"),
                        help="where the shots are made (kept: a rerun reuses them)")
    parser.add_argument("--json", help="also write the figures here")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--method", help=argparse.SUPPRESS)
    parser.add_argument("--variant", help=argparse.SUPPRESS)
    parser.add_argument("--shot", help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        return worker(args)
    methods = args.methods.split(",")
    unknown = [m for m in methods if m not in VARIANTS]
    if unknown:
        parser.error(f"unknown method(s) {', '.join(unknown)}; methods: {', '.join(VARIANTS)}")
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    revisions = {"this": HERE.parent / "addon"}
    with tempfile.TemporaryDirectory(prefix="tempera-bench-shots-") as tmp:
        if args.compare:
            from bench_synthesis import build_revision
            args.previous = str(build_revision(args.compare, Path(tmp)))
        if args.previous:
            revisions[args.compare or "previous"] = Path(args.previous)
        try:
            rows = run_all(args, methods, revisions, work, tmp)
        finally:
            if args.compare:
                subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force",
                                str(Path(tmp) / "tree")])
    rows.sort(key=lambda r: (r["mpix"], *variant_order(r["method"], r["variant"]), r["revision"] != "this"))
    grown = growth(rows, "this")
    print()
    print_tables(rows, grown, list(revisions))
    if args.json:
        result = {"machine": f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores",
                  "load_average": os.getloadavg()[0], "frames": args.frames, "rows": rows, "growth": grown}
        Path(args.json).write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
