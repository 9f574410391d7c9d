"""Issue 31, item 1: a full disk never leaves a truncated frame under its final name.

A full disk is simulated without privileges: a file size limit (RLIMIT_FSIZE,
with SIGXFSZ ignored) makes every write past the limit fail with EFBIG, as
ENOSPC does, and image writers do not always report it. Every image Tempera
writes must read back whole before it replaces anything; the earlier file
stays, nothing is recorded, and the next run with room heals."""
import resource
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import tempera
from conftest import cli_path  # noqa: F401  (the fixture)


def limit_file_size(limit):
    def before_exec():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of death; kept across exec
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return before_exec


def noise(h=160, w=200, c=3, seed=0):
    return np.random.default_rng(seed).random((h, w, c)).astype(np.float32)  # incompressible


@pytest.mark.parametrize("extension", ["png", "exr"])
def test_a_write_that_does_not_fit_raises_and_keeps_the_earlier_file(tmp_path, extension):
    path = tmp_path / f"frame_0001.{extension}"
    tempera.write_image(str(path), noise(16, 16))
    before = path.read_bytes()
    code = textwrap.dedent(f"""
        import numpy as np, tempera
        image = np.random.default_rng(1).random((160, 200, 3)).astype(np.float32)
        try:
            tempera.write_image({str(path)!r}, image)
        except OSError as exc:
            print("OSError:", exc)
        else:
            print("written")
        """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                            preexec_fn=limit_file_size(len(before) + 4096))
    assert result.returncode == 0, result.stderr
    assert "OSError:" in result.stdout and "frame_0001" in result.stdout, result.stdout
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no temporary left behind


def test_noisy_fails_on_a_full_disk_and_the_next_run_heals(cli_path, tmp_path):
    tempera.write_image(str(tmp_path / "medium.png"), noise(64, 64))
    (tmp_path / "R").mkdir()
    for f in (1, 2):
        tempera.write_image(str(tmp_path / "R" / f"frame_{f:04d}.png"), noise(120, 160, seed=f))
    args = [str(cli_path), "noisy", "--exemplar", str(tmp_path / "medium.png"), "--reference", str(tmp_path / "R"),
            "--frames", "1-2", "--out", str(tmp_path / "out"), "--noise", "2.2", "--threads", "2"]
    first = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    made = {f: (tmp_path / "out" / f"frame_{f:04d}.png").read_bytes() for f in (1, 2)}

    full = subprocess.run(args + ["--seed", "2"], capture_output=True, text=True, timeout=300,
                          preexec_fn=limit_file_size(4096))
    assert full.returncode == 1, (full.returncode, full.stdout, full.stderr)
    assert "frame_0001.png" in full.stderr
    assert (tmp_path / "out" / "frame_0001.png").read_bytes() == made[1]  # the earlier frame, whole

    healed = subprocess.run(args + ["--seed", "2"], capture_output=True, text=True, timeout=300)
    assert healed.returncode == 0, healed.stderr
    assert "2 frame(s) made" in healed.stdout
    for f in (1, 2):
        image = tempera.read_image(str(tmp_path / "out" / f"frame_{f:04d}.png"))
        assert image.shape == (120, 160, 3)


def test_a_finished_job_is_not_failed_by_its_contact_sheet(cli_path, tmp_path):
    """Issue 31, smaller: a folder that cannot take the contact sheet (read-only,
    or full) failed a job whose frames were all done. Now that is a warning."""
    from synthetic_cache import make_cache, make_exemplar

    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    args = [str(cli_path), "stylize", "--guides", str(tmp_path / "cache"), "--exemplar", str(tmp_path / "paint.png"),
            "--exemplar-guides", str(tmp_path / "exemplar"), "--frames", "1-3", "--out", str(tmp_path / "out"),
            "--no-video", "--levels", "2"]
    assert subprocess.run(args, capture_output=True, text=True, timeout=300).returncode == 0
    frames = {p.name: p.read_bytes() for p in (tmp_path / "out" / "frames").glob("frame_*.png")}
    again = subprocess.run(args, capture_output=True, text=True, timeout=300, preexec_fn=limit_file_size(256))
    assert again.returncode == 0, again.stderr
    assert "warning: the contact sheet was not written" in again.stderr and "the frames are done" in again.stderr
    assert "0 frame(s) stylized, 3 skipped" in again.stdout
    assert {p.name: p.read_bytes() for p in (tmp_path / "out" / "frames").glob("frame_*.png")} == frames
