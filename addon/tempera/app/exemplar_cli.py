"""`tempera exemplar`: writes one of the exemplars the project makes itself
(tempera.app.media_exemplars) as a folder of PNG frames, with no Blender.

    tempera exemplar smoke|fire|ink --out DIR [--size WxH] [--frames N]
                     [--speed S] [--seed N]

smoke and fire: DIR/frame_0001.png ... RGBA (straight alpha); one frame is
the still, more frames a seamless loop. ink: DIR/frame_0001.png ... RGB over
paper and DIR/masks/frame_0001.png ... the pigment masks; --speed is the
wet front's speed in px per frame (ink only). Exit status 2 on bad input,
naming it.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

import numpy as np

from .. import _native
from . import exemplar_kit, media_exemplars
from .command import run_command

DEFAULT_SIZE = (256, 256)
DEFAULT_FRAMES = 24
DEFAULT_SPEED = 2.0


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise ValueError(message)


def _parser():
    p = _Parser(prog="tempera exemplar", description=__doc__.split("\n\n")[0])
    p.add_argument("kind", choices=[*media_exemplars.KINDS, "ink"], help="which exemplar")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--size", default=f"{DEFAULT_SIZE[0]}x{DEFAULT_SIZE[1]}", help="WxH in pixels (256x256)")
    p.add_argument("--frames", type=int, default=DEFAULT_FRAMES, help=f"number of frames ({DEFAULT_FRAMES})")
    p.add_argument("--speed", type=float, help=f"ink only: front speed in px per frame ({DEFAULT_SPEED})")
    p.add_argument("--seed", type=int, default=1, help="random seed (1)")
    return p


def parse_size(text):
    """(width, height) of a 'WxH' text; ValueError naming the problem."""
    width, x, height = str(text).lower().partition("x")
    try:
        return int(width), int(height)
    except ValueError:
        raise ValueError(f"--size expects WxH in pixels (e.g. 256x256), got '{text}'") from None


def run(args):
    width, height = parse_size(args.size)
    if args.kind == "ink":
        speed = DEFAULT_SPEED if args.speed is None else args.speed
        frames, masks = media_exemplars.ink_video(width, height, args.frames, speed, args.seed)
    else:
        if args.speed is not None:
            raise ValueError(f"--speed is for ink only (the front's speed), not {args.kind}")
        frames, masks = media_exemplars.smoke_loop(width, height, args.frames, args.seed, args.kind), None
    media_exemplars.write_frames(args.out, frames, masks)
    print(f"tempera exemplar: {len(frames)} {args.kind} frames of {width}x{height} in {args.out}")
    return 0


def generated_folder(out, kind):
    """The project's own `kind` exemplar (smoke, fire, ink) as a folder of
    RGBA frames in OUT, OUT/exemplar_generated_KIND/frame_0001.png ..., at
    this command's defaults (256x256, 24 frames, seed 1); ink's pigment masks
    are its alpha. Written once, under a temporary name renamed at the end,
    so a folder that exists is whole and a rerun reuses it (resume)."""
    folder = Path(out) / f"exemplar_generated_{kind}"
    if folder.is_dir():
        return folder
    width, height = DEFAULT_SIZE
    if kind == "ink":
        rgb, masks = media_exemplars.ink_video(width, height, DEFAULT_FRAMES, DEFAULT_SPEED, 1)
        frames = [np.dstack([colour, mask]).astype(np.float32) for colour, mask in zip(rgb, masks)]
    else:
        frames = media_exemplars.smoke_loop(width, height, DEFAULT_FRAMES, 1, kind)
    partial = folder.with_name(f".{folder.name}.partial{os.getpid()}")
    shutil.rmtree(partial, ignore_errors=True)
    media_exemplars.write_frames(partial, frames)
    try:
        os.rename(partial, folder)
    except OSError:  # another run wrote it meanwhile: keep theirs
        shutil.rmtree(partial, ignore_errors=True)
        if not folder.is_dir():
            raise
    return folder


def with_default_exemplar(args, entry):
    """`tempera stylize` arguments with `--exemplar OUT/exemplar_generated_KIND`
    added when the method has a default exemplar (its registry entry's
    ``default_exemplar``) and none is given; else the arguments as they are
    (the command then names what is missing)."""
    kind = entry["default_exemplar"]
    if not kind or kind == _native.JOB_MADE_EXEMPLAR or "--exemplar" in args or "--help" in args or "-h" in args:
        return list(args)
    if kind == _native.KIT_EXEMPLAR:
        return with_kit_exemplar(args)
    at = args.index("--out") if "--out" in args else len(args)
    if at + 1 >= len(args):
        return list(args)
    folder = generated_folder(args[at + 1], kind)
    print(f"tempera stylize: no --exemplar given: using the project's own {kind} exemplar, {folder}",
          file=sys.stderr, flush=True)
    return [*args, "--exemplar", str(folder)]


def with_kit_exemplar(args):
    """The arguments with the bundled kit's painting and guide cache as the
    exemplar (a light-path method's), unless the exemplar's guides or scene
    are given (the command then names what is missing). FileNotFoundError
    naming the kit when this install has none."""
    if "--exemplar-guides" in args or "--exemplar-scene" in args:
        return list(args)
    style, guides = exemplar_kit.kit_exemplar()
    print(f"tempera stylize: no --exemplar given: using the bundled exemplar kit, {style}", file=sys.stderr,
          flush=True)
    return [*args, "--exemplar", str(style), "--exemplar-guides", str(guides)]


def main(argv=None):
    return run_command("tempera exemplar", lambda: run(_parser().parse_args(argv)))
