"""Color Me Noisy (tempera.methods.noisy.noisy, native/src/methods/noisy/noisy.cpp): the amount of
temporal noise follows the low-pass width f, the noise is white, R's large
shapes stay, the MLS pre-deformation and the low-frequency term matter."""
import numpy as np
import pytest

from tempera.methods.noisy import noisy
from tempera.engine import synthesis, temporal

FRAMES = 32  # a static R repeated 32 times, as in the issue


def medium(rng, h, w):
    """A grainy 'scanned medium' (smoothed noise, high contrast)."""
    n = rng.random((h, w, 3)).astype(np.float32)
    for _ in range(2):
        n = sum(np.roll(np.roll(n, a, 0), b, 1) for a in (-1, 0, 1) for b in (-1, 0, 1)) / 9
    return np.clip(0.5 + 2.5 * (n - 0.5), 0, 1).astype(np.float32)


@pytest.fixture(scope="module")
def inputs():
    rng = np.random.default_rng(1)
    style = medium(rng, 96, 96)
    reference = np.ascontiguousarray(style[10:58, 12:76])  # R is made of S, as a texture synthesis makes it
    return style, reference


def run(inputs, f, frames=FRAMES, **kw):
    style, reference = inputs
    return [noisy.noisy_frame(style, reference, i, noise=f, threads=2, **kw) for i in range(frames)]


@pytest.fixture(scope="module")
def sweep(inputs):
    return {f: run(inputs, f) for f in (1.3, 2.2, 3.1, 4.3)}


def energy(frames):
    return temporal.noise_energy(temporal.temporal_power_spectrum(frames))


def test_noise_rises_with_the_width(sweep):
    e = {f: energy(frames) for f, frames in sweep.items()}
    assert e[1.3] < e[2.2] < e[3.1] < e[4.3]
    assert e[4.3] >= 2 * e[1.3]  # measured 2.19 (docs/noisy.md)


def test_noise_rises_over_all_eight_steps():
    """Every step of the slider boils more: E rises strictly over all eight
    tested widths, on a 128 x 96 R of a 192 x 192 medium (measured, 32
    frames: 0.0233 ... 0.0475, E(4.3)/E(1.3) = 2.04 with seed 1; with seed 0
    also strict, 2.28). At the 64 x 48 of the other tests it is not: the
    coarse levels of f >= 2.6 hold too few patches (the 96 x 96 exemplar is
    36 x 36 at the 7th level, for 7 x 7 patches), and E dips at 2.6."""
    rng = np.random.default_rng(1)
    style = medium(rng, 192, 192)
    reference = np.ascontiguousarray(style[10:106, 12:140])
    e = [energy(run((style, reference), f, frames=16)) for f in noisy.TESTED_NOISE]
    assert all(a < b for a, b in zip(e, e[1:])), e
    assert e[-1] >= 2 * e[0], e


def test_noise_is_white(sweep):
    for f in (2.2, 3.1, 4.3):
        assert temporal.spectral_flatness(temporal.temporal_power_spectrum(sweep[f])) >= 0.9


def test_large_shapes_follow_the_reference(inputs, sweep):
    _, reference = inputs
    for f, frames in sweep.items():
        assert max(temporal.box_consistency_error(x, reference, f) for x in frames) <= 0.05, f
    # Without the low-frequency term they drift away from R.
    loose = run(inputs, 2.2, frames=3, consistency=0.0)
    assert max(temporal.box_consistency_error(x, reference, 2.2) for x in loose) > \
        max(temporal.box_consistency_error(x, reference, 2.2) for x in sweep[2.2])


def test_without_deformation_there_is_less_noise(inputs, sweep):
    """The paper's ablation (§3.2): without the MLS pre-deformation low f
    gives a floating texture, not noise."""
    rigid = run(inputs, 1.3, frames=12, deform=False)
    assert energy(rigid) < energy(sweep[1.3][:12])


def patch_energy(image, style, w=7):
    """The patch term of eq. 2 as the engine measures it: the mean squared
    distance of image's w x w patches (every other one) to their nearest
    patch of style, by brute force (independent of the engine's search)."""
    def patches(a, step):
        v = np.lib.stride_tricks.sliding_window_view(a, (w, w, a.shape[2]))[::step, ::step, 0]
        return v.reshape(-1, w * w * a.shape[2]).astype(np.float32)

    t, s = patches(image, 2), patches(style, 1)
    d = (t * t).sum(1)[:, None] + (s * s).sum(1)[None, :] - 2 * t @ s.T
    return float(np.maximum(d.min(1), 0).mean())


