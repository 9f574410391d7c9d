"""fuzz_rigid: the rigid-body method's command on random and mutated inputs
(issue 31): its files (a guide cache's and an exemplar's tracks.json, and the
cache's manifest.json) and its options, each input a whole run of the native
`tempera stylize --method rigid` (read, check, fit, draw one frame, write).
tests/fuzz/fuzz_main.cpp fuzzes the native entry points in-process; `make
fuzz` runs both, and tests/python/test_fuzz_rigid.py runs this briefly in
every `make test`.

    PYTHONPATH=addon python3 tests/fuzz/fuzz_rigid.py [--seconds S] [--seed N]
                                                     [--only tracks|options] [--work DIR]
                                                     [--tempera PATH]

A run must end with exit status 0, 1 (a file) or 2 (a bad value), with a
message when it is not 0; a signal (a crash), another status, or a frame
that does not read back is a finding. Each finding's input is saved in the
work folder, and the exit status is 1.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tempera import _native
from tempera.methods.rigid import rigid, rigid_tracks

ROOT = Path(__file__).resolve().parents[2]

W, H = 96, 64
FRAMES = 12


def make_exemplar(folder):
    folder.mkdir(parents=True)
    track = _native.bouncing_ball((12, 16), (2.0, 0), 6, 1.2, 60, 0.6, 0.05, FRAMES)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 1.2))
    (folder / "drawn").mkdir()
    for i, drawing in enumerate(rigid.generated_exemplar(track, W, H)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), drawing, [])


def make_cache(folder):
    folder.mkdir(parents=True)
    track = _native.bouncing_ball((80, 12), (-1.5, 0), 6, 1.0, 60, 0.7, -0.05, FRAMES)
    rigid_tracks.write_tracks(folder, {"Target": track}, 1, (0, 1.0))
    (folder / "manifest.json").write_text(json.dumps({"resolution": [W, H]}))


# ------------------------------------------------------------------ mutations

ODD_VALUES = [float("nan"), float("inf"), -float("inf"), 1e300, -1e300, 1e-300, 0, -1, 1, 2**31, 2**63, -2**63,
              0.5, True, False, None, "", "1", "left", [], [1], [1, 2, 3], {}, {"a": 1}, [[1, 2]] * 3]


def mutate_value(rng, value, depth=0):
    """A JSON value with one node replaced, removed, repeated or retyped."""
    if isinstance(value, dict) and value and rng.random() < 0.8:
        key = rng.choice(list(value))
        out = dict(value)
        roll = rng.random()
        if roll < 0.1:
            del out[key]
        elif roll < 0.2:
            out[key + "x"] = out[key]
        else:
            out[key] = mutate_value(rng, value[key], depth + 1)
        return out
    if isinstance(value, list) and value and rng.random() < 0.8:
        out = list(value)
        i = rng.randrange(len(out))
        roll = rng.random()
        if roll < 0.1:
            del out[i]
        elif roll < 0.2:
            out.insert(i, out[i])
        elif roll < 0.25:
            out = out[:i]
        else:
            out[i] = mutate_value(rng, out[i], depth + 1)
        return out
    if isinstance(value, (int, float)) and not isinstance(value, bool) and rng.random() < 0.5:
        return value * rng.choice([-1, 0.5, 2, 10, 1e6, 1e-6]) + rng.choice([0, 1, -1, 0.25])
    return rng.choice(ODD_VALUES)


def mutate_bytes(rng, data):
    data = bytearray(data)
    for _ in range(1 + rng.randrange(6)):
        if not data:
            data.append(rng.randrange(256))
        at = rng.randrange(len(data))
        roll = rng.randrange(5)
        if roll == 0:
            data[at] = rng.randrange(256)
        elif roll == 1:
            del data[at:at + rng.randrange(32)]
        elif roll == 2:
            data[at:at] = rng.choice([b"[", b"{", b"]", b"}", b",", b"NaN", b"1e999", b"-", b'"', b"\xff"])
        elif roll == 3:
            data[at:at] = data[rng.randrange(len(data)):][:rng.randrange(64)]
        else:
            del data[at:]
    return bytes(data)


def mutate_json_file(rng, text):
    if rng.random() < 0.3:
        return mutate_bytes(rng, text.encode())
    value = json.loads(text)
    for _ in range(1 + rng.randrange(3)):
        value = mutate_value(rng, value)
    return json.dumps(value).encode()  # NaN and Infinity as Python writes them, as a user's script would


# ------------------------------------------------------------------ running

class Fuzz:
    def __init__(self, work, tempera):
        self.work = work
        self.tempera = tempera
        self.findings = 0
        self.statuses = {}

    def run(self, target, argv, saved_input):
        """Runs `tempera stylize --method rigid argv`; returns the status,
        counting a finding when it is not one of Tempera's."""
        try:
            done = subprocess.run([str(self.tempera), "stylize", "--method", "rigid", *argv], capture_output=True,
                                  text=True, errors="replace", timeout=120)
        except subprocess.TimeoutExpired:
            return self.finding(target, "no end within 120 s", argv, saved_input)
        status, said = done.returncode, done.stderr
        self.statuses[status] = self.statuses.get(status, 0) + 1
        if status not in (0, 1, 2):  # a signal (negative) or a status of no one's
            return self.finding(target, f"exit status {status}: {said[-300:]}", argv, saved_input)
        if status in (1, 2) and not said.strip():
            return self.finding(target, f"exit status {status} with no message", argv, saved_input)
        return status

    def finding(self, target, what, argv, saved_input):
        folder = self.work / f"finding_{target}_{self.findings}"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "argv.json").write_text(json.dumps(argv))
        for name, data in saved_input.items():
            (folder / name).write_bytes(data)
        print(f"fuzz_rigid: {target}: {what} (input saved in {folder})", flush=True)
        self.findings += 1
        return None


