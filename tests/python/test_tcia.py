"""tempera.methods.tcia.tcia: Bénard et al. 2013's sweeps from Python."""
import numpy as np
import pytest

from tempera.methods.tcia import tcia
from tempera.engine import temporal


def shot(frames=5, w=48, h=32, speed=2):
    rng = np.random.default_rng(2)
    style = rng.random((48, 64, 3)).astype(np.float32)
    uv_s = np.stack(np.meshgrid(np.arange(64) / 64, np.arange(48) / 48), -1).astype(np.float32)
    out = []
    for t in range(frames):
        xs, ys = np.meshgrid((np.arange(w) - speed * t + 12) / 64, (np.arange(h) + 8) / 48)
        v = np.zeros((h, w, 2), np.float32)
        v[..., 0] = speed
        chi_m, chi_p = np.ones((h, w), np.float32), np.ones((h, w), np.float32)
        chi_m[:, :speed], chi_p[:, -speed:] = 0, 0
        out.append(dict(guides=[np.stack([xs, ys], -1).astype(np.float32)], velocity_backward=v, velocity_forward=v,
                        occlusion_backward=chi_m, occlusion_forward=chi_p))
    return style, [("uv", uv_s, 4.0)], out


def test_shot_is_coherent_and_reports_progress():
    style, guides, frames = shot()
    seen = []
    out = tcia.stylize_shot(style, guides, frames, levels=3, patch_size=7, threads=2, progress=seen.append)
    assert len(out) == 5 and out[0].shape == (32, 48, 3)
    assert seen and seen[-1] == pytest.approx(1.0) and seen == sorted(seen)
    flick = np.mean([temporal.flicker(out[t - 1], out[t], frames[t]["velocity_backward"],
                                      frames[t]["occlusion_backward"]) for t in range(1, 5)])
    assert flick < 0.01


def test_a_shot_without_guides_has_its_frames_size():
    style, _, frames = shot(frames=2)
    out = tcia.stylize_shot(style, [], [dict(f, guides=[]) for f in frames], levels=2, patch_size=7)
    assert [o.shape for o in out] == [(32, 48, 3)] * 2


def test_cancel_and_bad_options():
    style, guides, frames = shot(frames=2)
    import tempera

    with pytest.raises(tempera.Cancelled):
        tcia.stylize_shot(style, guides, frames, levels=2, progress=lambda f: False)
    with pytest.raises(TypeError, match="sparkle"):
        tcia.stylize_shot(style, guides, frames, sparkle=1)
    with pytest.raises(ValueError, match="velocity_forward"):
        bad = [dict(frames[0])]
        del bad[0]["velocity_forward"]
        tcia.stylize_shot(style, guides, bad)


def test_orientation_fields_reach_the_method():
    style, guides, frames = shot(frames=2)
    turned = [dict(f, orientation=np.full((32, 48), 0.5, np.float32)) for f in frames]
    with pytest.raises(ValueError, match="the style has none"):
        tcia.stylize_shot(style, guides, turned, levels=2, patch_size=7)
    flat = tcia.stylize_shot(style, guides, frames, levels=2, patch_size=7, threads=2)
    out = tcia.stylize_shot(style, guides, turned, levels=2, patch_size=7, threads=2,
                            style_orientation=np.zeros((48, 64), np.float32))
    assert out[0].shape == (32, 48, 3)
    assert not np.array_equal(out[0], flat[0])  # patches compared turned by 0.5 rad


def test_a_key_comes_out_as_painted():
    style, guides, frames = shot(frames=4)
    painting = np.random.default_rng(5).random((32, 48, 3)).astype(np.float32)
    mask = np.zeros((32, 48), np.float32)
    mask[8:24, 10:30] = 1
    out = tcia.stylize_shot(style, guides, frames, keys=[(2, painting, mask)], levels=3, patch_size=7, threads=2)
    np.testing.assert_allclose(out[2][8:24, 10:30], painting[8:24, 10:30], atol=1 / 255)


def test_an_empty_key_mask_is_named_as_the_keys():
    """The solver sees a key as an extra exemplar and used to say "exemplar 1 mask is empty"."""
    style, guides, frames = shot(frames=4)
    painting = np.random.default_rng(5).random((32, 48, 3)).astype(np.float32)
    with pytest.raises(ValueError, match="the mask of keyframe 2 is empty") as error:
        tcia.stylize_shot(style, guides, frames, keys=[(2, painting, np.zeros((32, 48), np.float32))], levels=3,
                          patch_size=7, threads=2)
    assert "exemplar 1" not in str(error.value)


