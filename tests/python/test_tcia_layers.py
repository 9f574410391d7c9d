"""tempera.methods.tcia.tcia.stylize_layers and composite (Bénard 2013 layers, native/src/methods/tcia/tcia_layers.cpp)."""
import numpy as np
import pytest

from tempera.methods.tcia import tcia

W, H, N, SIDE, SPEED = 40, 28, 4, 10, 2


def square_shot():
    """A square moving right over a static background: uv guides of each surface, masks."""
    rng = np.random.default_rng(2)
    style = rng.random((48, 64, 3), dtype=np.float32)
    yy, xx = np.mgrid[0:48, 0:64].astype(np.float32)
    uv = np.stack([xx / 64, yy / 48], -1)
    frames, masks = [], []
    y, x = np.mgrid[0:H, 0:W].astype(np.float32)
    for t in range(N):
        left = 6 + SPEED * t
        inside = (x >= left) & (x < left + SIDE) & (y >= 9) & (y < 9 + SIDE)
        g = np.where(inside[..., None], np.stack([(44 + x - left) / 64, (30 + y - 9) / 48], -1),
                     np.stack([(x + 2) / 64, (y + 2) / 48], -1)).astype(np.float32)
        v = np.zeros((H, W, 2), np.float32)
        v[inside, 0] = SPEED
        frames.append(dict(guides=[g], velocity_backward=v, velocity_forward=v,
                           occlusion_backward=np.ones((H, W), np.float32) * (t > 0),
                           occlusion_forward=np.ones((H, W), np.float32) * (t < N - 1)))
        masks.append(inside.astype(np.float32))
    return style, [("uv", uv, 4.0)], frames, masks


def test_layers_and_their_composite():
    style, guides, frames, masks = square_shot()
    square, rest = tcia.stylize_layers(style, guides, frames, [(masks, None), ([1 - m for m in masks], None)],
                                       levels=2, patch_size=7, threads=2)
    assert len(square) == len(rest) == N and square[0].shape == (H, W, 3)
    for t in range(N):
        inside = masks[t] > 0.5
        out = tcia.composite([rest[t], square[t]], [1 - masks[t], masks[t]])
        np.testing.assert_array_equal(out[inside], square[t][inside])
        np.testing.assert_array_equal(out[~inside], rest[t][~inside])
        depth = np.where(inside, 1.0, 5.0).astype(np.float32)  # the square nearer: on top in either order
        np.testing.assert_array_equal(tcia.composite([square[t], rest[t]], [masks[t], 1 - masks[t]], depth), out)
    # The square's layer carries the paint just right of its outline along with it (Fig. 10);
    # not extended, that band shows the static background instead.
    plain = tcia.stylize_layers(style, guides, frames, [(masks, None)], extrapolate=False, levels=2, patch_size=7,
                                threads=2)[0]
    def band_change(frames_):
        return np.mean([np.abs(frames_[t][9:9 + SIDE, 6 + SPEED * t + SIDE:6 + SPEED * t + SIDE + 3] -
                               frames_[t - 1][9:9 + SIDE, 6 + SPEED * (t - 1) + SIDE:6 + SPEED * (t - 1) + SIDE + 3]
                               ).mean() for t in range(1, N)])
    assert band_change(square) < 0.5 * band_change(plain)


def test_a_layer_copies_only_from_its_part_of_the_exemplar():
    style, guides, frames, masks = square_shot()
    left = np.zeros(style.shape[:2], np.float32)
    left[:, :32] = 1  # the square's guides point to the exemplar's right part
    allowed = {tuple(c) for c in style[:, :32].reshape(-1, 3)}
    for part, inside in ((None, False), (left, True)):
        out = tcia.stylize_layers(style, guides, frames, [(masks, None, part)], levels=2, patch_size=7, threads=2)[0]
        assert all(tuple(c) in allowed for c in out[-1].reshape(-1, 3)) == inside


def test_bad_layers_name_the_problem():
    style, guides, frames, masks = square_shot()
    with pytest.raises(ValueError, match="layer 'layer 0' has 2 mask"):
        tcia.stylize_layers(style, guides, frames, [(masks[:2], None)])
    with pytest.raises(ValueError, match="the painting of layer 'layer 0' is 4x4x3"):
        tcia.stylize_layers(style, guides, frames, [(masks, np.zeros((4, 4, 3), np.float32))])
