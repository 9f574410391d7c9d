"""`tempera stylize --method rigid` (native/src/methods/rigid/rigid_job.cpp) on a
guide cache's tracks: RGBA frames written atomically into OUT/frames, resumed
runs keep finished frames, no file of anyone else is deleted, bad input is
named with a non-zero exit code; `tempera rigid`, the former Python form,
names the command that replaced it."""
import json
import os
import shutil
import signal
import subprocess
import sys

import numpy as np
import pytest

from tempera import _native
from tempera.methods.rigid import rigid, rigid_tracks
from conftest import ROOT

W, H = 240, 160


def _exemplar(folder):
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 150, 0.6, 0.05, 30)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 1.2))
    (folder / "drawn").mkdir()
    for i, d in enumerate(rigid.generated_exemplar(track, W, H)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


def _cache(folder):
    track = _native.bouncing_ball((200, 30), (-3.0, 0), 14, 1.0, 150, 0.7, -0.05, 24)
    rigid_tracks.write_tracks(folder, {"Target": track}, 1, (0, 1.0))
    (folder / "manifest.json").write_text(json.dumps({"resolution": [W, H]}))


@pytest.fixture()
def inputs(tmp_path):
    (tmp_path / "ex").mkdir()
    (tmp_path / "cache").mkdir()
    _exemplar(tmp_path / "ex")
    _cache(tmp_path / "cache")
    return tmp_path


def _command(cli_path, inputs, *extra, out=None, exemplar=True, frames="1-24", guides="cache"):
    given = ["--exemplar", str(inputs / "ex")] if exemplar else []
    return [str(cli_path), "stylize", "--method", "rigid", "--guides", str(inputs / guides), *given,
            "--out", str(out or inputs / "out"), "--frames", frames, *extra]


def _stylize(cli_path, inputs, *extra, **given):
    return subprocess.run(_command(cli_path, inputs, *extra, **given), capture_output=True, text=True, timeout=300)


def _frames(out):
    return sorted((out / "frames").glob("frame_*.png"))


def test_frames_written_and_resumed(cli_path, inputs):
    made = _stylize(cli_path, inputs, "--k", "2")
    assert made.returncode == 0 and "24 frame(s) stylized, 0 skipped" in made.stdout, made.stderr
    frames = _frames(inputs / "out")
    assert len(frames) == 24 and not list((inputs / "out").rglob(".*partial*"))
    assert (inputs / "out" / "contact_sheet.png").is_file()
    img = _native.read_image(str(frames[10]), None)
    assert img.shape == (H, W, 4) and img[:, :, 3].max() > 0.9
    # A resumed run keeps every finished frame; a lost one is made again, the same.
    first = frames[5].read_bytes()
    frames[5].unlink()
    again = _stylize(cli_path, inputs, "--k", "2")
    assert again.returncode == 0 and "1 frame(s) stylized, 23 skipped" in again.stdout, again.stderr
    assert frames[5].read_bytes() == first
    # Other options: everything again.
    paper = _stylize(cli_path, inputs, "--k", "1", "--paper")
    assert paper.returncode == 0 and "24 frame(s) stylized, 0 skipped" in paper.stdout, paper.stderr
    assert _native.read_image(str(frames[0]), None)[:, :, 3].min() == 1.0


def test_bad_input_is_named(cli_path, inputs):
    for extra, words in ((["--k", "0"], "k must be"),
                         (["--lambda-dir", "-1"], "lambda dir must be in [0,"),
                         (["--shape", "star"], "unknown proxy shape 'star'"),
                         (["--bogus", "1"], "unknown option '--bogus' for --method rigid"),
                         (["--object", "Nope"], "has no object 'Nope' (it has Target)")):
        result = _stylize(cli_path, inputs, *extra)
        assert result.returncode == 2 and words in result.stderr, (extra, result.stderr)
    outside = _stylize(cli_path, inputs, frames="20-40")
    assert outside.returncode == 2 and "frame 25 is outside the tracked frames 1-24" in outside.stderr
    no_guides = subprocess.run([str(cli_path), "stylize", "--method", "rigid", "--exemplar", str(inputs / "ex"),
                                "--frames", "1-2", "--out", str(inputs / "out")], capture_output=True, text=True,
                               timeout=60)
    assert no_guides.returncode == 2 and "--guides DIR" in no_guides.stderr
    nowhere = _stylize(cli_path, inputs, guides="nowhere")
    assert nowhere.returncode == 1 and "no rigid-body tracks" in nowhere.stderr
    (inputs / "ex" / "drawn" / "0003.png").unlink()
    missing = _stylize(cli_path, inputs)
    assert missing.returncode == 1 and "0003.png: drawn frame missing" in missing.stderr
    (inputs / "cache" / rigid_tracks.TRACKS_NAME).write_text('{"format": 1, "frame_start": 1,')
    broken = _stylize(cli_path, inputs, frames="1-2")
    assert broken.returncode == 2 and "tracks.json: unreadable tracks (line 1 column 32" in broken.stderr
    assert not list((inputs / "out").rglob("frame_*.png"))


def test_tempera_rigid_names_the_command_that_replaced_it(cli_path, inputs):
    """The Python form `tempera rigid` is gone (issue 41): a script that still
    calls it, by the console script or the native binary, is told what to run."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(cli_path))
    argv = ["rigid", "--cache", str(inputs / "cache"), "--out", str(inputs / "out")]
    for command in ([sys.executable, "-m", "tempera", *argv], [str(cli_path), *argv]):
        result = subprocess.run(command, capture_output=True, text=True, timeout=60, env=env)
        assert result.returncode == 2 and "tempera stylize --method rigid --guides CACHE" in result.stderr
    assert not (inputs / "out").exists()


def _corrupt(cache, change):
    path = cache / rigid_tracks.TRACKS_NAME
    data = json.loads(path.read_text())
    change(data, data["objects"]["Target"])
    path.write_text(json.dumps(data))


def _set(key, frame, value):
    def change(data, track):
        track[key][frame] = value
    return change


@pytest.mark.parametrize("change, words", [
    (_set("centre", 3, [float("nan"), 40.0]), "frame 3: the centre (nan, 40) must be finite"),
    (_set("centre", 3, [float("inf"), 40.0]), "frame 3: the centre (inf, 40) must be finite"),
    (_set("centre", 3, [1e300, 40.0]), "within 1000000 pixels"),
    (_set("radius", 5, float("nan")), "frame 5: the radius nan must be > 0"),
    (_set("radius", 5, 1e300), "frame 5: the radius 1e+300 must be > 0 and at most"),
    (_set("velocity", 2, [0.0, float("-inf")]), "frame 2: the velocity"),
    (_set("theta", 4, float("nan")), "frame 4: the rotation nan"),
    (_set("centre", 1, "left"), "object 'Target'"),
    (lambda data, track: data.update(frame_start="1"), "frame_start must be a whole number"),
    (lambda data, track: data.update(gravity=[0]), "gravity must be 2 finite numbers"),
    (lambda data, track: data["objects"].update(Target=[1, 2]), "object 'Target': not a track"),
])
def test_bad_track_values_are_named_with_exit_2(cli_path, inputs, change, words):
    """NaN, inf or 1e300 in tracks.json made exit 0 and a blank frame; wrong types a traceback."""
    _corrupt(inputs / "cache", change)
    result = _stylize(cli_path, inputs)
    assert result.returncode == 2 and words in result.stderr and "tracks.json" in result.stderr, result.stderr
    assert not list((inputs / "out").rglob("frame_*.png"))


def test_deep_tracks_and_huge_resolutions_are_named_with_exit_2(cli_path, inputs):
    (inputs / "cache" / rigid_tracks.TRACKS_NAME).write_text("[" * 100_000 + "]" * 100_000)
    deep = _stylize(cli_path, inputs)
    assert deep.returncode == 2 and "nested too deeply" in deep.stderr, deep.stderr
    _cache(inputs / "cache")
    for resolution, words in (([100_000, 100_000], "more than the limit"), (["wide", 160], "2 whole numbers")):
        (inputs / "cache" / "manifest.json").write_text(json.dumps({"resolution": resolution}))
        result = _stylize(cli_path, inputs)
        assert result.returncode == 2 and words in result.stderr, (resolution, result.stderr)


def test_stylize_method_rigid_draws_with_the_generated_exemplar_by_default(cli_path, inputs):
    """Step 5 of issue 41: no drawings of one's own needed; the generated
    exemplar is written once, and naming it is the same settings."""
    made = _stylize(cli_path, inputs, frames="1-3", exemplar=False)
    assert made.returncode == 0, made.stderr
    folder = inputs / "out" / "exemplar_generated_circle"
    assert (folder / rigid_tracks.TRACKS_NAME).is_file() and len(list((folder / "drawn").glob("*.png"))) == 60
    assert rigid_tracks.read_tracks(folder)["objects"]["Generated"]["centre"][0] == [60.0, 60.0]
    assert all(_native.read_image(str(f), None)[:, :, 3].max() > 0.5 for f in _frames(inputs / "out"))
    said = _stylize(cli_path, inputs, "--exemplar", "generated", frames="1-3", exemplar=False)
    assert said.returncode == 0 and "0 frame(s) stylized, 3 skipped" in said.stdout, said.stderr


# --------------------------------------------------------------------------- issue 31, items 2 and 5

def test_no_file_is_deleted_by_a_new_folder_or_new_settings(cli_path, inputs):
    """With no record yet, or other settings, the former `tempera rigid`
    deleted every frame_*.png in --out, even outside --frames (18 of a
    user's 20 files). Only the frames asked for are made."""
    out = inputs / "out" / "frames"
    out.mkdir(parents=True)
    rng = np.random.default_rng(3)
    for f in range(1, 21):
        _native.write_image(str(out / f"frame_{f:04d}.png"), rng.random((8, 8, 4)).astype(np.float32), [])
    theirs = {p.name: p.read_bytes() for p in out.glob("frame_*.png")}
    made = _stylize(cli_path, inputs, "--k", "2", frames="3-4")
    assert made.returncode == 0 and "2 frame(s) stylized" in made.stdout, made.stderr
    ours = {f"frame_{f:04d}.png" for f in (3, 4)}
    assert {n: b for n, b in theirs.items() if n not in ours} == {
        p.name: p.read_bytes() for p in out.glob("frame_*.png") if p.name not in ours}
    drawn = {n: (out / n).read_bytes() for n in ours}
    # Other settings, other frames: the frames of the first settings stay too.
    assert _stylize(cli_path, inputs, "--k", "1", frames="5-6").returncode == 0
    assert {n: (out / n).read_bytes() for n in ours} == drawn
    assert all((out / n).read_bytes() == theirs[n] for n in theirs if n not in ours | {"frame_0005.png", "frame_0006.png"})
    # Back to the first settings: their frames are still current.
    back = _stylize(cli_path, inputs, "--k", "2", frames="3-4")
    assert back.returncode == 0 and "0 frame(s) stylized, 2 skipped" in back.stdout, back.stderr


def test_frames_are_on_disk_as_they_are_drawn_and_kill_9_resumes(cli_path, inputs):
    """The frames used to be kept in memory and written at the end: kill -9
    at frame 154 of 200 left none. Each frame is written and recorded as soon
    as it is drawn, and the rerun equals an uninterrupted run."""
    whole = _stylize(cli_path, inputs, "--k", "2", out=inputs / "whole")
    assert whole.returncode == 0, whole.stderr
    process = subprocess.Popen(_command(cli_path, inputs, "--k", "2", out=inputs / "killed"),
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    for line in process.stdout:  # "frame 12/24 (#12): 0.02 s, ETA 0:00" as each frame is written
        if line.startswith("frame 12/24"):
            process.send_signal(signal.SIGKILL)
            break
    process.wait(timeout=60)
    assert process.returncode in (-signal.SIGKILL, 0)  # 0: every frame was written before the signal came
    kept = [p.name for p in _frames(inputs / "killed")]
    assert len(kept) >= 12 and kept[:12] == [f"frame_{f:04d}.png" for f in range(1, 13)]
    again = _stylize(cli_path, inputs, "--k", "2", out=inputs / "killed")
    assert again.returncode == 0, again.stderr
    assert f"{24 - len(kept)} frame(s) stylized, {len(kept)} skipped" in again.stdout
    for f in range(1, 25):
        name = f"frames/frame_{f:04d}.png"
        assert (inputs / "killed" / name).read_bytes() == (inputs / "whole" / name).read_bytes(), name


BLENDER = os.environ.get("TEMPERA_BLENDER", "blender")
RIGID_SCENE = """
import math, bpy
scene = bpy.context.scene
for o in list(scene.objects):
    bpy.data.objects.remove(o)
bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, 0))
floor = bpy.context.object
if scene.rigidbody_world is None:
    bpy.ops.rigidbody.world_add()
bpy.ops.rigidbody.object_add()
floor.rigid_body.type = "PASSIVE"
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-2, 0, 3))
ball = bpy.context.object
ball.name = "Target"
bpy.ops.rigidbody.object_add()
ball.rigid_body.collision_shape = "SPHERE"
ball.rigid_body.restitution = 0.9
cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
cam.data.type = "ORTHO"
cam.data.ortho_scale = 10
scene.collection.objects.link(cam)
cam.location, cam.rotation_euler = (0, -10, 2.5), (math.pi / 2, 0, 0)
scene.camera = cam
r = scene.render
r.resolution_x, r.resolution_y, r.resolution_percentage = 96, 64, 100
scene.frame_start, scene.frame_end = 1, 12
scene.rigidbody_world.point_cache.frame_end = 12
bpy.ops.wm.save_as_mainfile(filepath=PATH)
"""


@pytest.mark.skipif(shutil.which(BLENDER) is None, reason="Blender not installed")
def test_stylize_a_scene_renders_its_guides_and_tracks_first(tmp_path, cli_path):
    """Step 5 of issue 41: `tempera stylize SCENE.blend --method rigid` as for the other methods."""
    blend = tmp_path / "shot.blend"
    made = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr",
                           f"PATH = {str(blend)!r}\n" + RIGID_SCENE], capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr[-2000:]
    (tmp_path / "ex").mkdir()
    _exemplar(tmp_path / "ex")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(cli_path), TEMPERA_BLENDER=BLENDER)
    command = [sys.executable, "-m", "tempera", "stylize", str(blend), "--method", "rigid", "--exemplar",
               str(tmp_path / "ex"), "--frames", "1-12", "--out", str(tmp_path / "out"), "--samples", "1"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert "rendering the guides of" in result.stderr
    assert (tmp_path / "out" / "guides" / rigid_tracks.TRACKS_NAME).is_file()
    frames = sorted((tmp_path / "out" / "frames").glob("frame_*.png"))
    assert len(frames) == 12 and _native.read_image(str(frames[0]), None).shape == (64, 96, 4)
    assert max(_native.read_image(str(f), None)[:, :, 3].max() for f in frames) > 0.5  # the ball is drawn
    again = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
    assert again.returncode == 0 and "0 frame(s) stylized, 12 skipped" in again.stdout, again.stderr[-2000:]
    no_frames = subprocess.run(command[:-6] + ["--out", str(tmp_path / "o2")], capture_output=True, text=True,
                               timeout=120, env=env)
    assert no_frames.returncode == 2 and "--frames is required" in no_frames.stderr