def test_shot_job_runs_segments_like_the_cli(tmp_path):
    from synthetic_cache import make_cache, make_exemplar

    make_cache(tmp_path / "cache", frames=(1, 2, 3, 4, 5), forward=True)
    make_exemplar(tmp_path / "ex", tmp_path / "paint.png")
    key = tmp_path / "paint.png"
    assert tcia.segments(range(1, 6), [3]) == [(1, 3), (3, 5)] and tcia.segments([4], [4]) == [(4, 4)]
    seen = []
    job = tcia.ShotJob(tmp_path / "paint.png", tmp_path / "ex", tmp_path / "cache", range(1, 6), tmp_path / "out",
                       keys=[(3, key)], weights={"LDE": 3}, levels=2, patch_size=7)
    assert [s[:2] for s in job.segments] == tcia.segments(range(1, 6), [3]) and job.selected == [0, 1]
    assert job.segments[0][2] == [1, 2] and job.segments[1][2] == [3, 4, 5]
    assert job.run_segment(0, seen.append)["status"] == "stylized"
    assert seen[-1]["fraction"] == pytest.approx(1.0) and {d["direction"] for d in seen} == {1, -1}
    assert job.run_segment(0)["status"] == "skipped"
    import tempera

    with pytest.raises(tempera.Cancelled):
        job.run_segment(1, lambda d: False)
    assert not (tmp_path / "out" / "frame_0003.png").exists()
    with pytest.raises(ValueError, match="segment 2-4 is not one"):
        tcia.ShotJob(key, tmp_path / "ex", tmp_path / "cache", range(1, 6), tmp_path / "o", keys=[(3, key)],
                     segment=(2, 4))


def _ring(h, w, cx, cy, r):
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    return (np.abs(np.hypot(xx - cx, yy - cy) - r) < 0.75).astype(np.float32)


def test_line_term_puts_the_ink_on_the_frames_lines():
    """Eq. 9: a line painting (wobbly dark rings on paper) whose D(S) is
    paired with the frames' D(I) (rings moving 2 px per frame): at least 95%
    of the ink lies within d_max of the lines and at least 90% of the line
    pixels have ink within 2 px. Without the term the ink lands anywhere."""
    from tempera.engine.guides import line_distance

    d_max, rng = 10.0, np.random.default_rng(1)
    yy, xx = np.mgrid[0:64, 0:80].astype(np.float32)
    ink = np.zeros((64, 80), np.float32)
    for cx, cy, r in [(20, 20, 12), (58, 40, 16), (30, 48, 9)]:
        wobble = r + np.sin(5 * np.arctan2(yy - cy, xx - cx))
        ink = np.maximum(ink, (np.abs(np.hypot(xx - cx, yy - cy) - wobble) < 1.2).astype(np.float32))
    style = np.where(ink[..., None] > 0, (0.1, 0.1, 0.15), (0.95, 0.93, 0.88)).astype(np.float32)
    style += 0.03 * rng.random(style.shape, dtype=np.float32)
    frames, lines = [], []
    for t in range(4):
        m = np.maximum(_ring(48, 56, 20 + 2 * t, 24, 12), _ring(48, 56, 40 + 2 * t, 20, 7))
        v = np.zeros((48, 56, 2), np.float32)
        v[..., 0] = 2
        lines.append(m)
        frames.append(dict(guides=[line_distance(m, d_max)], velocity_backward=v, velocity_forward=v,
                           occlusion_backward=np.ones((48, 56), np.float32),
                           occlusion_forward=np.ones((48, 56), np.float32)))

    def scores(guides, shot):
        out = tcia.stylize_shot(style, guides, shot, levels=2, patch_size=7, threads=2)
        within, covered = [], []
        for o, f, m in zip(out, frames, lines):
            inked = o.mean(-1) < 0.5
            within.append((f["guides"][0][inked] < 1).mean())  # D(I) < 1: within d_max
            covered.append((line_distance(inked.astype(np.float32), d_max)[m > 0] * d_max <= 2).mean())
        return min(within), min(covered)

    within, covered = scores([("line_distance", line_distance(ink, d_max), 4.0)], frames)
    assert within >= 0.95 and covered >= 0.90, (within, covered)
    flat = [dict(f, guides=[np.zeros((48, 56), np.float32)]) for f in frames]  # the term off: no line information
    off = scores([("flat", np.zeros((64, 80), np.float32), 4.0)], flat)
    assert off[0] < 0.95 or off[1] < 0.90, off
