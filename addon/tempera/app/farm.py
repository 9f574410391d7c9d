"""A shot split into `tempera` commands, run on a Dask cluster (no bpy).

    tempera farm [SCENE.blend] --exemplar STYLE.png (--exemplar-guides DIR | --exemplar-scene EX.blend)
                 --frames 1-48 --out DIR [--chunk-size 8] [--scheduler tcp://HOST:8786] [stylize options]
    tempera farm [SCENE.blend] --method NAME --exemplar EXEMPLAR --frames 1-48 --out DIR [method options]
    tempera stylize ... --scheduler ADDRESS            (the same)

Every method of the registry (native/include/tempera/methods/registry.hpp) is
planned by its unit of work and its guide needs: the methods guided by light
paths take the exemplar's guides, --temporal and write a video; the others
take their exemplar as it is. Frames split anywhere, one task per segment,
one task for chained frames.

`plan()` cuts the shot into tasks, each one run of the batch CLI:

1. `exemplar-guides`: `tempera render-guides EX.blend --frames N` (only with --exemplar-scene);
2. `guides A-B`: `tempera render-guides SCENE --frames A-B`, one per chunk of frames (only with SCENE);
3. `stylize A-B`: `tempera stylize --guides ... --frames A-B --no-video`, one per chunk, after the
   guide chunks it reads. With a temporal weight a frame is pulled towards its predecessor, so a
   temporal chain must not be cut: the whole shot is one task. The coherent method
   (`--method tcia`) solves a shot as independent segments from key to key (`--key F=PATH`):
   one task per segment (`--segment A-B`). Results are then frame for frame those of one machine;
4. `finish`: `tempera stylize` over all frames, which finds every frame current (the resume
   key) and writes the contact sheet and the video.

Every command resumes (the CLI skips current guide and stylized frames, and writes each frame
atomically), so a task that is run again after its worker died redoes only unfinished frames,
and a rerun of the whole farm completes an interrupted shot. farm/flamenco/tempera.js makes the
same tasks for a Flamenco manager (tested against this module).

`run_dask()` submits the tasks with their dependencies to the scheduler at an address, or to a
local cluster it starts (the default, `--workers` processes on this machine).
"""
import argparse
import shlex
import shutil
import subprocess
import sys
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path

DEFAULT_CHUNK_SIZE = 8


class FarmError(RuntimeError):
    """A shot that cannot be planned, or a task that failed (the message names it)."""


@dataclass
class Task:
    name: str  # "guides 1-8", "stylize 1-8", "finish"
    kind: str  # "render-guides", "stylize", "finish"
    command: list  # argv
    depends: list = field(default_factory=list)  # names of tasks that must finish first
    frames: list = field(default_factory=list)


def parse_frames(text):
    """'1-24', '1-10,15' -> sorted unique frame numbers; FarmError on bad input."""
    frames = set()
    for part in str(text).split(","):
        part = part.strip()
        try:
            if "-" in part[1:]:
                cut = part.index("-", 1)
                first, last = int(part[:cut]), int(part[cut + 1:])
                if last < first:
                    raise ValueError
                frames.update(range(first, last + 1))
            else:
                frames.add(int(part))
        except ValueError:
            raise FarmError(f"bad frame range {text!r}: expected e.g. '1-48' or '1-10,15'") from None
    if not frames:
        raise FarmError(f"bad frame range {text!r}: no frames")
    return sorted(frames)


def format_frames(frames):
    """Sorted frames -> the shortest range text, [1, 2, 3, 7] -> '1-3,7'."""
    runs, start = [], None
    for i, f in enumerate(frames):
        if start is None:
            start = f
        if i + 1 == len(frames) or frames[i + 1] != f + 1:
            runs.append(str(start) if start == f else f"{start}-{f}")
            start = None
    return ",".join(runs)


