"""Inside background Blender for `tempera render-guides SCENE.blend ...`: renders
the guide cache of the opened file's scene and exits non-zero with a clear
message on any problem. The .blend on disk is never written.

    blender -b --factory-startup SCENE.blend --python-exit-code 1 \\
        --python-expr "...; from tempera.blender.render_guides_main import main; main()" \\
        -- --frames 1-24 --out DIR [--scene NAME] [--samples N] [--lpe EXPR ...] ...
"""
import argparse
import ctypes
import os
import shutil
import sys
import time
import traceback
from pathlib import Path

import bpy

from ..app import guide_cache
from ..app.frames import parse_frames
from .guide_render import GuideRenderError, render_guides

# Exit statuses, mapped by the `tempera` CLI (native/cli/render_guides_command.cpp):
EXIT_BAD_VALUE = 2  # a bad option value or scene setting (argparse uses 2 too)
EXIT_FILE_ERROR = 3  # a file that cannot be read or written (the CLI reports 1)
EXIT_INTERRUPTED = 130

# Command-line flags for the guide parameters (see guide_cache.DEFAULT_PARAMS).
PARAM_FLAGS = {
    "samples": ("--samples", int),
    "ld12e_samples": ("--ld12e-samples", int),
    "seed": ("--seed", int),
    "occlusion_epsilon": ("--epsilon", float),
    "tensor_sigma": ("--tensor-sigma", float),
    "line_depth_threshold": ("--line-depth-threshold", float),
    "line_normal_angle": ("--line-normal-angle", float),
    "line_d_max": ("--d-max", float),
    "masks": ("--masks", str),
    "orientation_aov": ("--orientation-aov", str),
    "lpe_samples": ("--lpe-samples", int),
}


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="tempera render-guides", description="Render a scene's guide cache.")
    parser.add_argument("--frames", required=True, help="e.g. 1-24 or 1-10,15")
    parser.add_argument("--out", required=True, help="guide cache folder")
    parser.add_argument("--scene", help="scene name (default: the file's active scene)")
    for key, (flag, kind) in PARAM_FLAGS.items():
        parser.add_argument(flag, dest=key, type=kind, help=f"default {guide_cache.DEFAULT_PARAMS[key]}")
    parser.add_argument("--lpe", action="append", metavar="EXPR",
                        help="a light path expression to trace as a guide (repeat for more), e.g. 'L.*SDE'")
    return parser.parse_args(argv)


def main():
    """Renders the guides, then ends Blender at once with the exit status of
    the run (see quit_at_once)."""
    try:
        status = render()
    except Exception:  # a bug: said as Blender says it, and the status --python-exit-code 1 gives
        traceback.print_exc()
        status = 1
    quit_at_once(status)


def render():
    """The run; returns its exit status (0, or EXIT_* after the error line)."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        args = parse_args(argv)
    except SystemExit as exc:  # argparse: --help (0) or a bad option, after the usage line (2)
        return exc.code if isinstance(exc.code, int) else EXIT_BAD_VALUE
    try:
        frames = parse_frames(args.frames)
        scene = bpy.data.scenes.get(args.scene) if args.scene else bpy.context.scene
        if scene is None:
            names = ", ".join(s.name for s in bpy.data.scenes)
            raise ValueError(f"no scene named {args.scene!r} in {bpy.data.filepath} (it has: {names})")
        params = {key: getattr(args, key) for key in PARAM_FLAGS if getattr(args, key) is not None}
        if args.lpe:
            params["lpe"] = args.lpe
        started = time.monotonic()

        def progress(done, total, message):
            elapsed = time.monotonic() - started
            eta = elapsed / done * (total - done) if done else 0.0
            print(f"tempera render-guides: {done}/{total} {message} (ETA {eta:.0f} s)", flush=True)

        report = render_guides(scene, frames, args.out, params, progress)
        for warning in report["warnings"]:
            print(f"tempera render-guides: warning: {warning}", flush=True)
    except (GuideRenderError, ValueError) as exc:
        print(f"tempera render-guides: error: {exc}", file=sys.stderr, flush=True)
        return EXIT_BAD_VALUE
    except OSError as exc:
        print(f"tempera render-guides: error: {exc}", file=sys.stderr, flush=True)
        return EXIT_FILE_ERROR
    except KeyboardInterrupt:
        print("tempera render-guides: interrupted; the frames finished so far are in the cache, rerun the same "
              "command to render the rest", file=sys.stderr, flush=True)
        return EXIT_INTERRUPTED
    print(f"tempera render-guides: rendered {len(report['rendered'])} frame(s), "
          f"{len(report['skipped'])} already current; manifest {report['manifest']}", flush=True)
    return 0


def quit_at_once(status):
    """Ends this Blender with `status` without running the shared libraries'
    exit-time destructors, once every file is written and closed.

    The wheel's native module brings its own copies (hashed sonames) of
    OpenImageIO and its ~230 dependencies into a Blender that already loaded
    the system's (Debian's Blender 3.4: gdcm, gnutls, OpenEXR, TBB, ...).
    Symbol interposition binds both copies' static objects to one of them,
    so at exit they are destroyed twice and Blender often dies with SIGSEGV
    after "Blender quit" (tests/wheel/test_dask_farm.py, two chunks at a
    time). Blender's own quit does nothing else for a background run that
    never saves: it removes its session temporary folder, done here too.
    """
    sys.stdout.flush()
    sys.stderr.flush()
    ctypes.CDLL(None).fflush(None)  # Blender's own printf lines (render stats) still in C's buffers
    session = Path(bpy.app.tempdir)
    if session.name.startswith("blender_"):  # its own mkdtemp folder, never the system's /tmp it falls back to
        shutil.rmtree(session, ignore_errors=True)
    os._exit(status)
