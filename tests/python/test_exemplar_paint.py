"""tempera.methods.stylit.exemplar_paint: the procedural hatched exemplar."""
import numpy as np
import pytest

from tempera.methods.stylit.exemplar_paint import PAPER, darkness_map, paint_hatching

LUMA = np.array([0.2126, 0.7152, 0.0722])


def ink(image):
    """Per-pixel ink coverage: how much darker than the paper a pixel is
    (beyond the paper's own grain and mottle, which stay within 6 %)."""
    return np.clip(1.0 - (image @ LUMA) / (np.array(PAPER) @ LUMA) - 0.06, 0.0, 1.0) / 0.94


def sphere_render(h=60, w=80):
    """A lit-sphere-like linear render: bright top left, dark bottom right."""
    y, x = np.mgrid[0:h, 0:w]
    shade = np.clip(1.0 - (x / w + y / h) / 2.0, 0.0, 1.0) ** 2
    return np.repeat(shade[:, :, None], 3, axis=2).astype(np.float32)


def test_shape_dtype_range():
    image = paint_hatching(sphere_render(), seed=3)
    assert image.shape == (60, 80, 3)
    assert image.dtype == np.float32
    assert image.min() >= 0.0 and image.max() <= 1.0
    gray = paint_hatching(sphere_render()[:, :, 0], seed=3)  # (H, W) works too
    assert gray.shape == (60, 80, 3)


def test_deterministic_for_a_seed():
    render = sphere_render()
    a = paint_hatching(render, seed=11)
    b = paint_hatching(render.copy(), seed=11)
    np.testing.assert_array_equal(a, b)
    c = paint_hatching(render, seed=12)
    assert np.abs(a - c).mean() > 0.005


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_darker_input_gets_more_ink(seed):
    coverages = [ink(paint_hatching(np.full((64, 64, 3), value, np.float32), seed=seed)).mean()
                 for value in (3.0, 0.8, 0.4, 0.15, 0.03)]
    assert all(a < b for a, b in zip(coverages, coverages[1:])), coverages
    assert coverages[0] < 0.01  # a highlight: bare paper
    assert coverages[-1] > 0.3  # deep shadow: densely hatched


def test_density_follows_the_shading_within_one_image():
    render = sphere_render(90, 120)
    coverage = ink(paint_hatching(render, seed=5))
    lit, shadow = coverage[:30, :40].mean(), coverage[-30:, -40:].mean()
    assert shadow > 3 * lit


def test_albedo_gives_shading_and_colour():
    h, w = 48, 64
    albedo = np.zeros((h, w, 3), np.float32)
    albedo[:, : w // 2] = (0.8, 0.1, 0.1)  # red material, left half
    albedo[:, w // 2:] = (0.1, 0.1, 0.8)  # blue material, right half
    light = np.full((h, w, 1), 0.15, np.float32)  # dim light everywhere
    image = paint_hatching(albedo * light, albedo, seed=4)
    left, right = image[8:-8, 4: w // 2 - 8], image[8:-8, w // 2 + 8: -4]
    # Same shading on both halves, so similar ink; the pencils take the material's hue.
    assert abs(ink(left).mean() - ink(right).mean()) < 0.15
    assert left[:, :, 0].mean() > left[:, :, 2].mean() + 0.05
    assert right[:, :, 2].mean() > right[:, :, 0].mean() + 0.05


def test_background_and_highlights_stay_paper():
    h, w = 60, 80
    albedo = np.zeros((h, w, 3), np.float32)
    albedo[20:, :] = 0.5  # a table in the lower two thirds, background above
    render = albedo * 0.1  # in shadow
    render[40:, 50:] = 5.0  # a blinding highlight
    coverage = ink(paint_hatching(render, albedo, seed=6))
    assert coverage[:18].max() == 0.0  # no ink on the background, bar a pixel's fringe (the edge is row 20)
    assert coverage[46:, 56:].mean() < 0.05  # inside the highlight
    assert coverage[26:36, 5:45].mean() > 0.3  # the shadowed table


def test_marks_are_strokes_not_speckle():
    """Ink is laid in strokes several pixels long: along the best direction
    the ink map stays correlated 5 px away, which per-pixel noise does not."""
    image = paint_hatching(np.full((96, 96, 3), 0.5, np.float32), seed=8)
    c = ink(image)
    c = c - c.mean()

    def correlation(dy, dx):
        a = c[max(dy, 0): 96 + min(dy, 0), max(dx, 0): 96 + min(dx, 0)]
        b = c[max(-dy, 0): 96 + min(-dy, 0), max(-dx, 0): 96 + min(-dx, 0)]
        return float((a * b).mean() / np.sqrt((a * a).mean() * (b * b).mean()))

    lags = [(round(5 * np.sin(t)), round(5 * np.cos(t))) for t in np.linspace(0, np.pi, 16, endpoint=False)]
    correlations = [correlation(dy, dx) for dy, dx in lags]
    assert max(correlations) > 0.25, correlations
    assert max(correlations) > min(correlations) + 0.1  # anisotropic: hatching has a direction


def test_darkness_map():
    blocks = np.repeat(np.array([2.0, 1.2, 0.3, 0.0], np.float32), 6)  # 4 blocks of 6 px
    render = np.repeat(np.tile(blocks, (6, 1))[:, :, None], 3, axis=2)
    dark = darkness_map(render, white=1.2, gamma=1.0)
    assert dark.shape == (6, 24)
    centres = dark[3, 3::6]
    assert centres[0] == 0.0 and centres[1] == 0.0
    assert 0.0 < centres[2] < centres[3] <= 1.0
    np.testing.assert_allclose(centres[2], 0.75, atol=1e-6)
    mask = np.ones((6, 24), np.float32)
    mask[:, 12:18] = 0.0
    assert darkness_map(render, mask=mask)[3, 15] == 0.0


def test_bad_input():
    with pytest.raises(ValueError):
        paint_hatching(np.zeros((4,), np.float32))
    with pytest.raises(ValueError, match="albedo"):
        paint_hatching(np.zeros((4, 4, 3)), np.zeros((5, 4, 3)))
    with pytest.raises(ValueError, match="mask"):
        paint_hatching(np.zeros((4, 4, 3)), mask=np.ones((3, 3)))
    with pytest.raises(ValueError, match="stroke_length"):
        paint_hatching(np.zeros((4, 4, 3)), stroke_length=(5, 2))