def chunk_frames(frames, size):
    """Consecutive pieces of at most `size` frames, in order."""
    if size < 1:
        raise FarmError(f"chunk size must be at least 1, not {size}")
    return [frames[i:i + size] for i in range(0, len(frames), size)]


def _option_values(args, name):
    """The values of `name` in an argv list ("--key V" or "--key=V"), in order."""
    values = []
    for i, word in enumerate(args):
        if word == name and i + 1 < len(args):
            values.append(args[i + 1])
        elif word.startswith(name + "="):
            values.append(word[len(name) + 1:])
    return values


def shot_method(stylize_args):
    """The registry's entry of the shot's method (native/include/tempera/methods/registry.hpp):
    its unit of work ("frame", "segment", "chained frame") and guide needs; FarmError for a
    method the registry does not know."""
    from ..methods import registry  # here: a worker that only runs commands needs no native module
    try:
        return registry.find((_option_values(stylize_args, "--method") or [registry.default_name()])[-1])
    except ValueError as e:
        raise FarmError(str(e)) from None


def shot_segments(frames, stylize_args, method):
    """The segments [first, ..., last] of a shot whose method's unit is the
    segment (the coherent method; `method` is its registry entry): from key to key (the shot's --key and
    every layer's --layer-key) and to the shot's ends, by the rule the job
    solves them with (native/include/tempera/app/segments.hpp); None for
    other units."""
    if method["unit"] != "segment":
        return None
    from .. import _native
    from ..methods.tcia import tcia
    try:
        keys = _native.tcia_key_frames(_option_values(stylize_args, "--key"),
                                       _option_values(stylize_args, "--layer-key"))
    except ValueError as e:
        raise FarmError(str(e)) from None
    return [list(range(first, last + 1)) for first, last in tcia.segments(frames, keys)]


def plan(frames, out, exemplar, *, scene=None, guides=None, exemplar_guides=None, exemplar_scene=None,
         exemplar_frame=1, chunk_size=DEFAULT_CHUNK_SIZE, temporal=None, tempera=("tempera",),
         guide_args=(), stylize_args=(), video=True):
    """The tasks of a shot, in an order that respects their dependencies."""
    frames = parse_frames(frames) if isinstance(frames, str) else sorted(set(frames))
    if not frames:
        raise FarmError("no frames to stylize")
    method = shot_method(list(stylize_args))
    light_paths = method["light_path_guides"]  # StyLit's: the exemplar's guides, --temporal, a video
    if light_paths and (exemplar_guides is None) == (exemplar_scene is None):
        raise FarmError("give the exemplar's guides as exactly one of exemplar_guides (a cache folder) "
                        "and exemplar_scene (a .blend to render)")
    if not light_paths and (exemplar_guides is not None or exemplar_scene is not None or temporal is not None):
        raise FarmError(f"--method {method['name']} takes its exemplar as it is: no exemplar guides or scene "
                        "and no --temporal (those are StyLit's)")
    if scene is None and guides is None:
        raise FarmError("give the shot as a scene (.blend, guides rendered) or as a guide cache folder")
    tempera = list(tempera)
    out = str(out)
    guides = str(guides) if guides is not None else str(Path(out) / "guides")
    tasks = []
    exemplar_task = []
    if exemplar_scene is not None:
        exemplar_guides = str(Path(out) / "exemplar_guides")
        tasks.append(Task("exemplar-guides", "render-guides",
                          tempera + ["render-guides", str(exemplar_scene), "--frames", str(exemplar_frame),
                                     "--out", exemplar_guides, *guide_args], frames=[exemplar_frame]))
        exemplar_task = ["exemplar-guides"]
    guide_tasks = []
    if scene is not None:
        for chunk in chunk_frames(frames, chunk_size):
            name = f"guides {format_frames(chunk)}"
            tasks.append(Task(name, "render-guides",
                              tempera + ["render-guides", str(scene), "--frames", format_frames(chunk),
                                         "--out", guides, *guide_args], frames=chunk))
            guide_tasks.append((set(chunk), name))
    segments = shot_segments(frames, list(stylize_args), method)
    if temporal is None and segments is None and light_paths:
        from .settings import DEFAULT_TEMPORAL_WEIGHT as temporal
    # Always stated: the chunks must agree with a single run whatever the CLI's default. The
    # coherent method keeps its own (3) unless one is given.
    common = (["--guides", guides, "--exemplar", str(exemplar)]
              + (["--exemplar-guides", str(exemplar_guides)] if light_paths else [])
              + ["--out", out] + ([] if temporal is None else ["--temporal", repr(float(temporal))]))
    common += list(stylize_args)
    no_video = ["--no-video"] if light_paths else []  # the others write no video
    if segments is not None:  # each task solves one segment of the whole shot
        pieces = [(p, ["--frames", format_frames(frames), "--segment", f"{p[0]}-{p[-1]}"]) for p in segments]
    else:  # a temporal chain is one task, as is a method of chained frames
        chained = bool(temporal) or method["unit"] == "chained frame"
        pieces = [(p, ["--frames", format_frames(p)]) for p in ([frames] if chained else
                                                                chunk_frames(frames, chunk_size))]
    stylize_names = []
    for piece, which in pieces:
        name = f"stylize {format_frames(piece)}"
        needs = exemplar_task + [n for covered, n in guide_tasks if covered & set(piece)]
        tasks.append(Task(name, "stylize", tempera + ["stylize", *which, *common, *no_video], needs, piece))
        stylize_names.append(name)
    tasks.append(Task("finish", "finish",
                      tempera + ["stylize", "--frames", format_frames(frames), *common,
                                 *([] if video else no_video)], stylize_names, frames))
    return tasks


