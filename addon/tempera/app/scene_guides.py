"""`tempera stylize SCENE.blend --method M ...` for a method written in
Python (the rigid-body method): the scene's guide cache is rendered first by
the native `tempera render-guides`, as the native command does for its own
methods (native/cli/scene_guides.hpp), then the method runs on the cache."""
from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

# Flags that go to Blender's guide render, not to the method.
RENDER_FLAGS = ("--samples", "--blender", "--addon-path")


def _last_value(argv, name):
    values = [b for a, b in zip(argv, argv[1:]) if a == name]
    return values[-1] if values else None


def with_scene_guides(argv, prog="tempera stylize"):
    """The method's arguments once a scene's guides are rendered: when `argv`
    starts with a scene file, its guides are rendered into --guides (default
    OUT/guides; frames already current are reused) and the scene and the
    render flags are taken out; otherwise (no scene, or --help) `argv` as it is."""
    if not argv or argv[0].startswith("-") or "--help" in argv or "-h" in argv:
        return list(argv)
    scene, rest, render = argv[0], [], []
    i = 1
    while i < len(argv):
        if argv[i] in RENDER_FLAGS and i + 1 < len(argv):
            render += [argv[i], argv[i + 1]]
            if argv[i] == "--samples":  # as the native command: both renders
                render += ["--ld12e-samples", argv[i + 1]]
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    frames, out = _last_value(rest, "--frames"), _last_value(rest, "--out")
    if frames is None:
        raise ValueError("--frames is required with a scene (the frames whose guides are rendered, e.g. 1-48)")
    if out is None:
        raise ValueError("--out is required (the output folder)")
    guides = _last_value(rest, "--guides") or _last_value(rest, "--cache")
    if guides is None:
        guides = str(Path(out) / "guides")
        rest += ["--guides", guides]
    render_scene_guides(scene, frames, guides, render, prog)
    return rest


def _die_with_parent():
    """In the child: SIGTERM when this process dies, even by kill -9 (Linux), so
    that no render outlives the command that started it."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def render_scene_guides(scene, frames, out, options=(), prog="tempera stylize"):
    """Runs `tempera render-guides SCENE --frames FRAMES --out OUT OPTIONS`.
    ValueError (its status 2), OSError (another failure, or no native CLI),
    KeyboardInterrupt on Ctrl-C or SIGTERM, which stop the render too."""
    from ..__main__ import PACKAGE_PARENT, native_cli

    print(f"{prog}: rendering the guides of {scene} (frames {frames}) into {out}", file=sys.stderr, flush=True)
    env = dict(os.environ)
    env.setdefault("TEMPERA_ADDON_PATH", str(PACKAGE_PARENT))
    command = [str(native_cli()), "render-guides", os.path.abspath(scene), "--frames", str(frames),
               "--out", str(out), *options]
    child = subprocess.Popen(command, env=env, preexec_fn=_die_with_parent)
    stopped = []

    def stop(_signum, _frame):
        stopped.append(True)
        child.terminate()  # the native command stops Blender, then exits 130

    main = threading.current_thread() is threading.main_thread()  # only there can a handler be set
    previous = signal.signal(signal.SIGTERM, stop) if main else None
    try:
        status = child.wait()
    except KeyboardInterrupt:
        child.terminate()
        child.wait()
        raise
    finally:
        if main:
            signal.signal(signal.SIGTERM, previous)
    if stopped or status in (130, -signal.SIGINT, -signal.SIGTERM):
        raise KeyboardInterrupt
    if status == 2:
        raise ValueError(f"rendering the guides of '{scene}' failed: bad values (see above)")
    if status != 0:
        raise OSError(f"rendering the guides of '{scene}' failed (see above)")
