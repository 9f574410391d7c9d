"""tempera.engine.guides: motion, orientation and line-distance building blocks."""
import numpy as np
import pytest

from conftest import assert_releases_gil
from tempera.engine import guides

H, W, STEP = 12, 24, 3


def square_velocity(frame):
    """V+ = V- of a 6x6 square moving right by 3 px per frame over a static
    background; at `frame` it covers x in [6 + 3 frame, 12 + 3 frame)."""
    v = np.zeros((H, W, 2), np.float32)
    v[3:9, 6 + STEP * frame:12 + STEP * frame, 0] = STEP
    return v


def stripes(angle, h=48, w=64, period=10.0):
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    across = -np.sin(angle) * xx + np.cos(angle) * yy
    return (0.5 + 0.5 * np.sin(2 * np.pi * across / period)).astype(np.float32)


def angle_error(a, b):
    d = np.abs(a - b) % np.pi
    return np.minimum(d, np.pi - d)


def test_backward_occlusion_marks_the_revealed_background():
    chi = guides.occlusion_backward(square_velocity(1), square_velocity(0))
    assert chi.shape == (H, W) and chi.dtype == np.float32
    expected = np.ones((H, W), np.float32)
    expected[3:9, 6:9] = 0  # covered by the square at t-1, visible at t
    np.testing.assert_array_equal(chi, expected)


def test_forward_occlusion_marks_the_background_about_to_be_covered():
    chi = guides.occlusion_forward(square_velocity(1), square_velocity(2))
    expected = np.ones((H, W), np.float32)
    expected[3:9, 15:18] = 0
    np.testing.assert_array_equal(chi, expected)


def test_epsilon_is_a_squared_tolerance():
    here, there = np.zeros((4, 4, 2)), np.full((4, 4, 2), 1.0)
    assert guides.occlusion_backward(here, there, epsilon=2.0).max() == 0
    assert guides.occlusion_backward(here, there, epsilon=2.5).min() == 1


def test_warp_backward_undoes_a_shift_and_keeps_the_shape():
    rng = np.random.default_rng(0)
    previous = rng.random((16, 20, 3), dtype=np.float32)
    v = np.zeros((16, 20, 2), np.float32)
    v[..., 0], v[..., 1] = 3, 2
    current = guides.warp_backward(previous, v)
    assert current.shape == previous.shape
    np.testing.assert_allclose(current[2:, 3:], previous[:-2, :-3], atol=1e-5)
    gray = guides.warp_backward(previous[..., 0], v)
    assert gray.shape == (16, 20)
    np.testing.assert_allclose(gray[2:, 3:], previous[:-2, :-3, 0], atol=1e-5)


def test_warp_backward_is_bilinear():
    yy, xx = np.mgrid[0:12, 0:16].astype(np.float32)
    ramp = 0.1 * xx + 0.05 * yy
    v = np.zeros((12, 16, 2), np.float32)
    v[..., 0], v[..., 1] = 2.5, -1.25
    expected = 0.1 * (xx - 2.5) + 0.05 * (yy + 1.25)
    np.testing.assert_allclose(guides.warp_backward(ramp, v)[:10, 3:], expected[:10, 3:], atol=1e-5)


@pytest.mark.parametrize("degrees", [0, 30, 90, 120])
def test_orientation_of_stripes(degrees):
    angle, coherence = guides.orientation(stripes(np.radians(degrees)))
    inner = np.s_[8:-8, 8:-8]
    assert angle.shape == coherence.shape == (48, 64)
    assert ((angle >= 0) & (angle < np.pi)).all()
    assert angle_error(angle[inner], np.radians(degrees)).max() < np.radians(3)
    assert coherence[inner].min() > 0.9


def test_orientation_accepts_rgb_and_tensors():
    gray = stripes(0.5)
    rgb = np.repeat(gray[..., None], 3, axis=2)
    tensor = guides.structure_tensor(gray, sigma=2.0)
    assert isinstance(tensor, guides.StructureTensor) and tensor.shape == (48, 64, 3)
    a, c = guides.orientation(gray)
    for other in (guides.orientation(rgb), guides.orientation(tensor),
                  guides.orientation(np.asarray(tensor), tensor=True),
                  guides.orientation((tensor + tensor) / 2)):  # averaging keeps the type
        np.testing.assert_allclose(other[0], a, atol=1e-5)
        np.testing.assert_allclose(other[1], c, atol=1e-5)