def run_command(command, *_dependencies):
    """Runs one task's command on a worker; raises naming it if it fails."""
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        tail = (result.stderr or result.stdout).strip().splitlines()[-5:]
        raise FarmError(f"'{shlex.join(command)}' exited with {result.returncode}: " + " | ".join(tail))
    return result.stdout


def run_dask(tasks, scheduler=None, workers=2, retries=2, log=print):
    """Runs `tasks` on the Dask scheduler at `scheduler` (an address such as
    tcp://host:8786), or on a local cluster of `workers` processes. A task
    whose worker dies is run again elsewhere (`retries` times; its command
    resumes). Returns {task name: stdout}; raises FarmError naming the first
    task that failed."""
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as exc:
        raise FarmError("the Dask farm needs dask.distributed: pip install 'dask[distributed]' "
                        f"(or tempera_native[farm]) ({exc})") from exc
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None)
        client = Client(cluster)
    else:
        client = Client(scheduler, timeout="30s")
    run_id = uuid.uuid4().hex[:8]
    try:
        futures, names = {}, {}
        for task in tasks:
            future = client.submit(run_command, task.command, *(futures[d] for d in task.depends),
                                   key=f"tempera-{task.name.replace(' ', '_')}-{run_id}", pure=False,
                                   retries=retries)
            futures[task.name] = future
            names[future.key] = task.name
        log(f"farm: {len(tasks)} task(s) on {scheduler or f'a local cluster of {workers} worker(s)'}")
        outputs = {}
        started = time.monotonic()
        for future in as_completed(list(futures.values())):
            name = names[future.key]
            try:
                outputs[name] = future.result()
            except Exception as exc:
                for other in futures.values():
                    other.cancel()
                raise FarmError(f"task '{name}' failed: {exc}") from exc
            log(f"farm: {name} done ({time.monotonic() - started:.1f} s)")
        return outputs
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def default_tempera():
    """How workers run the CLI: the `tempera` on PATH (the console script
    or the native binary), else this Python's `-m tempera`."""
    found = shutil.which("tempera")
    return [found] if found else [sys.executable, "-m", "tempera"]


