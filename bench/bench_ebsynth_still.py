#!/usr/bin/env python3
"""The StyLit still against ebsynth (issue 32): ebsynth's own example
(jamriska/ebsynth examples/stylit: a painted ball, 1200x912, four light-path
guides at weight 0.5, its run.sh command) and `tempera synth` on the very same
PNGs, each as a whole process, run after one another in every repeat so that
they see the same machine load. `--previous` adds a second Tempera CLI (the
previous revision's build) to the same run, for side-by-side speed-ups.

    PYTHONPATH=addon /usr/bin/python3 bench/bench_ebsynth_still.py --ebsynth ebsynth/bin/ebsynth \\
        --examples ebsynth/examples/stylit [--tempera build/bin/tempera] [--previous OLD/build/bin/tempera] \\
        [--repeats 2] [--threads 2] [--work DIR] [--json out.json]

Per run: wall seconds, CPU seconds and peak RSS of the process (os.wait4's
rusage of that child alone), and the energy of its image. The energy is
judged the same way for every image: the mean distance of each of the image's
patches (with the target guides) to its nearest exemplar patch (with the
exemplar guides), i.e. StyLit's guided patch energy without a usage term,
found by `tempera synth --reference IMAGE` at the finest level alone
(--levels 1 --em-iters 1 --usage none: the search starts from a random field
on the given image and its energy is taken before any vote). Lower is better.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

GUIDES = ("fullgi", "dirdif", "dirspc", "indirb")  # examples/stylit/run.sh's order
WEIGHT = "0.5"
JUDGE_SWEEPS = 32  # PatchMatch sweeps of the judge: on the still its energy falls ~1% more by 48 (6% from 4 to 12)


def guide_args(flag, examples):
    """The guide pairs as `flag SRC TGT -weight W` for ebsynth or `--guide ... --weight` for Tempera."""
    args = []
    for name in GUIDES:
        args += [flag, str(examples / f"source_{name}.png"), str(examples / f"target_{name}.png")]
        args += ["-weight" if flag == "-guide" else "--weight", WEIGHT]
    return args


def measured(command, env=None):
    """Run a process; its wall and CPU seconds and its own peak RSS in MB."""
    started = time.monotonic()
    process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.monotonic() - started
    process.returncode = os.waitstatus_to_exitcode(status)
    error = process.stderr.read().decode(errors="replace")
    if process.returncode != 0:
        raise SystemExit(f"{command[0]} failed ({process.returncode}): {error[-2000:]}")
    return dict(seconds=wall, cpu_seconds=usage.ru_utime + usage.ru_stime, peak_rss_mb=usage.ru_maxrss / 1024)


def judged_energy(tempera, examples, image, work):
    """Guided patch energy of `image` against the exemplar (see the module's docstring)."""
    stats = work / f"{image.stem}_judge.json"
    subprocess.run([tempera, "synth", "--style", str(examples / "source_style.png"), *guide_args("--guide", examples),
                    "--reference", str(image), "--levels", "1", "--em-iters", "1", "--pm-iters", str(JUDGE_SWEEPS),
                    "--usage", "none", "--skip-converged", "false", "--output", str(work / "judge.png"),
                    "--stats", str(stats), "--quiet"], check=True)
    return json.loads(stats.read_text())["levels"][-1]["energy"][0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ebsynth", required=True, help="ebsynth binary (build-linux-cpu_only.sh)")
    parser.add_argument("--examples", required=True, help="ebsynth's examples/stylit folder")
    parser.add_argument("--tempera", default="build/bin/tempera")
    parser.add_argument("--previous", help="another tempera binary (the previous revision) to run alongside")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--work", help="folder for the outputs (default: a temporary one)")
    parser.add_argument("--json")
    args = parser.parse_args()
    examples = Path(args.examples)
    work = Path(args.work or tempfile.mkdtemp(prefix="tempera-still-"))
    work.mkdir(parents=True, exist_ok=True)

    commands = {"ebsynth": lambda out: [args.ebsynth, "-style", str(examples / "source_style.png"),
                                        *guide_args("-guide", examples), "-output", str(out), "-backend", "cpu"]}
    binaries = {"tempera": args.tempera, **({"tempera previous": args.previous} if args.previous else {})}
    for run, binary in binaries.items():
        commands[run] = lambda out, binary=binary: [
            binary, "synth", "--style", str(examples / "source_style.png"), *guide_args("--guide", examples),
            "--threads", str(args.threads), "--output", str(out), "--quiet"]
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))  # ebsynth's CPU backend is OpenMP
    rows = []
    for repeat in range(args.repeats):
        for run, command in commands.items():
            out = work / f"{run.replace(' ', '_')}.png"
            row = dict(run=run, repeat=repeat, **measured(command(out), env))
            rows.append(row)
            print(f"{run}: {row['seconds']:.2f} s wall, {row['cpu_seconds']:.2f} s CPU, "
                  f"peak RSS {row['peak_rss_mb']:.1f} MB", flush=True)
    summary = {}
    for run in commands:
        mine = [r for r in rows if r["run"] == run]
        summary[run] = {key: statistics.median(r[key] for r in mine) for key in ("seconds", "cpu_seconds", "peak_rss_mb")}
        summary[run]["energy"] = judged_energy(args.tempera, examples, work / f"{run.replace(' ', '_')}.png", work)
    base = summary["ebsynth"]
    print("\n| run (median of %d) | wall s | against ebsynth | CPU s | peak RSS MB | energy |" % args.repeats)
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for run, s in summary.items():
        print(f"| {run} | {s['seconds']:.2f} | {base['seconds'] / s['seconds']:.2f}x | {s['cpu_seconds']:.2f} | "
              f"{s['peak_rss_mb']:.1f} | {s['energy']:.5f} |")
    print(f"images in {work}")
    if args.json:
        Path(args.json).write_text(json.dumps({"args": vars(args), "rows": rows, "summary": summary}, indent=1))


if __name__ == "__main__":
    main()