def test_flat_image_has_no_coherence():
    angle, coherence = guides.orientation(np.full((16, 16), 0.3))
    assert np.isfinite(angle).all()
    np.testing.assert_allclose(coherence, 0, atol=1e-6)


def brute_force_distance(mask):
    ys, xs = np.nonzero(mask > 0.5)
    yy, xx = np.mgrid[0:mask.shape[0], 0:mask.shape[1]]
    return np.sqrt((yy[..., None] - ys) ** 2 + (xx[..., None] - xs) ** 2).min(axis=-1)


@pytest.mark.parametrize("d_max", [3.0, 100.0])
def test_line_distance_matches_brute_force(d_max):
    mask = (np.random.default_rng(5).random((17, 23)) < 0.04).astype(np.float32)
    expected = np.minimum(brute_force_distance(mask), d_max) / d_max
    np.testing.assert_allclose(guides.line_distance(mask, d_max=d_max), expected, atol=1e-5)
    np.testing.assert_allclose(guides.line_distance(mask[..., None], d_max=d_max), expected, atol=1e-5)


def test_line_distance_of_a_single_pixel_and_of_no_line():
    mask = np.zeros((15, 20), np.float32)
    mask[7, 5] = 1
    yy, xx = np.mgrid[0:15, 0:20]
    np.testing.assert_allclose(guides.line_distance(mask, d_max=50) * 50, np.hypot(xx - 5, yy - 7), atol=1e-4)
    np.testing.assert_array_equal(guides.line_distance(np.zeros((6, 9))), np.ones((6, 9), np.float32))


V = np.zeros((8, 8, 2), np.float32)
NAN_V = V.copy()
NAN_V[2, 5, 1] = np.nan


@pytest.mark.parametrize("call, message", [
    (lambda: guides.occlusion_backward(V, np.zeros((8, 6, 2))), "v_minus_t is 8x8 but v_plus_prev is 6x8"),
    (lambda: guides.occlusion_forward(V, np.zeros((8, 8, 3))), r"v_minus_next must be an \(H, W, 2\)"),
    (lambda: guides.occlusion_backward(V[..., 0], V), r"v_minus_t must be an \(H, W, 2\)"),
    (lambda: guides.occlusion_backward(NAN_V, V), "v_minus_t contains a non-finite value .* at x=5 y=2"),
    (lambda: guides.occlusion_forward(V, V, epsilon=0), "epsilon must be a positive finite number"),
    (lambda: guides.occlusion_backward(V, V, epsilon=-1), "epsilon must be a positive finite number"),
    (lambda: guides.warp_backward(np.zeros((8, 9)), V), "previous is 9x8 but v_minus_t is 8x8"),
    (lambda: guides.warp_backward(np.zeros((8, 8)), NAN_V), "non-finite"),
    (lambda: guides.warp_backward(np.zeros((2, 8, 8, 1)), V), r"previous must be an \(H, W\) or \(H, W, C\)"),
    (lambda: guides.structure_tensor(np.zeros((8, 8)), sigma=-1), "sigma must be a finite number >= 0"),
    (lambda: guides.structure_tensor(np.array([["a"]])), "numeric array"),
    (lambda: guides.orientation(np.zeros((8, 8, 2)), tensor=True), r"structure tensor must be an \(H, W, 3\)"),
    (lambda: guides.line_distance(np.zeros((8, 8, 3))), r"line mask must be an \(H, W\) or \(H, W, 1\)"),
    (lambda: guides.line_distance(np.zeros((8, 8)), d_max=0), "d_max must be a positive finite number"),
    (lambda: guides.line_distance(np.zeros((0, 8))), "line mask is empty"),
])
def test_bad_inputs_raise_value_errors_naming_the_problem(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_native_layer_validates_too():
    # The C++ checks stand on their own (other callers skip the wrapper).
    from tempera import _native
    with pytest.raises(ValueError, match="occlusion epsilon must be a positive"):
        _native.occlusion_backward(V, V, 0.0)
    with pytest.raises(ValueError, match="v_plus_t must have 2 channels"):
        _native.occlusion_forward(np.zeros((8, 8, 3), np.float32), V)
    with pytest.raises(ValueError, match="d_max must be a positive"):
        _native.line_distance(np.zeros((8, 8), np.float32), -1.0)
    with pytest.raises(ValueError, match="structure tensor must have 3 channels"):
        _native.orientation_from_tensor(V)


def test_the_gil_is_released():
    big = np.random.default_rng(1).random((1500, 1500), dtype=np.float32)
    assert_releases_gil(lambda: guides.structure_tensor(big, sigma=8.0))
