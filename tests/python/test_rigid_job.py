"""tempera.methods.rigid.rigid_job, the panel's rigid-body method as steps: one per object
and chunk, then the composites by depth; resumed runs keep finished steps,
a cancelled step writes nothing, other settings redo everything."""
import json

import numpy as np
import pytest

import tempera
from tempera import _native
from tempera.methods.rigid import rigid, rigid_tracks
from tempera.methods.rigid.rigid_job import RigidJob, exemplar_folders

W, H = 200, 140
FRAMES = 16


def _exemplar(folder):
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 130, 0.6, 0.05, 24)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 1.2))
    (folder / "drawn").mkdir(parents=True)
    for i, d in enumerate(rigid.generated_exemplar(track, W, H)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


def _cache(folder, near="Near"):
    """Two balls on the same path, 'Near' nearer the camera than 'Far'."""
    track = _native.bouncing_ball((150, 30), (-3.0, 0), 14, 1.0, 130, 0.7, -0.05, FRAMES)
    tracks = {"Far": dict(track), "Near": dict(track)}
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


def _run(job, progress=None):
    return [job.run_step(i, progress)["status"] for i in range(job.total)]


def test_steps_layers_composite_by_depth_and_resume(examples, cache, tmp_path):
    frames = list(range(3, 13))
    job = RigidJob(cache, examples, tmp_path / "out", frames, chunk=4, k=2)
    assert job.total == 2 * 3 + 3 and job.depth_order(5) == ["Far", "Near"]
    assert _run(job) == ["stylized"] * 6 + ["composited"] * 3
    assert not list((tmp_path / "out").rglob(".*partial*"))
    f = 8
    out = tempera.read_image(str(job.output_path(f)))
    near = tempera.read_image(str(job.layer_path("Near", f)))
    assert out.shape == (H, W, 4) and out[:, :, 3].max() > 0.9
    ink = near[:, :, 3] > 0.5
    np.testing.assert_allclose(out[ink, :3], near[ink, :3], atol=2 / 255)  # the nearer body on top
    # Resumed: every step kept; a lost layer is drawn again.
    job.layer_path("Far", 4).unlink()
    again = RigidJob(cache, examples, tmp_path / "out", frames, chunk=4, k=2)
    assert _run(again) == ["stylized"] + ["kept"] * 8
    # On paper: opaque frames, every step redone.
    paper = RigidJob(cache, examples, tmp_path / "out", frames, chunk=4, k=2, paper=True)
    assert _run(paper) == ["stylized"] * 6 + ["composited"] * 3
    assert tempera.read_image(str(paper.output_path(f)))[:, :, 3].min() == 1.0


def test_the_nearer_body_is_composited_last(examples, tmp_path):
    """Same bodies, depths swapped: the composite follows the depth, not the names."""
    _cache(tmp_path / "cache", near="Far")
    job = RigidJob(tmp_path / "cache", examples, tmp_path / "out", [8], objects=["Near", "Far"])
    assert job.depth_order(8) == ["Near", "Far"]


def test_cancel_writes_nothing_of_the_step_and_resume_equals_uninterrupted(examples, cache, tmp_path):
    frames = list(range(1, 9))
    job = RigidJob(cache, examples, tmp_path / "stopped", frames, objects=["Near"], chunk=4)
    job.run_step(0)
    with pytest.raises(tempera.Cancelled):
        job.run_step(1, lambda fraction: fraction < 0.3)
    assert [p.name for p in sorted((tmp_path / "stopped" / "layers" / "Near").iterdir())] == [
        f"frame_{f:04d}.png" for f in range(1, 5)]
    resumed = RigidJob(cache, examples, tmp_path / "stopped", frames, objects=["Near"], chunk=4)
    assert _run(resumed) == ["kept", "stylized", "composited", "composited"]
    whole = RigidJob(cache, examples, tmp_path / "whole", frames, objects=["Near"], chunk=4)
    _run(whole)
    for f in frames:
        np.testing.assert_array_equal(tempera.read_image(str(resumed.output_path(f))),
                                      tempera.read_image(str(whole.output_path(f))))


def test_strokes_are_resynthesized_cancellable_and_part_of_the_settings(examples, cache, tmp_path):
    """With a stroke exemplar the layers take its look; Esc while the strokes
    are re-made writes nothing of the step; plain and stroked runs are
    different settings (each redoes the other's files)."""
    from tempera.methods.rigid import rigid_strokes

    out = tmp_path / "out"
    plain = RigidJob(cache, examples, out, [6, 7], objects=["Near"])
    assert _run(plain) == ["stylized", "composited"]
    plain_layers = {p.name: p.read_bytes() for p in (out / "layers" / "Near").iterdir()}
    stroked = RigidJob(cache, examples, out, [6, 7], objects=["Near"], strokes="generated")
    calls = []

    def esc_in_the_strokes(fraction):  # the first two calls are the two frames' drawing
        calls.append(fraction)
        return len(calls) <= 2

    with pytest.raises(tempera.Cancelled):
        stroked.run_step(0, esc_in_the_strokes)
    assert len(calls) == 3
    assert {p.name: p.read_bytes() for p in (out / "layers" / "Near").iterdir()} == plain_layers  # nothing written
    assert _run(RigidJob(cache, examples, out, [6, 7], objects=["Near"], strokes="generated")) == [
        "stylized", "composited"]
    layer = tempera.read_image(str(stroked.layer_path("Near", 6)))
    ink = layer[:, :, 3] > 0.5
    assert ink.sum() > 20 and np.abs(layer[ink, :3].mean(0) - rigid_strokes.STROKE_COLOUR).max() < 0.05
    assert _run(RigidJob(cache, examples, out, [6, 7], objects=["Near"])) == ["stylized", "composited"]


def test_bad_input_is_named(examples, cache, tmp_path):
    with pytest.raises(FileNotFoundError, match="examples folder"):
        exemplar_folders(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="holds no example"):
        exemplar_folders(tmp_path / "empty")
    with pytest.raises(ValueError, match="no rigid-body track of Cube"):
        RigidJob(cache, examples, tmp_path / "out", [2], objects=["Cube"])
    with pytest.raises(ValueError, match="outside the tracked range 1-16"):
        RigidJob(cache, examples, tmp_path / "out", [2, 40])
    with pytest.raises(ValueError, match="unknown proxy shape 'star'"):
        RigidJob(cache, examples, tmp_path / "out", [2], shape="star")
