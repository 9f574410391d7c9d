"""The programs Tempera starts, Blender and ffmpeg (issue 31, items 7-9).

Paths are never read as their options or URLs: a scene named '-P' would make
Blender run the next argument as Python, '-a' start its player; ffmpeg reads
a relative '-y' or '-dash/…' as an option and 'shot:01/…' as a URL. And
Blender never outlives the command that started it."""
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import tempera
from tempera.app import media_source
from tempera.app.video import encode_video

FFMPEG = shutil.which("ffmpeg")
needs_ffmpeg = pytest.mark.skipif(FFMPEG is None, reason="ffmpeg is not on PATH")
# What Tempera itself passes to Blender before '--' (render_guides_command.cpp).
BLENDER_OPTIONS = {"-b", "--factory-startup", "--python-exit-code", "--python-expr"}


def stand_in_blender(tmp_path, name, body):
    """An executable Python script `name` that does `body` where Tempera expects Blender."""
    script = tmp_path / name
    script.write_text(f"#!{sys.executable}\nimport os, sys, time\n{body}\n")
    script.chmod(0o755)
    return script


def fake_blender(tmp_path):
    """A stand-in for Blender that appends its arguments, one call a line, to calls.txt."""
    calls = tmp_path / "calls.txt"
    return stand_in_blender(tmp_path, "blender", f"open({str(calls)!r}, 'a').write(repr(sys.argv[1:]) + '\\n')"), calls


def blender_calls(calls):
    return [eval(line) for line in calls.read_text().splitlines()] if calls.is_file() else []


def options_before_double_dash(argv):
    """Every argument before '--' that Blender would take as an option, minus Tempera's own."""
    head = argv[:argv.index("--")] if "--" in argv else argv
    values_of = {"--python-exit-code", "--python-expr"}  # their values are Tempera's, not options
    skip, found = False, []
    for arg in head:
        if skip:
            skip = False
        elif arg in values_of:
            skip = True
        elif arg.startswith("-") and arg not in BLENDER_OPTIONS:
            found.append(arg)
    return found


@pytest.mark.parametrize("name", ["-P", "-a"])
def test_render_guides_passes_the_scene_as_a_path(cli_path, tmp_path, name):
    blender, calls = fake_blender(tmp_path)
    work = tmp_path / "work"
    work.mkdir()
    (work / name).write_bytes(b"BLENDER")  # the user's scene, named like an option
    subprocess.run([str(cli_path), "render-guides", name, "--out", "cache", "--frames", "1-1",
                    "--blender", str(blender)], cwd=work, capture_output=True, text=True, timeout=60)
    (argv,) = blender_calls(calls)
    assert options_before_double_dash(argv) == [], argv
    assert str(work / name) in argv[:argv.index("--")]


def test_stylize_passes_the_exemplar_scene_as_a_path(cli_path, tmp_path):
    blender, calls = fake_blender(tmp_path)
    work = tmp_path / "work"
    work.mkdir()
    for name in ("-P", "-a"):
        (work / name).write_bytes(b"BLENDER")
    tempera.write_image(str(work / "style.png"), np.full((8, 8, 3), 0.5, np.float32))
    subprocess.run([str(cli_path), "stylize", "-a", "--exemplar", "style.png", "--exemplar-scene", "-P",
                    "--frames", "1-1", "--out", "out", "--blender", str(blender)],
                   cwd=work, capture_output=True, text=True, timeout=60)
    argvs = blender_calls(calls)
    assert argvs, "Blender was never started"
    for argv in argvs:
        assert options_before_double_dash(argv) == [], argv


def _frames(folder, n=3):
    folder.mkdir(parents=True)
    for i in range(n):
        image = np.zeros((16, 24, 3), np.float32)
        image[4:12, 2 + 4 * i:10 + 4 * i] = (1.0, 0.6, 0.2)
        tempera.write_image(str(folder / f"frame_{i + 1:04d}.png"), image)


@needs_ffmpeg
@pytest.mark.parametrize("folder", ["-y", "-dash", "shot:01", "http:h"])
def test_video_of_a_relative_folder_ffmpeg_would_misread(tmp_path, monkeypatch, folder):
    monkeypatch.chdir(tmp_path)
    _frames(tmp_path / folder)
    assert encode_video(f"{folder}/frame_%04d.png", 1, f"{folder}/video.mp4")
    assert (tmp_path / folder / "video.mp4").stat().st_size > 0
    assert sorted(os.listdir(tmp_path / folder))[-1] == "video.mp4"  # no temporary file left


@needs_ffmpeg
def test_movie_exemplar_named_like_a_url_and_cache_like_an_option(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _frames(tmp_path / "src")
    subprocess.run([FFMPEG, "-y", "-v", "error", "-framerate", "10", "-i", str(tmp_path / "src" / "frame_%04d.png"),
                    "-c:v", "png", str(tmp_path / "http:h.mov")], check=True)
    (tmp_path / "-y").mkdir()
    folder = media_source.decode_movie("http:h.mov", "-y")
    assert len(media_source.image_files(folder)) == 3


def _sleeping_blender(tmp_path):
    """A stand-in for Blender that writes its pid, then sleeps (a long render)."""
    pid_file = tmp_path / "blender.pid"
    body = f"open({str(pid_file)!r}, 'w').write(str(os.getpid()))\ntime.sleep(120)"
    return stand_in_blender(tmp_path, "slow_blender", body), pid_file


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as stat:  # a zombie has stopped; only its parent has not reaped it
        return stat.read().split(")")[-1].split()[0] != "Z"


def _wait(condition, seconds=20):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("command", ["render-guides", "stylize"])
@pytest.mark.parametrize("signal_name", ["SIGTERM", "SIGKILL"])
def test_blender_does_not_outlive_the_command(cli_path, tmp_path, command, signal_name):
    """A farm's cancel (SIGTERM) stops Blender with the CLI; so does the CLI's death (SIGKILL)."""
    blender, pid_file = _sleeping_blender(tmp_path)
    scene = tmp_path / "shot.blend"
    scene.write_bytes(b"BLENDER")
    args = ["--out", str(tmp_path / "cache"), "--frames", "1-1", "--blender", str(blender)]
    if command == "stylize":
        tempera.write_image(str(tmp_path / "style.png"), np.full((8, 8, 3), 0.5, np.float32))
        args += ["--exemplar", str(tmp_path / "style.png"), "--exemplar-scene", str(scene)]
    cli = subprocess.Popen([str(cli_path), command, str(scene), *args],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        started = lambda: pid_file.is_file() and pid_file.read_text()
        # Until Blender starts or the CLI ends: a CLI that failed first says why.
        _wait(lambda: started() or cli.poll() is not None, seconds=90)
        if not started():
            cli.kill()
            out, err = cli.communicate()
            pytest.fail(f"Blender was never started; the CLI ended with {cli.returncode}: {err.decode()}{out.decode()}")
        child = int(pid_file.read_text())
        cli.send_signal(getattr(signal, signal_name))
        status = cli.wait(timeout=20)
        assert _wait(lambda: not _alive(child)), f"Blender (pid {child}) outlived the CLI's {signal_name}"
        if signal_name == "SIGTERM":
            assert status == 130 and "interrupted" in cli.stderr.read().decode()
    finally:
        if cli.poll() is None:
            cli.kill()
        if pid_file.is_file() and pid_file.read_text() and _alive(int(pid_file.read_text())):
            os.kill(int(pid_file.read_text()), signal.SIGKILL)