def test_the_medium_is_kept(inputs):
    """Medium kept: the finest-level energy of a noisy frame (its patches'
    distance to the undeformed S) is at most 1.25x that of the same frame
    without noise, R, here a plain synthesis of S (so R is the engine's
    best fit of S at that size, as a coherent pass makes it), as a mean over
    8 frames. Measured (docs/noisy.md): 1.24, 1.22, 1.21, 1.21 at f = 1.3, 2.2, 3.1, 4.3; single
    frames at f = 4.3 spread from 0.88 to 1.34, so 2 frames were not enough
    to tell 4.3 from the bound. An unsolved finest level (1 EM x 1 PM) gives
    1.43."""
    style, _ = inputs
    # Usage none: the error budget would spread S's patches at the cost of their fit.
    reference, _ = synthesis.synthesize(style, target_shape=(48, 64), patch_size=7, threads=2, seed=3, usage="none")
    kept = patch_energy(reference, style)

    def ratio(f, **kw):
        return np.mean([patch_energy(noisy.noisy_frame(style, reference, i, noise=f, threads=2, **kw), style)
                        for i in range(8)]) / kept

    for f in (1.3, 2.2, 3.1, 4.3):
        assert ratio(f) <= 1.25, f
    assert ratio(2.2, em_iterations=1, pm_iterations=1) > 1.25  # the test notices a finest level left unsolved


def test_a_full_noise_map_changes_nothing(inputs):
    style, reference = inputs
    ones = np.ones(reference.shape[:2], np.float32)
    for i in range(2):
        np.testing.assert_array_equal(noisy.noisy_frame(style, reference, i, noise=3.1, noise_map=ones, threads=2),
                                      noisy.noisy_frame(style, reference, i, noise=3.1, threads=2))


