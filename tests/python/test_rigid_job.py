"""The rigid-body method's job as the panel runs it (tempera.methods.registry.make_job,
native/src/methods/rigid/rigid_job.cpp): every target body drawn and laid
far to near by camera depth, frames resumed, a cancelled frame writes
nothing, strokes re-made, bad input named."""
import json

import numpy as np
import pytest

import tempera
from tempera import _native
from tempera.methods import registry
from tempera.methods.rigid import rigid, rigid_strokes, rigid_tracks

W, H = 200, 140
FRAMES = 16
INK = (0.9, 0.1, 0.1)  # the drawn bodies' fill, under their graphite outline


def _exemplar(folder):
    """The generated ball, its inside filled in red: two colours, so that
    which body lies on top shows where two bodies overlap."""
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 130, 0.6, 0.05, 24)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 1.2))
    (folder / "drawn").mkdir(parents=True)
    ys, xs = np.mgrid[0:H, 0:W] + 0.5
    for i, d in enumerate(rigid.generated_exemplar(track, W, H)):
        (cx, cy), r = track["centre"][i], track["radius"][i]
        inside = (np.hypot(xs - cx, ys - cy) < 0.85 * r) & (d[:, :, 3] < 0.5)
        d[inside] = (*INK, 1.0)
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


def _cache(folder, near="Near"):
    """Two balls on the same path, 'Far' 10 px to the right of 'Near' (they
    overlap), NEAR nearer the camera."""
    track = _native.bouncing_ball((150, 30), (-3.0, 0), 14, 1.0, 130, 0.7, -0.05, FRAMES)
    shifted = dict(track, centre=[[x + 10, y] for x, y in track["centre"]])
    tracks = {"Near": dict(track), "Far": shifted}
    for name in tracks:
        tracks[name]["depth"] = [5.0 if name == near else 9.0] * FRAMES
    folder.mkdir(parents=True, exist_ok=True)
    rigid_tracks.write_tracks(folder, tracks, 1, (0, 1.0))
    (folder / "manifest.json").write_text(json.dumps({"resolution": [W, H]}))


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    root = tmp_path_factory.mktemp("examples")
    _exemplar(root / "ball")
    return root


@pytest.fixture()
def cache(tmp_path):
    _cache(tmp_path / "cache")
    return tmp_path / "cache"


def _job(cache, examples, out, frames, *flags):
    return registry.make_job("rigid", examples, cache, frames, out, options=[("k", 2), *flags])


def _run(job, progress=None):
    return [job.run_frame(i, progress)["status"] for i in range(len(job.frames))]


def _frame(out, f):
    return tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png"))


def _on_top(cache, examples, tmp_path, f):
    """The composite at frame F where both bodies are opaque, and each body's own frame there."""
    drawn = {}
    for name in ("all", "Near", "Far"):
        flags = [] if name == "all" else [("object", name)]
        _run(_job(cache, examples, tmp_path / name, [f], *flags))
        drawn[name] = _frame(tmp_path / name, f)
    both = (drawn["Near"][:, :, 3] > 0.99) & (drawn["Far"][:, :, 3] > 0.99)
    differ = np.abs(drawn["Near"][:, :, :3] - drawn["Far"][:, :, :3]).max(axis=2) > 0.3
    where = both & differ
    assert where.sum() > 20  # the two colours overlap somewhere
    return [drawn[n][where, :3] for n in ("all", "Near", "Far")]


def test_the_nearer_body_is_laid_on_top(examples, cache, tmp_path):
    composite, near, far = _on_top(cache, examples, tmp_path, 8)
    np.testing.assert_allclose(composite, near, atol=2 / 255)
    assert np.abs(composite - far).max() > 0.3


def test_depths_swapped_the_other_body_is_on_top(examples, tmp_path):
    _cache(tmp_path / "cache", near="Far")
    composite, near, far = _on_top(tmp_path / "cache", examples, tmp_path, 8)
    np.testing.assert_allclose(composite, far, atol=2 / 255)
    assert np.abs(composite - near).max() > 0.3


