"""`tempera stylize --method tcia`: segments at keys, farm split, resume, cancel, threads, errors."""
import shutil
import signal
import subprocess

import numpy as np
import pytest

import tempera
from synthetic_cache import H, W, make_cache, make_exemplar
from test_cli_stylize import stylize

FRAMES = range(1, 8)


@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    p = tmp_path_factory.mktemp("tcia_cli")
    make_cache(p / "cache", frames=tuple(FRAMES), forward=True)
    make_cache(p / "no_forward", frames=tuple(FRAMES))
    make_exemplar(p / "exemplar", p / "paint.png")
    # The key: the painting's texture shifted, so the key differs from what the sweeps make alone.
    paint = tempera.read_image(str(p / "paint.png"))
    tempera.write_image(str(p / "key4.png"), np.roll(paint, 7, axis=1)[::-1].copy())
    return p


def args(p, out, *extra, cache="cache"):
    return ("--method", "tcia", "--guides", p / cache, "--exemplar", p / "paint.png", "--exemplar-guides",
            p / "exemplar", "--frames", "1-7", "--out", p / out, "--levels", "2", "--patch-size", "7",
            "--no-video", *extra)


def frames_of(p, out):
    return [(p / out / "frames" / f"frame_{f:04d}.png").read_bytes() for f in FRAMES]


def run_single(cli_path, shot):
    if not (shot / "single" / "frames" / "frame_0007.png").is_file():
        result = stylize(cli_path, *args(shot, "single", "--key", f"4={shot / 'key4.png'}", "--threads", "2"))
        assert result.returncode == 0, result.stderr
        assert "segment 1/2 (frames 1-4)" in result.stdout and "segment 2/2 (frames 4-7)" in result.stdout
        assert "level 2/2 backward sweep, 100%" in result.stdout
        assert "2 segment(s) stylized, 0 skipped" in result.stdout
    return frames_of(shot, "single")


def test_key_comes_out_as_painted_and_farm_split_equals_single_run(cli_path, shot):
    single = run_single(cli_path, shot)
    key = tempera.read_image(str(shot / "key4.png"))
    out4 = tempera.read_image(str(shot / "single" / "frames" / "frame_0004.png"))
    assert np.abs(out4 - key).max() <= 1 / 255 + 1e-6
    # A farm: each segment on its own machine, which has only its own guide frames.
    for segment in ("4-7", "1-4"):
        a, b = map(int, segment.split("-"))
        own = shot / f"cache_{segment}"
        own.mkdir(exist_ok=True)
        for f in range(a, b + 1):
            shutil.copy2(shot / "cache" / f"frame_{f:04d}.exr", own)
        result = stylize(cli_path, *args(shot, "farm", "--key", f"4={shot / 'key4.png'}", "--segment", segment,
                                         "--threads", "1", cache=own.name))
        assert result.returncode == 0, result.stderr
        assert "1 segment(s) stylized" in result.stdout
    assert frames_of(shot, "farm") == single
    assert not (shot / "farm" / "contact_sheet.png").exists()  # a segment is a task; the finish writes it
    finish = stylize(cli_path, *args(shot, "farm", "--key", f"4={shot / 'key4.png'}"))
    assert "0 segment(s) stylized, 2 skipped" in finish.stdout, finish.stdout
    assert (shot / "farm" / "contact_sheet.png").is_file()


def test_resume_after_interrupt_equals_uninterrupted_run(cli_path, shot):
    single = run_single(cli_path, shot)
    cmd = [str(cli_path), "stylize", *map(str, args(shot, "resumed", "--key", f"4={shot / 'key4.png'}"))]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:  # the second segment under way
        if line.startswith("segment 2/2") and "sweep" in line:
            proc.send_signal(signal.SIGTERM)
            break
    proc.stdout.read()
    assert proc.wait(timeout=120) == 130
    made = sorted(f.name for f in (shot / "resumed" / "frames").iterdir() if f.is_file())
    assert made == [f"frame_{f:04d}.png" for f in range(1, 4)]  # segment 1 only, nothing half-written
    assert not [f for f in (shot / "resumed").rglob(".*")]
    again = stylize(cli_path, *args(shot, "resumed", "--key", f"4={shot / 'key4.png'}"))
    assert again.returncode == 0, again.stderr
    assert "segment 1/2 (frames 1-4): skipped" in again.stdout and "1 segment(s) stylized, 1 skipped" in again.stdout
    assert frames_of(shot, "resumed") == single
    # A changed key redoes only the segments it bounds: here both.
    changed = stylize(cli_path, *args(shot, "resumed", "--key", f"4={shot / 'key4.png'}", "--coherence", "0.1"))
    assert "2 segment(s) stylized" in changed.stdout


