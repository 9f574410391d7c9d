"""Issue 31, item 1, for every writer: a full disk in the middle of a run of
new settings leaves no damaged frame and nothing wrongly current.

For each method: a run with room (settings A), then a run of settings B with
the disk full (a file size limit: RLIMIT_FSIZE with SIGXFSZ ignored, so a
write fails with EFBIG as with ENOSPC), then B again with room. The full run
fails ("is the disk full?"); every frame then in the output folder reads back whole; and
the rerun makes B's frames byte for byte as a fresh run of B does."""
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import tempera
from tempera.app import guide_cache

from synthetic_cache import make_cache, make_exemplar
from test_full_disk import limit_file_size
from test_fluidymation import make_inputs

ADDON = Path(__file__).resolve().parents[2] / "addon"


def stylit(p, cli):
    make_cache(p / "cache", frames=(1, 2, 3, 4, 5), forward=True)
    make_exemplar(p / "exemplar", p / "paint.png")
    base = [str(cli), "stylize", "--guides", str(p / "cache"), "--exemplar", str(p / "paint.png"),
            "--exemplar-guides", str(p / "exemplar"), "--frames", "1-3", "--no-video", "--threads", "1",
            "--levels", "2"]
    return lambda out, b: base + ["--out", str(out), "--seed", "2" if b else "1"], "frames"


def tcia(p, cli):
    command, folder = stylit(p, cli)
    return lambda out, b: command(out, b) + ["--method", "tcia", "--frames", "1-5", "--patch-size", "7"], folder


def lazyfluids(p, cli):
    from test_lazyfluids import disc, flow, smoke

    for f in (1, 2, 3):
        guide_cache.write_frame(p / "cache", f, {"alpha": disc(14 + 2 * f), "fluid_velocity": flow()})
    tempera.write_image(str(p / "smoke.png"), smoke())
    base = [str(cli), "stylize", "--method", "lazyfluids", "--guides", str(p / "cache"), "--exemplar",
            str(p / "smoke.png"), "--frames", "1-3", "--em-iters", "1", "--threads", "1"]
    return lambda out, b: base + ["--out", str(out), "--seed", "2" if b else "1"], "frames"


def fluidymation(p, cli):
    exemplar, cache = make_inputs(p, frames=3)
    base = [str(cli), "stylize", "--method", "fluidymation", "--guides", str(cache), "--exemplar", str(exemplar),
            "--frames", "1-3", "--levels", "2", "--shape-blur", "6", "--threads", "1"]
    return lambda out, b: base + ["--out", str(out), "--seed", "2" if b else "1"], "frames"


def noisy(p, cli):
    medium = np.random.default_rng(4).random((64, 64, 3)).astype(np.float32)
    tempera.write_image(str(p / "medium.png"), medium)
    (p / "R").mkdir()
    for f in (1, 2, 3):
        tempera.write_image(str(p / "R" / f"frame_{f:04d}.png"), np.roll(medium, f, axis=1)[4:44, 6:54].copy())
    base = [str(cli), "noisy", "--exemplar", str(p / "medium.png"), "--reference", str(p / "R"), "--frames", "1-3",
            "--noise", "2.2", "--threads", "1"]
    return lambda out, b: base + ["--out", str(out), "--seed", "2" if b else "1"], "."


def rigid(p, cli):
    from test_cli_rigid import _cache, _exemplar

    (p / "ex").mkdir()
    (p / "cache").mkdir()
    _exemplar(p / "ex")
    _cache(p / "cache")
    base = [str(cli), "stylize", "--method", "rigid", "--guides", str(p / "cache"), "--exemplar", str(p / "ex"),
            "--frames", "1-10"]
    return lambda out, b: base + ["--out", str(out), "--k", "1" if b else "2"], "frames"


@pytest.mark.parametrize("method", [stylit, tcia, lazyfluids, fluidymation, noisy, rigid],
                         ids=lambda m: m.__name__)
def test_a_full_disk_leaves_no_damaged_frame_and_the_rerun_heals(cli_path, tmp_path, method):
    command, folder = method(tmp_path, cli_path)
    env = dict(os.environ, PYTHONPATH=str(ADDON))

    def run(out, b, limit=None):
        return subprocess.run(command(out, b), capture_output=True, text=True, timeout=600, env=env,
                              preexec_fn=limit_file_size(limit) if limit else None)

    out = tmp_path / "out"
    assert run(out, False).returncode == 0
    full = run(out, True, limit=256)
    assert full.returncode == 1 and ("cannot write" in full.stderr or "disk full" in full.stderr), full.stderr[-500:]
    frames = sorted((out / folder).glob("frame_*.*"))
    assert frames
    for frame in frames:  # every frame there is whole: A's, or B's made before the disk filled
        assert tempera.read_image(str(frame)).size > 0, frame
    healed = run(out, True)
    assert healed.returncode == 0, healed.stderr[-2000:]
    fresh = tmp_path / "fresh"
    assert run(fresh, True).returncode == 0
    made = sorted(p.name for p in (fresh / folder).glob("frame_*.*"))
    assert made and made == sorted(p.name for p in (out / folder).glob("frame_*.*"))
    for name in made:
        assert (out / folder / name).read_bytes() == (fresh / folder / name).read_bytes(), name
