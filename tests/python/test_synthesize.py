"""tempera.synthesize: the engine through its Python API."""
import numpy as np
import pytest

import tempera
from conftest import assert_releases_gil


def coordinate_guide(h, w):
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    return np.stack([xx / w, yy / h], -1)


def noise(h, w, c=3, seed=0):
    return np.random.default_rng(seed).random((h, w, c), dtype=np.float32)


def test_identical_guides_reproduce_the_exemplar():
    style = noise(40, 48)
    guide = coordinate_guide(40, 48)
    image, stats = tempera.synthesize(style, [(guide, guide, 4.0)], usage="none", seed=3)
    assert image.shape == style.shape and image.dtype == np.float32
    # A band of about one patch at the border is only approximated (patch
    # centers keep a radius from the exemplar border).
    assert np.abs(image - style)[6:-6, 6:-6].mean() < 1e-3


def test_stats_report_energy_timings_coverage_and_nnf():
    style = noise(32, 32)
    image, stats = tempera.synthesize(style, [(coordinate_guide(32, 32), coordinate_guide(24, 40))],
                                      em_iterations=3, usage="uniform")
    assert image.shape == (24, 40, 3)
    assert len(stats["levels"]) >= 1
    for level in stats["levels"]:
        assert len(level["energy"]) == 3
        assert level["search_seconds"] >= 0 and level["vote_seconds"] >= 0
    assert stats["levels"][-1]["width"] == 40 and stats["levels"][-1]["height"] == 24
    assert stats["nnf"].shape == (24, 40, 2)
    assert stats["source_coverage"] == pytest.approx(1.0)  # uniform uses every patch
    assert stats["usage"] == "uniform"


def test_equal_seeds_equal_output_and_seed_matters():
    style, g = noise(32, 32, seed=1), coordinate_guide(32, 32)
    a, _ = tempera.synthesize(style, [(g, g[::-1].copy())], seed=5)
    b, _ = tempera.synthesize(style, [(g, g[::-1].copy())], seed=5, threads=1)
    c, _ = tempera.synthesize(style, [(g, g[::-1].copy())], seed=6)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_guides_accept_dicts_and_grayscale():
    style = noise(32, 32)
    gray = coordinate_guide(32, 32)[..., 0]
    image, _ = tempera.synthesize(style, [{"name": "x", "source": gray, "target": gray, "weight": 2}],
                                  usage="none")
    assert image.shape == (32, 32, 3)


@pytest.mark.parametrize("kwargs, message", [
    (dict(usage="sometimes"), "unknown patch usage 'sometimes'"),
    (dict(patch_size=4), "patch size must be odd"),
    (dict(guide_variance=0.0), "guide variance"),
    (dict(target_mask=np.zeros((32, 32), np.float32)), "target mask is empty"),
    (dict(source_mask=np.zeros((32, 32), np.float32)), "source mask is empty"),
    (dict(target_mask=np.ones((10, 10), np.float32)), "target mask is 10x10"),
])
def test_bad_options_raise_value_errors_naming_the_problem(kwargs, message):
    g = coordinate_guide(32, 32)
    with pytest.raises(ValueError, match=message):
        tempera.synthesize(noise(32, 32), [(g, g)], **kwargs)


def test_mismatched_guide_size_names_the_guide():
    with pytest.raises(ValueError, match="guide 'lde' source is 20x32"):
        tempera.synthesize(noise(32, 32), [
            {"name": "full", "source": coordinate_guide(32, 32), "target": coordinate_guide(32, 32)},
            {"name": "lde", "source": coordinate_guide(32, 20), "target": coordinate_guide(32, 32)},
        ])


def test_nan_in_a_target_guide_is_reported_with_its_position():
    g = coordinate_guide(32, 32)
    bad = g.copy()
    bad[7, 9, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite value .* at x=9 y=7"):
        tempera.synthesize(noise(32, 32), [(g, bad)])


def test_bad_array_shape():
    with pytest.raises(ValueError, match=r"\(H, W\) or \(H, W, C\)"):
        tempera.synthesize(np.zeros((2, 8, 8, 3), np.float32), target_shape=(8, 8))
    with pytest.raises(ValueError, match="at least one guide pair or target_shape"):
        tempera.synthesize(noise(8, 8))


def test_progress_is_monotone_and_false_cancels():
    g = coordinate_guide(32, 32)
    seen = []
    tempera.synthesize(noise(32, 32), [(g, g)], progress=seen.append)
    assert seen and seen == sorted(seen) and 0 < seen[0] and seen[-1] == pytest.approx(1.0)
    calls = []

    def stop_after_two(fraction):
        calls.append(fraction)
        return len(calls) < 2

    with pytest.raises(tempera.Cancelled):
        tempera.synthesize(noise(32, 32), [(g, g)], progress=stop_after_two)
    assert len(calls) == 2


def test_the_gil_is_released_while_solving():
    style, g = noise(128, 128), coordinate_guide(128, 128)
    assert_releases_gil(lambda: tempera.synthesize(style, [(g, g[::-1].copy())], threads=1))


def test_knee_of_a_step_curve():
    errors = [0.01] * 300 + [1.0 + 0.001 * i for i in range(700)]
    assert 280 <= tempera._native.error_knee(errors) <= 310


def test_rotation_aware_patches_turn_stripes():
    yy = np.mgrid[0:48, 0:48][0].astype(np.float32)
    stripes = (0.5 + 0.5 * np.sin(2 * np.pi * yy / 8))[..., None]  # horizontal stripes
    out, _ = tempera.synthesize(stripes, target_shape=(40, 40), usage="none",
                                source_orientation=np.zeros((48, 48), np.float32),
                                target_orientation=np.full((40, 40), np.pi / 2, np.float32))
    core = out[4:-4, 4:-4, 0]
    along_x = np.abs(np.diff(core, axis=1)).mean()
    along_y = np.abs(np.diff(core, axis=0)).mean()
    assert along_x > 4 * along_y  # vertical stripes now


def test_unknown_map_or_option_is_rejected():
    g = coordinate_guide(16, 16)
    with pytest.raises(TypeError):
        tempera.synthesize(noise(16, 16), [(g, g)], sharpness=3)
    with pytest.raises(ValueError, match="unknown synthesis option 'sharpness'"):
        tempera._native.synthesize(noise(16, 16), [("g", g, g, 1.0, None)], {"sharpness": 3}, {}, None, None)


def test_occurrence_penalty_breaks_up_hotspots():
    """Plain matching reuses a few exemplar patches many times on a flat guide;
    the occurrence penalty (Kaspar et al. 2015) spreads the usage."""
    yy, xx = np.mgrid[0:48, 0:48]
    rng = np.random.default_rng(2)
    style = (0.5 + 0.4 * np.sin(xx / 3.0)[..., None] + 0.05 * rng.random((48, 48, 3))).astype(np.float32)
    flat_source, flat_target = np.zeros((48, 48), np.float32), np.zeros((64, 64), np.float32)

    def max_uses(**kwargs):
        # Float features: on a flat guide every match is a near-tie, and the
        # hotspots of one seed move with the rounding of fixed-point features
        # (over seeds 1-8 the penalty spreads the usage just as well in int16).
        _, stats = tempera.synthesize(style, [(flat_source, flat_target)], seed=3, feature_precision="float", **kwargs)
        nnf = stats["nnf"]
        return np.bincount((nnf[..., 1] * 48 + nnf[..., 0]).ravel()).max()

    assert max_uses(usage="penalty", penalty_weight=0.5) < 0.5 * max_uses(usage="none")