def test_any_thread_count_gives_the_same_frames(cli_path, shot):
    for threads in ("1", "2"):
        result = stylize(cli_path, *args(shot, f"threads{threads}", "--threads", threads))
        assert result.returncode == 0, result.stderr
        assert "segment 1/1 (frames 1-7)" in result.stdout
    assert frames_of(shot, "threads1") == frames_of(shot, "threads2")


@pytest.mark.parametrize("extra, code, message", [
    (("--key", "4"), 2, "--key expects FRAME=PAINTING[,MASK], got '4'"),
    (("--key", "x=k.png"), 2, "the frame of --key 'x=k.png'"),
    (("--key", "4=k.png,"), 2, "--key expects FRAME=PAINTING[,MASK]"),
    (("--key", "40=KEY"), 2, "keyframe 40 is outside the frames 1-7"),
    (("--key", "4=KEY", "--key", "4=KEY"), 2, "keyframe 4 is given twice"),
    (("--key", "4=missing.png"), 1, "painting of keyframe 4 not found: 'missing.png'"),
    (("--key", "4=SMALL"), 2, f"is {W // 2}x{H // 2} but frame 4's guides are {W}x{H}"),
    (("--segment", "2-5"), 2, "segment 2-5 is not one of the shot's segments (1-7"),
    (("--segment", "3"), 2, "--segment expects A-B"),
    (("--method", "ebsynth"), 2, "unknown --method 'ebsynth'"),
    (("--sweeps", "0"), 2, "sweep"),
])
def test_bad_input_names_the_problem(cli_path, shot, extra, code, message):
    small = shot / "small.png"
    tempera.write_image(str(small), np.zeros((H // 2, W // 2, 3), np.float32))
    extra = [e.replace("KEY", str(shot / "key4.png")).replace("SMALL", str(small)) for e in extra]
    result = stylize(cli_path, *args(shot, "bad", *extra))
    assert result.returncode == code and message in result.stderr, result.stderr


def test_line_term_runs_from_the_cli_and_is_part_of_the_resume_key(cli_path, shot):
    result = stylize(cli_path, *args(shot, "lines", "--lines", "4", "--ink", "0.6"))
    assert result.returncode == 0, result.stderr
    assert "1 segment(s) stylized" in result.stdout
    again = stylize(cli_path, *args(shot, "lines", "--lines", "4", "--ink", "0.6"))
    assert "0 segment(s) stylized, 1 skipped" in again.stdout
    off = stylize(cli_path, *args(shot, "lines"))
    assert "1 segment(s) stylized" in off.stdout
    missing = stylize(cli_path, *args(shot, "lines2", "--lines", "4", cache="no_forward"))
    assert missing.returncode == 2 and "needs 'line_distance'" in missing.stderr, missing.stderr


def test_stylit_refuses_tcia_options_and_tcia_needs_forward_motion(cli_path, shot):
    stylit = [a for a in args(shot, "bad2", "--key", f"4={shot / 'key4.png'}") if a not in ("--method", "tcia")]
    result = stylize(cli_path, *stylit)
    assert result.returncode == 2 and "--key needs --method tcia" in result.stderr
    result = stylize(cli_path, *args(shot, "bad3", cache="no_forward"))
    assert result.returncode == 2 and "needs 'velocity_forward'" in result.stderr
    gappy = [a if a != "1-7" else "1-3,5" for a in args(shot, "bad4")]
    result = stylize(cli_path, *gappy)
    assert result.returncode == 2 and "needs consecutive frames" in result.stderr


def test_temporal_noise_boils_the_coherent_frames(cli_path, shot):
    single = run_single(cli_path, shot)  # the reference: the same tcia run without noise
    result = stylize(cli_path, *args(shot, "noisy", "--key", f"4={shot / 'key4.png'}", "--threads", "2",
                                     "--noise", "2.2"))
    assert result.returncode == 0, result.stderr
    assert frames_of(shot, "noisy") == single  # the coherent frames are the method's own
    noisy = [tempera.read_image(str(shot / "noisy" / "noisy" / f"frame_{f:04d}.png")) for f in FRAMES]
    coherent = [tempera.read_image(str(shot / "noisy" / "frames" / f"frame_{f:04d}.png")) for f in FRAMES]
    assert all(np.abs(n - c).mean() > 0.002 for n, c in zip(noisy, coherent))  # every frame boiled
    segment = stylize(cli_path, *args(shot, "noisy2", "--key", f"4={shot / 'key4.png'}", "--segment", "1-4",
                                      "--noise", "2.2"))
    assert segment.returncode == 2 and "--noise with --segment" in segment.stderr, segment.stderr


def _turning_hatching(p, frames=8, size=40, start=60.0, step=4.0):
    """A disc of paper turning `step` degrees per frame about the centre, flat
    shading, and a `tensor` guide whose edge direction turns with it (as the
    render's structure or an orientation AOV would give); the exemplar is
    horizontal hatching (edge direction 0) with its own tensor. Only the
    orientation says which way to hatch. Returns the field's angle per frame."""
    from tempera.app import guide_cache

    def tensor(angle, h, w):  # the gradient across the strokes, n = (-sin a, cos a)
        nx, ny = -np.sin(angle), np.cos(angle)
        return np.broadcast_to(np.array([nx * nx, nx * ny, ny * ny], np.float32), (h, w, 3)).copy()

    def flat(h, w):
        return {name: np.full((h, w, 3), 0.5, np.float32) for name in ("FULL", "LDE", "LSE", "LDDE")}

    yy, xx = np.mgrid[0:48, 0:48].astype(np.float32)
    stripes = 0.5 + 0.5 * np.cos(2 * np.pi * yy / 6)
    tempera.write_image(str(p / "hatching.png"), np.repeat(stripes[:, :, None], 3, axis=2).astype(np.float32))
    guide_cache.write_frame(p / "hatching_exemplar", 1, dict(flat(48, 48), tensor=tensor(0.0, 48, 48)))
    guide_cache.write_manifest(p / "hatching_exemplar", {"frames": {"1": {"key": "synthetic"}}, "guides": ["FULL"]})
    c, s = np.cos(np.radians(step)), np.sin(np.radians(step))
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float32)
    dx, dy = xx - (size - 1) / 2, yy - (size - 1) / 2
    v_minus = np.stack([dx - (c * dx + s * dy), dy - (-s * dx + c * dy)], -1)  # p came from R(-step) p
    v_plus = np.stack([c * dx - s * dy - dx, s * dx + c * dy - dy], -1)  # and goes to R(step) p
    ones = np.ones((size, size), np.float32)
    truth = []
    for t in range(frames):
        truth.append(np.radians(start + step * t) % np.pi)
        guide_cache.write_frame(p / "hatching_shot", 1 + t, dict(
            flat(size, size), tensor=tensor(truth[-1], size, size), velocity_backward=v_minus,
            velocity_forward=v_plus, occlusion_backward=ones, occlusion_forward=ones))
    guide_cache.write_manifest(p / "hatching_shot", {"frames": {str(1 + t): {"key": "synthetic"} for t in range(frames)},
                                                     "guides": ["FULL"]})
    return truth


def _median_angle_error(folder, truth, inset=6):
    """Median over frames and coherent pixels of the axial angle, in degrees,
    between the output's hatching (its structure tensor) and the field."""
    from tempera.engine import guides

    errors = []
    for t, angle in enumerate(truth):
        out = tempera.read_image(str(folder / "frames" / f"frame_{1 + t:04d}.png"))[:, :, :3].mean(axis=2)
        a, coherence = guides.orientation(out, 2.0)
        inner = np.zeros_like(coherence, bool)
        inner[inset:-inset, inset:-inset] = True
        d = np.abs(a - angle) % np.pi
        errors.append(np.degrees(np.minimum(d, np.pi - d))[inner & (coherence > 0.5)])
    errors = np.concatenate(errors)
    return float(np.median(errors)) if errors.size else 90.0


def test_orientation_from_the_cache_turns_the_hatching(cli_path, tmp_path):
    """--orientation: each frame's and the exemplar's `tensor` guide give the
    orientation fields, patches are compared rotated, and the hatching
    follows a field turning 4 degrees per frame; without it the hatching
    keeps the exemplar's direction."""
    truth = _turning_hatching(tmp_path)
    errors = {}
    for name, extra in (("oriented", ("--orientation", "true")), ("plain", ())):
        result = stylize(cli_path, "--method", "tcia", "--guides", tmp_path / "hatching_shot", "--exemplar",
                         tmp_path / "hatching.png", "--exemplar-guides", tmp_path / "hatching_exemplar", "--frames",
                         f"1-{len(truth)}", "--out", tmp_path / name, "--weights", "FULL=1,LDE=0,LSE=0,LDDE=0",
                         "--levels", "2", "--no-video", *extra)
        assert result.returncode == 0, result.stderr
        errors[name] = _median_angle_error(tmp_path / name, truth)
    print(f"median angle error: with --orientation {errors['oriented']:.1f} deg, without {errors['plain']:.1f} deg")
    assert errors["oriented"] <= 10.0
    assert errors["plain"] > 10.0


def test_orientation_needs_the_tensor_guide(cli_path, shot):
    result = stylize(cli_path, *args(shot, "no_tensor", "--orientation", "true"))
    assert result.returncode == 2
    assert "--orientation needs the structure tensor 'tensor'" in result.stderr, result.stderr
