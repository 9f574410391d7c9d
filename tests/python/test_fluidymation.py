"""Fluidymation from Python and the CLI: the flow from masks, the motion
extents, the sequence API and the guide-cache job (resume, cancel, bad input)."""
import subprocess

import numpy as np
import pytest

import tempera
from tempera.methods.fluidymation import fluidymation
from tempera.app import guide_cache
from tempera import read_image, write_image
from conftest import assert_releases_gil

SIZE = 40


def disc(radius, size=SIZE):
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float32)
    return (np.hypot(xx - size / 2, yy - size / 2) <= radius).astype(np.float32)


def ink_frames(n=8, speed=1.5, r0=5):
    """An ink-like RGBA exemplar: rings travelling outward with a spreading disc."""
    yy, xx = np.mgrid[0:SIZE, 0:SIZE].astype(np.float32)
    r = np.hypot(xx - SIZE / 2, yy - SIZE / 2)
    out = []
    for i in range(n):
        mask = disc(r0 + speed * i)
        ring = 0.5 + 0.5 * np.sin(2 * np.pi * (r0 + speed * i - r) / 6)
        rgb = np.stack([0.2 + 0.6 * ring, 0.3 + 0.1 * np.cos(xx * 0.7), 0.9 - 0.5 * ring], -1)
        out.append(np.concatenate([rgb * mask[..., None], mask[..., None]], -1).astype(np.float32))
    return out


FAST = dict(shape_blur=6, levels=2, threads=1)