def check_frames(fuzz, target, out, argv, saved_input):
    """Every frame a run wrote must read back as finite RGBA of the manifest's size."""
    for path in sorted(Path(out).glob("frame_*.png")):
        image = _native.read_image(str(path), None)
        if image.shape[2] != 4 or not math.isfinite(float(image.sum())):
            fuzz.finding(target, f"{path.name}: shape {image.shape} or values not finite", argv, saved_input)


def fuzz_tracks(fuzz, rng, more):
    """The target's tracks.json, the exemplar's tracks.json and the manifest, mutated."""
    clean = fuzz.work / "clean"
    make_cache(clean / "cache")
    make_exemplar(clean / "ex")
    originals = {
        "cache/tracks.json": (clean / "cache" / rigid_tracks.TRACKS_NAME).read_text(),
        "ex/tracks.json": (clean / "ex" / rigid_tracks.TRACKS_NAME).read_text(),
        "cache/manifest.json": (clean / "cache" / "manifest.json").read_text(),
    }
    run = fuzz.work / "tracks"
    while more():
        shutil.rmtree(run, ignore_errors=True)
        shutil.copytree(clean, run)
        which = rng.choices(list(originals), weights=[6, 3, 1])[0]
        data = mutate_json_file(rng, originals[which])
        (run / which).write_bytes(data)
        argv = ["--guides", str(run / "cache"), "--exemplar", str(run / "ex"), "--out", str(run / "out"),
                "--frames", str(1 + rng.randrange(FRAMES))]
        if fuzz.run("tracks", argv, {which.replace("/", "_"): data}) == 0:
            check_frames(fuzz, "tracks", run / "out" / "frames", argv, {which.replace("/", "_"): data})


def option_flags(tempera):
    """Every option of the method, from its help (so a new one is fuzzed at once)."""
    shown = subprocess.run([str(tempera), "stylize", "--method", "rigid", "--help"], capture_output=True, text=True,
                           timeout=60).stdout
    given = {"--help", "--guides", "--exemplar", "--out", "--method"}
    return sorted({f for f in re.findall(r"^\s+(--[a-z][a-z0-9-]*)", shown, re.M) if f not in given})


OPTION_VALUES = ["0", "1", "-1", "2", "0.5", "1e300", "-1e300", "nan", "inf", "-inf", "1,2", "1,nan", ",", "",
                 "true", "false", "circle", "box", "3-1", "1-99999", "x", "1e-300", "4096", "2147483648",
                 "generated", "missing.png", "1-4", "5"]


def fuzz_options(fuzz, rng, more):
    """Random option lines on good inputs."""
    inputs = fuzz.work / "inputs"
    make_cache(inputs / "cache")
    make_exemplar(inputs / "ex")
    flags = option_flags(fuzz.tempera)
    out = fuzz.work / "options_out"
    while more():
        shutil.rmtree(out, ignore_errors=True)
        argv = ["--guides", str(inputs / "cache"), "--exemplar", str(inputs / "ex"), "--out", str(out),
                "--frames", "3"]
        for _ in range(rng.randrange(8)):
            argv.append(rng.choice(flags))
            if rng.random() < 0.85:
                value = rng.choice(OPTION_VALUES)
                argv.append(value if rng.random() < 0.9 else mutate_bytes(rng, value.encode()).decode("latin-1"))
        if fuzz.run("options", argv, {}) == 0:
            check_frames(fuzz, "options", out / "frames", argv, {})


TARGETS = {"tracks": fuzz_tracks, "options": fuzz_options}


def main(argv=None):
    p = argparse.ArgumentParser(prog="fuzz_rigid", description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=10)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--only", choices=list(TARGETS))
    p.add_argument("--work", type=Path)
    p.add_argument("--tempera", type=Path, default=Path(os.environ.get("TEMPERA_CLI", ROOT / "build" / "bin" / "tempera")),
                   help="the native CLI (default $TEMPERA_CLI, else build/bin/tempera)")
    args = p.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="tempera-fuzz-rigid-"))
    work.mkdir(parents=True, exist_ok=True)
    fuzz = Fuzz(work, args.tempera)
    targets = [args.only] if args.only else list(TARGETS)
    each = args.seconds / len(targets)
    for name in targets:
        rng = random.Random(args.seed)
        end = time.monotonic() + each
        runs = [0]

        def more():
            runs[0] += 1
            return time.monotonic() < end
        fuzz.statuses = {}
        TARGETS[name](fuzz, rng, more)
        print(f"fuzz_rigid: {name}: {runs[0] - 1} inputs in {each:g} s, exit statuses {dict(sorted(fuzz.statuses.items()))}",
              flush=True)
    if not args.work and fuzz.findings == 0:
        shutil.rmtree(work)
    print(f"fuzz_rigid: {fuzz.findings} finding(s)" + (f" (inputs in {work})" if fuzz.findings else ""))
    return 1 if fuzz.findings else 0


if __name__ == "__main__":
    sys.exit(main())
