"""The project's own exemplars (tempera.app.media_exemplars) and `tempera
exemplar`: seamless loops, soft alpha, the ink front's measured speed, masks
from the pigment, determinism by seed, named errors with exit status 2."""
import numpy as np
import pytest

from tempera.app import media_exemplars as me
from tempera import read_image
from tempera.__main__ import main

INK_SIZE, INK_FRAMES = 160, 20


def _step(a, b):
    """Mean absolute difference of two RGBA frames, premultiplied (colour where there is smoke)."""
    return float(np.abs(a[..., :3] * a[..., 3:] - b[..., :3] * b[..., 3:]).mean() + np.abs(a[..., 3] - b[..., 3]).mean())


def _wrap_over_step(frames):
    steps = [_step(frames[i], frames[i + 1]) for i in range(len(frames) - 1)]
    assert min(steps) > 1e-3, "the loop does not move"
    return _step(frames[-1], frames[0]) / np.mean(steps)


@pytest.mark.parametrize("kind", me.KINDS)
@pytest.mark.parametrize("width, height", [(96, 96), (64, 150)])
def test_loop_is_seamless(kind, width, height):
    frames = me.smoke_loop(width, height, 12, seed=3, kind=kind)
    assert 0.6 < _wrap_over_step(frames) < 1.5
    assert np.array_equal(frames[0], me.smoke_still(width, height, 3, kind)), "the first frame is the still"


@pytest.mark.parametrize("kind", me.KINDS)
def test_seam_check_sees_a_cut_loop(kind):
    """Half of a 24-frame loop does not loop: the same check sees the jump."""
    assert _wrap_over_step(me.smoke_loop(96, 96, 24, seed=3, kind=kind)[:12]) > 2.0


@pytest.mark.parametrize("kind", me.KINDS)
def test_alpha_is_soft_and_in_unit_range(kind):
    rgba = me.smoke_still(128, 128, seed=5, kind=kind)
    assert rgba.shape == (128, 128, 4) and rgba.dtype == np.float32
    assert rgba.min() >= 0 and rgba.max() <= 1
    alpha = rgba[..., 3]
    covered = alpha > 0.02
    assert 0.05 < covered.mean() < 0.8, "the element covers a part of the frame, not none or all"
    assert alpha.max() > 0.5
    assert (alpha[covered] < 0.98).mean() > 0.5, "most of the element is partly transparent"
    steepest = max(np.abs(np.diff(alpha, axis=0)).max(), np.abs(np.diff(alpha, axis=1)).max())
    assert steepest < 0.4, f"alpha jumps by {steepest} between neighbours: a hard edge"


def _front_speed(masks):
    radius = [np.sqrt(m.sum() / np.pi) for m in masks]
    return np.polyfit(np.arange(len(radius)), radius, 1)[0]


@pytest.mark.parametrize("speed", [1.0, 2.5])
def test_ink_front_moves_at_the_speed(speed):
    rgb, masks = me.ink_video(INK_SIZE, INK_SIZE, INK_FRAMES, speed, seed=7)
    measured = _front_speed(masks)
    assert abs(measured - speed) <= 0.1 * speed, f"front speed {measured:.3f} px/frame for {speed}"
    last = masks[-1].astype(bool)
    assert not (last[0].any() or last[-1].any() or last[:, 0].any() or last[:, -1].any()), "front left the frame"
    assert rgb[-1][last].mean() < 0.75 * rgb[-1][~last].mean(), "ink darker than the paper"


def test_mask_is_pigment_over_threshold():
    sim = me.ink_simulation(96, 96, 8, 1.5, seed=2)
    rgb, masks = me.ink_video(96, 96, 8, 1.5, seed=2)
    for (picture, pigment), frame, mask in zip(sim, rgb, masks):
        assert 0 <= pigment.min() and pigment.max() <= 1
        assert np.array_equal(mask, (pigment > me.INK_THRESHOLD).astype(np.float32))
        assert np.array_equal(picture, frame)
        assert 0 <= frame.min() and frame.max() <= 1 and frame.shape == (96, 96, 3)
    assert masks[-1].sum() > masks[0].sum() > 0


def _bytes(frames):
    return b"".join(np.asarray(f).tobytes() for f in frames)


