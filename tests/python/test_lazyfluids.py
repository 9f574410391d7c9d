"""LazyFluids from Python: options, arrays in/out, the guide-cache job (resume,
cancel, warnings) and `tempera stylize --method lazyfluids` errors."""
import subprocess

import numpy as np
import pytest

import tempera
from tempera.app import guide_cache
from tempera.methods.lazyfluids import lazyfluids

H, W = 36, 44


def smoke(n=20, seed=1):
    """Smoke-like RGBA exemplar: noise in RGB, a soft alpha disc."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:n, 0:n]
    alpha = np.clip((0.42 * n - np.hypot(xx - (n - 1) / 2, yy - (n - 1) / 2)) / 1.5, 0, 1)
    return np.dstack([rng.random((n, n, 3)), alpha]).astype(np.float32)


def disc(cx, cy=H / 2, r=11):
    yy, xx = np.mgrid[0:H, 0:W]
    return np.clip(r - np.hypot(xx - cx, yy - cy) + 0.5, 0, 1).astype(np.float32)


def flow(vx=2.0):
    f = np.zeros((H, W, 2), np.float32)
    f[..., 0] = vx
    return f


FAST = dict(em_iterations=2, threads=2)


def test_options_have_the_thesis_defaults_and_reject_typos():
    o = lazyfluids.options()
    assert (o.temporal_weight, o.alpha_guide_weight, o.alpha_weight) == pytest.approx((0.2, 3, 3))
    assert (o.alpha_radius, o.alpha_lower, o.alpha_upper) == pytest.approx((3, 0.1, 0.9))
    assert o.rotations is False and o.motion_blur == 0
    assert o.synthesis.usage == "uniform" and o.synthesis.patch_size == 5
    assert lazyfluids.options(usage="none", temporal_weight=0.5).temporal_weight == pytest.approx(0.5)
    with pytest.raises(TypeError):
        lazyfluids.options(lamda=0.2)


def test_sequence_on_arrays_is_transparent_outside_and_deterministic():
    alphas = [disc(16), disc(18), disc(20)]
    out = lazyfluids.stylize_sequence(smoke(), alphas, [flow()] * 3, **FAST)
    assert len(out) == 3 and out[0].shape == (H, W, 4)
    yy, xx = np.mgrid[0:H, 0:W]
    for cx, a, o in zip((16, 18, 20), alphas, out):
        far = np.hypot(xx - cx, yy - H / 2) > 11 + 8  # blurred alpha (sigma 3) far below 0.1: outside
        assert np.all(o[far] == 0)
        iou = np.logical_and(o[..., 3] > 0.5, a > 0.5).sum() / np.logical_or(o[..., 3] > 0.5, a > 0.5).sum()
        assert iou >= 0.9
    again = lazyfluids.stylize_sequence(smoke(), alphas, [flow()] * 3, **dict(FAST, threads=1))
    assert all(np.array_equal(a, b) for a, b in zip(out, again))


@pytest.mark.parametrize("warm_start,temporal_weight", [(False, 0.2), (True, 0.2), (True, 0.0)])
def test_frames_chained_one_by_one_are_the_sequence(warm_start, temporal_weight):
    """stylize_frame (what benches chain) gives the sequence driver's frames bit for bit;
    a warm frame solves the finest level alone, and only with a temporal term (λ > 0)."""
    alphas = [disc(16), disc(18), disc(20)]
    values = dict(FAST, warm_start=warm_start, temporal_weight=temporal_weight, levels=2)
    sequence = lazyfluids.stylize_sequence(smoke(), alphas, [flow()] * 3, **values)
    previous = field = None
    for t, alpha in enumerate(alphas):
        chained = {} if t == 0 else dict(previous=previous, previous_field=field, flow_previous=flow())
        image, stats = lazyfluids.stylize_frame(smoke(), alpha, **values, **chained)
        np.testing.assert_array_equal(image, sequence[t])
        assert stats["final_energy"] > 0 and stats["field"].shape == (H, W, 2)
        if t == 0:
            cold_levels = len(stats["levels"])
        warm = warm_start and temporal_weight > 0 and t > 0
        assert len(stats["levels"]) == (1 if warm else cold_levels)
        previous, field = image, stats["field"]
    assert cold_levels == 2
    with pytest.raises(ValueError, match="flow_previous"):
        lazyfluids.stylize_frame(smoke(), alphas[1], previous=previous, **values)


def test_temporal_weights_are_equation_5_6():
    rng = np.random.default_rng(2)
    target, advected = rng.random((5, 6)).astype(np.float32), rng.random((5, 6, 4)).astype(np.float32)
    w = lazyfluids.temporal_weights(target, advected, 0.2)[..., 0]
    expected = ((np.float32(1) - np.maximum(np.float32(0), target - advected[..., 3])) * np.float32(0.2))
    np.testing.assert_array_equal(w, expected.astype(np.float32))


def test_bad_arrays_are_value_errors():
    with pytest.raises(ValueError, match="exemplar"):
        lazyfluids.stylize_sequence(smoke()[..., :3], [disc(16)], [flow()])
    with pytest.raises(ValueError, match="flow"):
        lazyfluids.stylize_sequence(smoke(), [disc(16)], [flow()[..., :1]])


@pytest.fixture()
def cache(tmp_path):
    for f in range(1, 5):
        guides = {"alpha": disc(14 + 2 * f)}
        if f != 3:  # frame 3 falls back to velocity_forward
            guides["fluid_velocity"] = flow()
        else:
            guides["velocity_forward"] = flow()
        guide_cache.write_frame(tmp_path / "cache", f, guides)
    tempera.write_image(str(tmp_path / "smoke.png"), smoke())
    return tmp_path


def run_all(job):
    return [job.run_frame(i)["status"] for i in range(len(job.frames))]


@pytest.mark.parametrize("warm_start", [False, True])
def test_job_resume_equals_uninterrupted_and_cancel_writes_nothing(cache, warm_start):
    FAST = dict(em_iterations=2, threads=2, warm_start=warm_start)
    whole = lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", range(1, 5), cache / "whole", **FAST)
    assert any("velocity_forward" in w and "3" in w for w in whole.warnings)
    assert run_all(whole) == ["stylized"] * 4
    part = lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", range(1, 5), cache / "part", **FAST)
    part.run_frame(0), part.run_frame(1)
    with pytest.raises(tempera.Cancelled):
        part.run_frame(2, progress=lambda f: f < 0.3)
    assert not (cache / "part" / "frame_0003.png").exists()
    resumed = lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", range(1, 5), cache / "part", **FAST)
    assert run_all(resumed) == ["skipped", "skipped", "stylized", "stylized"]
    for f in range(1, 5):
        assert (cache / "whole" / f"frame_{f:04d}.png").read_bytes() == (cache / "part" / f"frame_{f:04d}.png").read_bytes()
    assert resumed.output_path(4).endswith("frame_0004.png")
    resumed.write_contact_sheet(cache / "sheet.png")
    assert tempera.read_image(str(cache / "sheet.png")).shape[2] == 4


def test_job_checks_its_inputs(cache):
    with pytest.raises(ValueError, match="consecutive"):
        lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", [1, 3], cache / "o")
    tempera.write_image(str(cache / "rgb.png"), smoke()[..., :3].copy())
    with pytest.raises(ValueError, match="RGBA"):
        lazyfluids.FluidJob(cache / "rgb.png", cache / "cache", [1, 2], cache / "o")
    with pytest.raises(FileNotFoundError):
        lazyfluids.FluidJob(cache / "missing.png", cache / "cache", [1, 2], cache / "o")


def test_a_frame_asked_for_first_makes_its_predecessors_like_fluidymation(cache):
    """Frames are chained (app/frame_job.hpp ChainedFrameJob): asking for the
    last frame of a fresh job makes the ones before it first, in order, as
    Fluidymation does, and the result equals an in-order run."""
    job = lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", [1, 2, 3], cache / "o", **FAST)
    calls = []
    assert job.run_frame(2, progress=lambda f: calls.append(f) or True)["status"] == "stylized"
    assert calls == sorted(calls) and calls[-1] <= 1.0 and calls[0] < 1 / 3  # one bar over the three frames
    assert [job.run_frame(i)["status"] for i in range(3)] == ["skipped"] * 3
    in_order = lazyfluids.FluidJob(cache / "smoke.png", cache / "cache", [1, 2, 3], cache / "in_order", **FAST)
    assert run_all(in_order) == ["stylized"] * 3
    for f in (1, 2, 3):
        name = f"frame_{f:04d}.png"
        assert (cache / "o" / name).read_bytes() == (cache / "in_order" / name).read_bytes()


def test_video_exemplar_folder(cache):
    (cache / "video").mkdir()
    for i in range(2):
        tempera.write_image(str(cache / "video" / f"z_{i}.png"), smoke(seed=10 + i))
    job = lazyfluids.FluidJob(cache / "video", cache / "cache", [1, 2], cache / "v", **FAST)
    assert run_all(job) == ["stylized"] * 2


def stylize(cli_path, *args):
    return subprocess.run([str(cli_path), "stylize", "--method", "lazyfluids", *map(str, args)], capture_output=True,
                          text=True, timeout=300)


def test_cli_runs_resumes_and_rejects_bad_input(cli_path, cache):
    base = ("--guides", cache / "cache", "--exemplar", cache / "smoke.png", "--frames", "1-2", "--out", cache / "cli",
            "--em-iters", "2", "--motion-blur", "3", "--rotations", "--warm-start")
    first = stylize(cli_path, *base)
    assert first.returncode == 0, first.stderr
    assert (cache / "cli" / "frames" / "frame_0002.png").is_file() and (cache / "cli" / "contact_sheet.png").is_file()
    assert "skipped" in stylize(cli_path, *base).stdout
    assert "--lambda" in stylize(cli_path, "--help").stdout
    for bad in (("--lambda", "-1"), ("--alpha-lower", "0.95"), ("--frames", "1,3"), ("--bogus", "1"),
                ("--format", "gif")):
        r = stylize(cli_path, *base, *bad)  # a later --frames replaces the first
        assert r.returncode == 2, (bad, r.stderr)


def test_video_exemplar_arrays_loop_and_progress_cancels():
    video = [smoke(seed=20), smoke(seed=21)]
    alphas = [disc(16)] * 3
    looped = lazyfluids.stylize_sequence(video, alphas, [flow(0)] * 3, temporal_weight=0, **FAST)
    still = lazyfluids.stylize_sequence(video[0], alphas, [flow(0)] * 3, temporal_weight=0, **FAST)
    # λ = 0 and a still target: frame t depends only on exemplar frame t mod 2.
    assert np.array_equal(looped[0], looped[2]) and not np.array_equal(looped[0], looped[1])
    assert np.array_equal(looped[0], still[0])
    with pytest.raises(tempera.Cancelled):
        lazyfluids.stylize_sequence(video, alphas, [flow()] * 3, progress=lambda f: f < 0.5, **FAST)