def test_a_split_map_splits_the_noise_in_the_global_ratio(inputs, sweep):
    """§3.3: the calm half (f_p = 1.3) boils like a global 1.3, the lively
    half (4.3) like a global 4.3: their energy ratio is the global one
    (within 30%; measured 0.90 of it)."""
    style, reference = inputs
    h, w = reference.shape[:2]
    split = np.ones((h, w), np.float32)
    split[:, : w // 2] = 1.3 / 4.3
    n = 16
    mapped = [noisy.noisy_frame(style, reference, i, noise=4.3, noise_map=split, threads=2) for i in range(n)]
    calm, lively = slice(4, w // 2 - 4), slice(w // 2 + 4, w - 4)  # away from the seam

    def half(frames, cols):
        return energy([x[:, cols] for x in frames])

    split_ratio = half(mapped, lively) / half(mapped, calm)
    global_ratio = half(sweep[4.3][:n], lively) / half(sweep[1.3][:n], calm)
    assert global_ratio > 1.3
    assert 0.7 * global_ratio <= split_ratio <= 1.3 * global_ratio, (split_ratio, global_ratio)


def test_bad_options_are_named(inputs):
    style, reference = inputs
    with pytest.raises(TypeError, match="sparkle"):
        noisy.noisy_frame(style, reference, 1, sparkle=3)
    with pytest.raises(ValueError, match="noise"):
        noisy.noisy_frame(style, reference, 1, noise=-2)


def test_noise_is_bounded_by_what_works_and_says_so(inputs):
    """f needs 1 + ceil(ln f / ln(1/0.85)) levels: at most 11.4 (16, the engine's most), and less for a
    small exemplar, whose coarsest level must hold a patch. The errors speak of the noise, not of levels."""
    style, reference = inputs
    small = np.ascontiguousarray(style[:48, :64])  # 64x48: its coarsest level holds a patch up to f = 5.0
    with pytest.raises(ValueError, match=r"11\.4") as too_coarse:
        noisy.noisy_frame(style, reference, 1, noise=12)
    assert "levels must be" not in str(too_coarse.value)
    with pytest.raises(ValueError, match=r"64x48 exemplar.*at most 5") as too_small:
        noisy.noisy_frame(small, reference, 1, noise=8)
    assert "levels must be" not in str(too_small.value)
    assert noisy.noisy_frame(small, reference, 1, noise=5.0).shape == reference.shape  # the largest that works
    with pytest.raises(ValueError, match="at most 5"):
        noisy.noisy_frame(small, reference, 1, noise=5.1)


def test_the_warp_error_of_a_moving_shot_rises_with_the_width(inputs):
    """A moving R (the medium sliding right 2 px a frame, its Vector passes
    as Blender writes them): the warp error along the motion, the flicker
    figure, rises strictly over f = 1.3, 2.2, 3.1, 4.3 (the issue's test on
    the moving shot), and is small for R itself (R is coherent)."""
    style, _ = inputs
    h, w, dx, n = 48, 64, 2, 6
    shot = [np.ascontiguousarray(style[10:10 + h, 24 - dx * t:24 - dx * t + w]) for t in range(n)]
    vector = np.zeros((h, w, 4), np.float32)
    vector[..., 0] = vector[..., 2] = -dx  # XY = p(t-1) - p(t), ZW = p(t) - p(t+1), content moving right
    backward, visible = temporal.motion(vector, vector)

    def warp_error(frames):
        return np.mean([temporal.flicker(a, b, backward, visible) for a, b in zip(frames, frames[1:])])

    errors = [warp_error([noisy.noisy_frame(style, r, t, noise=f, threads=2) for t, r in enumerate(shot)])
              for f in (1.3, 2.2, 3.1, 4.3)]
    assert all(a < b for a, b in zip(errors, errors[1:])), errors
    assert warp_error(shot) < 0.2 * errors[0]


def test_the_panel_steps_and_map_choices():
    assert [noisy.noise_width(k) for k in range(9)] == [0.0, *noisy.TESTED_NOISE]
    with pytest.raises(ValueError, match="0 \\(off\\) to 8"):
        noisy.noise_width(9)
    assert noisy.noise_map_spec("NONE") is None
    assert noisy.noise_map_spec("OBJECT", object_name="Face.001") == "mask.OB_Face_001"
    assert noisy.noise_map_spec("COLLECTION", collection_name="Background") == "mask.CO_Background"
    assert noisy.noise_map_spec("GUIDE", guide="aov_wetness") == "aov_wetness"
    with pytest.raises(ValueError, match="object"):
        noisy.noise_map_spec("OBJECT")


def test_a_sequence_is_made_then_current(inputs, tmp_path):
    import tempera

    style, reference = inputs
    (tmp_path / "R").mkdir()
    tempera.write_image(str(tmp_path / "medium.png"), style)
    for f in (1, 2):
        tempera.write_image(str(tmp_path / "R" / f"frame_{f:04d}.png"), reference)
    args = dict(exemplar=tmp_path / "medium.png", reference=tmp_path / "R", frames=[1, 2], out=tmp_path / "out",
                noise=2.2, threads=2)
    first = noisy.NoisySequence(**args)
    assert [first.run_frame(i)["status"] for i in range(2)] == ["made", "made"]
    assert [noisy.NoisySequence(**args).run_frame(i)["status"] for i in range(2)] == ["skipped", "skipped"]
    assert noisy.NoisySequence(**dict(args, noise=3.1)).run_frame(0)["status"] == "made"  # new settings
    with pytest.raises(tempera.Cancelled):
        noisy.NoisySequence(**dict(args, noise=1.6)).run_frame(0, lambda f: False)
    with pytest.raises(ValueError, match="neither an image file nor a guide"):
        noisy.NoisySequence(**args, noise_map="alpha")


def thin_strokes():
    """Guided noise's case (docs/noisy.md): R's thin red strokes lie on dark
    hatching; S has red strokes only in its lit half, on a lighter ground, so
    a colour-only search matches R's strokes with S's dark, unlit half."""
    rng = np.random.default_rng(1)
    red = np.array([0.9, 0.1, 0.1], np.float32)
    style = np.zeros((64, 64, 3), np.float32)
    style[:, :32] = 0.38 + 0.1 * rng.random((64, 32, 1))
    style[:, 32:] = 0.3 + 0.1 * rng.random((64, 32, 1))
    style[:, 2:32:6] = red
    lit = np.where(np.arange(64) < 32, 0.9, 0.1).astype(np.float32)
    style_guide = np.broadcast_to(lit[None, :, None], (64, 64, 1)).copy()
    reference = (0.3 + 0.1 * rng.random((40, 48, 1))).repeat(3, 2).astype(np.float32)
    reference[:, 10:26:6] = red
    x = np.arange(48)
    frame_guide = np.broadcast_to(np.where((x >= 8) & (x < 28), 0.9, 0.1)[None, :, None], (40, 48, 1))
    return style, reference, {"LDE": (style_guide, frame_guide.astype(np.float32).copy(), 1.0)}


def red_kept(out, reference):
    strokes = (reference[..., 0] > 0.7) & (reference[..., 1] < 0.3)
    return float(((out[..., 0] > 0.6) & (out[..., 1] < 0.4) & strokes).sum() / strokes.sum())


@pytest.mark.parametrize("guided", [0.5])
def test_guided_noise_keeps_the_thin_strokes(guided):
    style, reference, guides = thin_strokes()
    kept = {}
    for g in (0.0, guided):
        a, b = (noisy.noisy_frame(style, reference, f, noise=2.2, threads=2, noise_guides=g, guides=guides)
                for f in (1, 2))
        kept[g] = red_kept(a, reference)
        if g:
            assert np.abs(a - b).mean() > 0.01  # it still boils
            assert temporal.box_consistency_error(a, reference, 2.2) <= 0.05  # the large shapes stay R's
    assert kept[guided] >= 0.8 and kept[guided] > kept[0.0] + 0.3, kept


def test_guided_noise_is_the_same_for_any_thread_count():
    style, reference, guides = thin_strokes()
    one, two = (noisy.noisy_frame(style, reference, 3, noise=3.1, threads=t, noise_guides=0.5, guides=guides)
                for t in (1, 2))
    np.testing.assert_array_equal(one, two)


def test_guided_noise_names_missing_or_bad_guides():
    style, reference, guides = thin_strokes()
    with pytest.raises(ValueError, match="light-path guides"):
        noisy.noisy_frame(style, reference, 1, noise=2.2, noise_guides=0.5)
    with pytest.raises(ValueError, match="noise_guides"):
        noisy.noisy_frame(style, reference, 1, noise=2.2, noise_guides=-1, guides=guides)
    small = {"LDE": (guides["LDE"][0][:32], guides["LDE"][1], 1.0)}
    with pytest.raises(ValueError, match="exemplar guide 'LDE'"):
        noisy.noisy_frame(style, reference, 1, noise=2.2, noise_guides=0.5, guides=small)


def test_a_guided_sequence_reads_both_caches_and_keys_the_setting(tmp_path):
    import tempera
    from tempera.app import guide_cache

    style, reference, guides = thin_strokes()
    source, target, _ = guides["LDE"]
    (tmp_path / "R").mkdir()
    tempera.write_image(str(tmp_path / "medium.png"), style)
    guide_cache.write_frame(str(tmp_path / "exemplar_guides"), 1, {"LDE": source.repeat(3, 2)})
    for f in (1, 2):
        tempera.write_image(str(tmp_path / "R" / f"frame_{f:04d}.png"), reference)
        guide_cache.write_frame(str(tmp_path / "guides"), f, {"LDE": target.repeat(3, 2)})
    args = dict(exemplar=tmp_path / "medium.png", reference=tmp_path / "R", frames=[1, 2], out=tmp_path / "out",
                noise=2.2, threads=2, guides=tmp_path / "guides", exemplar_guides=tmp_path / "exemplar_guides",
                guide_weights={"LDE": 1.0}, noise_guides=0.5)
    assert [noisy.NoisySequence(**args).run_frame(i)["status"] for i in range(2)] == ["made", "made"]
    assert noisy.NoisySequence(**args).run_frame(0)["status"] == "skipped"
    assert noisy.NoisySequence(**dict(args, noise_guides=1.0)).run_frame(0)["status"] == "made"  # new setting
    assert noisy.NoisySequence(**dict(args, noise_guides=0.0)).run_frame(1)["status"] == "made"
    with pytest.raises(ValueError, match="exemplar's guide cache"):
        noisy.NoisySequence(**dict(args, exemplar_guides=None))


def test_guided_noise_off_ignores_the_guides_bit_for_bit():
    style, reference, guides = thin_strokes()
    plain = noisy.noisy_frame(style, reference, 2, noise=2.2, threads=2)
    np.testing.assert_array_equal(noisy.noisy_frame(style, reference, 2, noise=2.2, threads=2, guides=guides), plain)