def test_same_seed_same_bytes_and_different_seed_different():
    assert _bytes(me.smoke_loop(64, 64, 3, 11, "fire")) == _bytes(me.smoke_loop(64, 64, 3, 11, "fire"))
    assert _bytes(me.smoke_loop(64, 64, 3, 11, "fire")) != _bytes(me.smoke_loop(64, 64, 3, 12, "fire"))
    assert _bytes(me.smoke_still(64, 64, 11)) != _bytes(me.smoke_still(64, 64, 12))
    a, b, c = (me.ink_video(64, 64, 4, 1.0, s) for s in (4, 4, 5))
    assert _bytes(a[0] + a[1]) == _bytes(b[0] + b[1])
    assert _bytes(a[0]) != _bytes(c[0])


@pytest.mark.parametrize("call, message", [
    (lambda: me.smoke_still(8, 64, 1), "width"),
    (lambda: me.smoke_still(64, 64.5, 1), "height"),
    (lambda: me.smoke_still(64, 64, 1, kind="water"), "kind"),
    (lambda: me.smoke_loop(64, 64, 0, 1), "frames"),
    (lambda: me.ink_video(64, 64, 4, 0.0, 1), "speed"),
    (lambda: me.ink_video(64, 64, 4, float("nan"), 1), "speed"),
    (lambda: me.ink_video(64, 64, 4, 20.0, 1), "speed"),
])
def test_bad_input_is_named(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_cli_writes_frames_and_masks(tmp_path):
    assert main(["exemplar", "ink", "--out", str(tmp_path / "ink"), "--size", "64x48", "--frames", "3",
                 "--speed", "1.5", "--seed", "9"]) == 0
    rgb, masks = me.ink_video(64, 48, 3, 1.5, 9)
    for i in range(3):
        image = read_image(str(tmp_path / "ink" / me.frame_name(i)))
        mask = read_image(str(tmp_path / "ink" / "masks" / me.frame_name(i)))
        assert image.shape == (48, 64, 3) and np.abs(image - rgb[i]).max() <= 0.5 / 255 + 1e-6
        assert np.array_equal(mask[..., 0], masks[i])
    assert main(["exemplar", "smoke", "--out", str(tmp_path / "smoke"), "--size", "32x32", "--frames", "2"]) == 0
    assert read_image(str(tmp_path / "smoke" / "frame_0002.png")).shape == (32, 32, 4)
    assert not (tmp_path / "smoke" / "frame_0003.png").exists() and not (tmp_path / "smoke" / "masks").exists()


@pytest.mark.parametrize("argv, message", [
    (["fire", "--size", "64"], "--size expects WxH"),
    (["smoke", "--speed", "2"], "--speed is for ink only"),
    (["ink", "--frames", "0"], "frames"),
    (["ink", "--speed", "-1"], "speed"),
    (["water"], "invalid choice"),
    (["ink", "--frames", "many"], "invalid int"),
])
def test_cli_bad_input_exits_2(tmp_path, capsys, argv, message):
    assert main(["exemplar", *argv, "--out", str(tmp_path / "x")]) == 2
    assert message in capsys.readouterr().err
    assert not any((tmp_path / "x").glob("*.png")) if (tmp_path / "x").exists() else True


def test_ink_mask_by_threshold_finds_the_simulated_pigment():
    """The recipe for filmed ink (a threshold on the optical density against
    the paper) recovers the simulation's own masks."""
    rgb, masks = me.ink_video(128, 128, 12, 2.0, seed=3)
    for frame, mask in zip(rgb[2:], masks[2:]):
        found = me.ink_mask(frame).astype(bool)
        truth = mask.astype(bool)
        assert (found & truth).sum() / (found | truth).sum() > 0.9
    assert not me.ink_mask(np.full((8, 8, 3), 0.9)).any()
    with pytest.raises(ValueError, match="expected an"):
        me.ink_mask(np.zeros((8, 8)))


def test_ink_edges_are_darker_than_the_inside():
    """Watercolour's darker rim: the optical density next to the front
    exceeds the density well inside it."""
    rgb, masks = me.ink_video(128, 128, 16, 2.0, seed=4)
    frame, mask = rgb[-1], masks[-1].astype(bool)
    density = -np.log(np.clip(frame, 1e-4, None) / me.PAPER).mean(axis=2)
    inside = mask.copy()
    for _ in range(2):  # two pixels in from the front
        inside[1:-1, 1:-1] &= inside[:-2, 1:-1] & inside[2:, 1:-1] & inside[1:-1, :-2] & inside[1:-1, 2:]
    rim = mask & ~inside
    deep = inside.copy()
    for _ in range(8):
        deep[1:-1, 1:-1] &= deep[:-2, 1:-1] & deep[2:, 1:-1] & deep[1:-1, :-2] & deep[1:-1, 2:]
    assert rim.sum() > 50 and deep.sum() > 50
    assert density[rim].mean() > 1.2 * density[deep].mean()