def test_flow_from_masks_points_outward_on_a_spreading_disc():
    flows = fluidymation.flow_from_masks([disc(8 + 2 * i) for i in range(6)])
    f = flows[3]
    assert f.shape == (SIZE, SIZE, 2)
    assert f[SIZE // 2, SIZE // 2 + 10, 0] > 1.0  # right of the centre: moving right
    assert f[SIZE // 2 - 10, SIZE // 2, 1] < -1.0  # above it: moving up (y down)
    assert np.all(f[disc(14) <= 0.5] == 0)


def test_motion_extent_accumulates_forward_and_backward():
    masks = [np.ones((4, 6), np.float32)] * 5
    flows = [np.dstack([np.full((4, 6), 3.0, np.float32), np.full((4, 6), 4.0, np.float32)])] * 5
    plus, minus = fluidymation.motion_extent(flows, masks)
    assert [round(float(e[1, 1, 0]), 4) for e in plus] == [0, 5, 10, 15, 20]
    assert [round(float(e[1, 1, 0]), 4) for e in minus] == [20, 15, 10, 5, 0]


def test_stylize_sequence_paints_inside_the_masks_only():
    ex = ink_frames()
    targets = [disc(7 + 1.5 * j) for j in range(3)]
    frames = fluidymation.stylize_sequence([e[..., :3] for e in ex], [e[..., 3] for e in ex], targets, **FAST)
    assert len(frames) == 3
    for target, f in zip(targets, frames):
        assert f["image"].shape == (SIZE, SIZE, 3)
        assert np.all(f["image"][target <= 0.5] == 0)
        assert f["image"][target > 0.5].mean() > 0.2
        assert np.all(f["nnf"][target <= 0.5, 0] == -1)
    assert np.all(frames[0]["time_shift"] == 0)


def test_the_solve_releases_the_gil():
    ex = ink_frames()
    targets = [disc(7 + 1.5 * j) for j in range(3)]
    assert_releases_gil(lambda: fluidymation.stylize_sequence([e[..., :3] for e in ex], [e[..., 3] for e in ex],
                                                              targets, em_iterations=12, **FAST))


def test_bad_values_are_value_errors():
    ex = ink_frames(3)
    with pytest.raises(ValueError, match="target"):
        fluidymation.stylize_sequence([e[..., :3] for e in ex], [e[..., 3] for e in ex], [disc(5)], **FAST)
    with pytest.raises(TypeError, match="unknown fluidymation option"):
        fluidymation.options(no_such_option=1)
    with pytest.raises(ValueError, match="modulation_upper"):
        fluidymation.options(modulation_upper=0.001)


def make_inputs(tmp_path, frames=4):
    exemplar = tmp_path / "exemplar"
    exemplar.mkdir()
    for i, f in enumerate(ink_frames()):
        write_image(str(exemplar / f"ink_{i:03d}.png"), f)
    cache = tmp_path / "guides"
    for j in range(frames):
        mask = disc(7 + 1.5 * j)
        yy, xx = np.mgrid[0:SIZE, 0:SIZE].astype(np.float32)
        r = np.maximum(np.hypot(xx - SIZE / 2, yy - SIZE / 2), 1e-3)
        v = np.dstack([1.5 * (xx - SIZE / 2) / r, 1.5 * (yy - SIZE / 2) / r]) * mask[..., None]
        guide_cache.write_frame(cache, j + 1, {"alpha": mask, "velocity_forward": v.astype(np.float32)})
    return exemplar, cache


def test_media_job_resumes_to_the_uninterrupted_result(tmp_path):
    exemplar, cache = make_inputs(tmp_path)
    whole = fluidymation.MediaJob(exemplar, cache, [1, 2, 3, 4], tmp_path / "whole", **FAST)
    assert whole.flow_guide == "velocity_forward"
    assert [whole.run_frame(i)["status"] for i in range(4)] == ["stylized"] * 4
    # Interrupted after frame 2 (a new job, as after a restart), then resumed.
    part = fluidymation.MediaJob(exemplar, cache, [1, 2, 3, 4], tmp_path / "part", **FAST)
    part.run_frame(0), part.run_frame(1)
    with pytest.raises(tempera.Cancelled):
        part.run_frame(2, progress=lambda f: False)
    import os
    assert not os.path.exists(part.output_path(3))
    again = fluidymation.MediaJob(exemplar, cache, [1, 2, 3, 4], tmp_path / "part", **FAST)
    assert [again.run_frame(i)["status"] for i in range(4)] == ["skipped", "skipped", "stylized", "stylized"]
    for f in (1, 2, 3, 4):
        a, b = read_image(whole.output_path(f)), read_image(again.output_path(f))
        assert np.array_equal(a, b), f
        assert np.allclose(a[..., 3], disc(7 + 1.5 * (f - 1)), atol=1 / 255)
    # An output changed after it was written is made again, the same as before.
    tempera.write_image(again.output_path(4), np.zeros((SIZE, SIZE, 4), np.float32))
    fresh = fluidymation.MediaJob(exemplar, cache, [1, 2, 3, 4], tmp_path / "part", **FAST)
    assert [fresh.run_frame(i)["status"] for i in range(4)] == ["skipped"] * 3 + ["stylized"]
    assert np.array_equal(read_image(fresh.output_path(4)), read_image(whole.output_path(4)))
    whole.write_contact_sheet(tmp_path / "sheet.png")
    assert (tmp_path / "sheet.png").is_file()


def test_media_job_runs_earlier_frames_first_and_rejects_bad_input(tmp_path):
    exemplar, cache = make_inputs(tmp_path, frames=3)
    job = fluidymation.MediaJob(exemplar, cache, [1, 2, 3], tmp_path / "out", flow="masks", **FAST)
    assert job.flow_guide is None
    assert job.run_frame(2)["status"] == "stylized"
    assert job.run_frame(0)["status"] == "skipped"
    both = fluidymation.MediaJob(exemplar, cache, [1, 2, 3], tmp_path / "both", bidirectional=True, **FAST)
    assert [both.run_frame(i)["status"] for i in range(3)] == ["stylized"] * 3
    assert np.allclose(read_image(both.output_path(3))[..., 3], disc(7 + 3.0), atol=1 / 255)
    with pytest.raises(ValueError, match="consecutive"):
        fluidymation.MediaJob(exemplar, cache, [1, 3], tmp_path / "bad")
    with pytest.raises(ValueError, match="mask.OB_Nope"):
        fluidymation.MediaJob(exemplar, cache, [1, 2], tmp_path / "bad", target_mask="mask.OB_Nope")
    with pytest.raises(FileNotFoundError):
        fluidymation.MediaJob(tmp_path / "none", cache, [1, 2], tmp_path / "bad")


def test_auto_flow_prefers_fluid_velocity(tmp_path):
    """As on Mantaflow smoke: velocity_forward zero, the motion in fluid_velocity.
    Auto must solve with fluid_velocity (the result of --flow fluid), not the zeros."""
    exemplar, cache = make_inputs(tmp_path, frames=3)
    for f in (1, 2, 3):
        guides = guide_cache.read_frame(cache, f, ["alpha", "velocity_forward"])
        guide_cache.write_frame(cache, f, {"alpha": guides["alpha"], "fluid_velocity": guides["velocity_forward"],
                                           "velocity_forward": np.zeros_like(guides["velocity_forward"])})
    results = {}
    for flow in ("auto", "fluid", "guides"):
        job = fluidymation.MediaJob(exemplar, cache, [1, 2, 3], tmp_path / f"out_{flow}", flow=flow, **FAST)
        assert job.flow_guide == {"guides": "velocity_forward"}.get(flow, "fluid_velocity")
        assert [job.run_frame(i)["status"] for i in range(3)] == ["stylized"] * 3
        results[flow] = read_image(job.output_path(3))
    assert np.array_equal(results["auto"], results["fluid"])
    assert np.abs(results["auto"] - results["guides"]).max() > 0.1  # the flow matters
    guide_cache.write_frame(cache, 1, {"alpha": disc(7)})
    with pytest.raises(ValueError, match="--flow fluid needs fluid_velocity"):
        fluidymation.MediaJob(exemplar, cache, [1, 2, 3], tmp_path / "none", flow="fluid", **FAST)


def test_media_job_takes_rgb_frames_with_a_mask_folder(tmp_path):
    _, cache = make_inputs(tmp_path, frames=2)
    rgb, masks = tmp_path / "rgb", tmp_path / "masks"
    rgb.mkdir(), masks.mkdir()
    for i, f in enumerate(ink_frames()):
        write_image(str(rgb / f"f{i:02d}.png"), np.ascontiguousarray(f[..., :3]))
        write_image(str(masks / f"m{i:02d}.png"), np.ascontiguousarray(f[..., 3:]))
    job = fluidymation.MediaJob(rgb, cache, [1, 2], tmp_path / "out", exemplar_masks=masks, format="exr", **FAST)
    assert [job.run_frame(i)["status"] for i in range(2)] == ["stylized"] * 2
    out = read_image(job.output_path(2))
    assert out.shape == (SIZE, SIZE, 4) and np.all(out[disc(8.5) <= 0.5, :3] == 0)
    with pytest.raises(ValueError, match="no alpha"):
        fluidymation.MediaJob(rgb, cache, [1, 2], tmp_path / "bad")


def test_cli_runs_and_exits_2_on_bad_input(tmp_path, cli_path):
    exemplar, cache = make_inputs(tmp_path, frames=2)
    base = [str(cli_path), "stylize", "--method", "fluidymation", "--guides", str(cache), "--exemplar",
            str(exemplar), "--out", str(tmp_path / "out")]
    ok = subprocess.run(base + ["--frames", "1-2", "--shape-blur", "6", "--levels", "2"], capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    assert (tmp_path / "out" / "frames" / "frame_0002.png").is_file()  # the one layout: OUT/frames
    assert "skipped" in subprocess.run(base + ["--frames", "1-2", "--shape-blur", "6", "--levels", "2"],
                                       capture_output=True, text=True).stdout
    for extra, message in ((["--frames", "1-2", "--flow", "sideways"], "flow"),
                           (["--frames", "1-2", "--temporal-weight", "-1"], "temporal"),
                           (["--frames", "1,2", "--target-mask", "depth"], "target mask"),
                           (["--frames", "1-2", "--bogus"], "unknown option")):
        bad = subprocess.run(base + extra, capture_output=True, text=True)
        assert bad.returncode == 2, (extra, bad.stderr)
        assert message in bad.stderr
    helptext = subprocess.run(base[:4] + ["--help"], capture_output=True, text=True).stdout
    assert "--exemplar-masks" in helptext and "--boundary-weight" in helptext


def test_cli_runs_through_the_registrys_one_command(tmp_path, cli_path):
    """Issue 41: Fluidymation has no command of its own; the registry's one
    command gives it a lone switch, the engine's image cap, its contact sheet
    and the flow it used on the last line."""
    exemplar, cache = make_inputs(tmp_path, frames=2)
    out = tmp_path / "out"
    run = subprocess.run([str(cli_path), "stylize", "--method", "fluidymation", "--guides", str(cache),
                          "--exemplar", str(exemplar), "--bidirectional", "--frames", "1-2", "--out", str(out),
                          "--shape-blur", "6", "--levels", "2", "--max-image-pixels", "100000"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "2 frame(s) stylized" in run.stdout and "flow from " in run.stdout, run.stdout
    assert (out / "contact_sheet.png").is_file() and (out / "frames" / "frame_0002.png").is_file()
    tiny = subprocess.run([str(cli_path), "stylize", "--method", "fluidymation", "--guides", str(cache),
                           "--exemplar", str(exemplar), "--frames", "1-2", "--out", str(tmp_path / "tiny"),
                           "--max-image-pixels", "100"], capture_output=True, text=True)
    assert tiny.returncode != 0 and "100" in tiny.stderr, tiny.stderr


@pytest.mark.parametrize("bidirectional", [False, True])
def test_an_empty_target_mask_gives_a_transparent_frame(tmp_path, bidirectional):
    """Issue 31, item 12: an object off screen for a frame stopped the shot
    ("target mask is empty", no frame named). Now that frame is transparent,
    as in LazyFluids, and the frame after it starts afresh."""
    exemplar, cache = make_inputs(tmp_path, frames=3)
    guide_cache.write_frame(cache, 2, {"alpha": np.zeros((SIZE, SIZE), np.float32),
                                       "velocity_forward": np.zeros((SIZE, SIZE, 2), np.float32)})
    job = fluidymation.MediaJob(exemplar, cache, [1, 2, 3], tmp_path / "out", bidirectional=bidirectional, **FAST)
    assert [job.run_frame(i)["status"] for i in range(3)] == ["stylized"] * 3
    empty = read_image(job.output_path(2))
    assert empty[..., 3].max() == 0
    after = read_image(job.output_path(3))
    inside = disc(7 + 3.0) > 0.5
    assert np.allclose(after[..., 3], disc(7 + 3.0), atol=1 / 255)
    assert after[inside, :3].std() > 0.02  # painted, not blank