def test_resumed_frames_are_kept_and_other_settings_redraw(examples, cache, tmp_path):
    frames = list(range(3, 9))
    out = tmp_path / "out"
    assert _run(_job(cache, examples, out, frames)) == ["stylized"] * 6
    assert not list(out.rglob(".*partial*"))
    (out / "frames" / "frame_0005.png").unlink()
    assert _run(_job(cache, examples, out, frames)) == ["skipped", "skipped", "stylized"] + ["skipped"] * 3
    paper = _job(cache, examples, out, frames, ("paper", True))
    assert _run(paper) == ["stylized"] * 6
    assert _frame(out, 3)[:, :, 3].min() == 1.0


def test_cancel_writes_nothing_and_resume_equals_uninterrupted(examples, cache, tmp_path):
    frames = [4, 5, 6]
    stopped = _job(cache, examples, tmp_path / "stopped", frames, ("object", "Near"))
    stopped.run_frame(0)
    with pytest.raises(tempera.Cancelled):
        stopped.run_frame(1, lambda fraction: False)
    assert sorted(p.name for p in (tmp_path / "stopped" / "frames").glob("frame_*")) == ["frame_0004.png"]
    assert _run(_job(cache, examples, tmp_path / "stopped", frames, ("object", "Near"))) == [
        "skipped", "stylized", "stylized"]
    _run(_job(cache, examples, tmp_path / "whole", frames, ("object", "Near")))
    for f in frames:
        np.testing.assert_array_equal(_frame(tmp_path / "stopped", f), _frame(tmp_path / "whole", f))


def test_strokes_are_resynthesized_cancellable_and_part_of_the_settings(examples, cache, tmp_path):
    """With a stroke exemplar the bodies take its look; Esc while the strokes
    are re-made writes nothing of the frame; plain and stroked runs are
    different settings (each redoes the other's files)."""
    out = tmp_path / "out"
    assert _run(_job(cache, examples, out, [5, 6], ("object", "Near"))) == ["stylized"] * 2
    plain = (out / "frames" / "frame_0006.png").read_bytes()
    stroked = _job(cache, examples, out, [5, 6], ("object", "Near"), ("strokes", rigid_strokes.GENERATED))
    assert stroked.run_frame(0)["status"] == "stylized"  # the exemplar fitted, frame 5 drawn
    calls = []

    def esc_in_the_strokes(fraction):  # the first call starts the frame, the next are the strokes'
        calls.append(fraction)
        return len(calls) <= 1

    with pytest.raises(tempera.Cancelled):
        stroked.run_frame(1, esc_in_the_strokes)
    assert len(calls) == 2 and (out / "frames" / "frame_0006.png").read_bytes() == plain
    assert _run(stroked) == ["skipped", "stylized"]
    frame = _frame(out, 6)
    ink = frame[:, :, 3] > 0.5
    assert ink.sum() > 20 and np.abs(frame[ink, :3].mean(0) - rigid_strokes.STROKE_COLOUR).max() < 0.05
    assert _run(_job(cache, examples, out, [5, 6], ("object", "Near"))) == ["stylized"] * 2


def test_bad_input_is_named(examples, cache, tmp_path):
    with pytest.raises(FileNotFoundError, match="exemplar folder '.*nowhere' does not exist"):
        _native.rigid_exemplar_folders(str(tmp_path / "nowhere"))
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no exemplar"):
        _native.rigid_exemplar_folders(str(tmp_path / "empty"))
    assert _native.rigid_exemplar_folders(str(examples)) == [str(examples / "ball")]
    with pytest.raises(ValueError, match="no object 'Cube'"):
        _job(cache, examples, tmp_path / "out", [2], ("object", "Cube"))
    with pytest.raises(ValueError, match="frame 40 is outside the tracked frames 1-16"):
        _job(cache, examples, tmp_path / "out", [2, 40])
    with pytest.raises(ValueError, match="star"):
        _job(cache, examples, tmp_path / "out", [2], ("shape", "star"))