# Options of the farm itself (with a value, and flags); every other option goes
# to the tasks as it is: --samples, --blender and --addon-path to render-guides,
# the rest to stylize (all take a value except the flags in PASS_FLAGS).
FARM_OPTIONS = {"--exemplar", "--exemplar-guides", "--exemplar-scene", "--exemplar-frame", "--guides", "--frames",
                "--out", "--temporal", "--chunk-size", "--scheduler", "--workers", "--retries", "--tempera"}
FARM_FLAGS = {"--no-video", "--dry-run", "-h", "--help"}
GUIDE_OPTIONS = {"--samples", "--blender", "--addon-path"}
PASS_FLAGS = {"--no-resume"}


def _split_argv(argv):
    """(the farm's own arguments, render-guides options, stylize options)."""
    own, guide_args, stylize_args = [], [], []
    i = 0
    while i < len(argv):
        word = argv[i]
        key = word.split("=", 1)[0]
        takes_value = "=" not in word and key not in FARM_FLAGS and key not in PASS_FLAGS and i + 1 < len(argv)
        group = own if (key in FARM_OPTIONS or key in FARM_FLAGS or not word.startswith("-")) else (
            guide_args if key in GUIDE_OPTIONS else stylize_args)
        if word.startswith("-") and takes_value:
            group.extend(argv[i:i + 2])
            i += 2
        else:
            group.append(word)
            i += 1
    return own, guide_args, stylize_args


def parse_args(argv):
    own, guide_args, stylize_args = _split_argv(list(argv))
    parser = argparse.ArgumentParser(
        prog="tempera farm", description="Stylize a shot on a Dask cluster (see tempera.app.farm). Options "
        "not listed here are passed to the tasks: --samples, --blender and --addon-path to render-guides, "
        "all others to stylize.")
    parser.add_argument("scene", nargs="?", help="the shot's .blend (its guides are rendered); "
                        "or give --guides")
    parser.add_argument("--exemplar", required=True)
    parser.add_argument("--exemplar-guides")
    parser.add_argument("--exemplar-scene")
    parser.add_argument("--exemplar-frame", type=int, default=1)
    parser.add_argument("--guides")
    parser.add_argument("--frames", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--temporal", type=float, default=None,
                        help="weight of the temporal guide (default: tempera stylize's)")
    parser.add_argument("--no-video", action="store_true")
    parser.add_argument("--chunk-size", type=int, default=DEFAULT_CHUNK_SIZE, help="frames per task (default 8)")
    parser.add_argument("--scheduler", help="Dask scheduler address (default: start a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="local cluster size (default 2)")
    parser.add_argument("--retries", type=int, default=2, help="reruns of a task whose worker died")
    parser.add_argument("--tempera", help="the command workers run (default: tempera on PATH)")
    parser.add_argument("--dry-run", action="store_true", help="print the tasks, run nothing")
    return parser.parse_args(own), guide_args, stylize_args


def main(argv=None):
    args, guide_args, stylize_args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        tempera = shlex.split(args.tempera) if args.tempera else default_tempera()
        tasks = plan(args.frames, args.out, args.exemplar, scene=args.scene, guides=args.guides,
                     exemplar_guides=args.exemplar_guides, exemplar_scene=args.exemplar_scene,
                     exemplar_frame=args.exemplar_frame, chunk_size=args.chunk_size, temporal=args.temporal,
                     tempera=tempera, guide_args=guide_args, stylize_args=stylize_args,
                     video=not args.no_video)
        if args.dry_run:
            for task in tasks:
                after = f"   (after {', '.join(task.depends)})" if task.depends else ""
                print(f"{task.name}: {shlex.join(task.command)}{after}")
            return 0
        outputs = run_dask(tasks, args.scheduler, args.workers, args.retries)
    except FarmError as exc:
        print(f"tempera farm: {exc}", file=sys.stderr)
        return 1
    print(outputs["finish"].rstrip())
    return 0


if __name__ == "__main__":
    sys.exit(main())
