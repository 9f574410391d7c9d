import numpy as np

from tempera.engine.color import linear_to_srgb, srgb_to_linear


def test_reference_values():
    linear = np.array([0.0, 0.0031308, 0.18, 0.5, 1.0], dtype=np.float32)
    expected = [0.0, 0.04045, 0.46135, 0.73536, 1.0]
    np.testing.assert_allclose(linear_to_srgb(linear), expected, atol=2e-5)


def test_out_of_range_and_nan_are_clipped():
    out = linear_to_srgb(np.array([-3.0, 7.0, np.nan, np.inf], dtype=np.float32))
    np.testing.assert_array_equal(out, [0.0, 1.0, 0.0, 1.0])
    assert out.dtype == np.float32


def test_round_trip():
    x = np.linspace(0, 1, 1001, dtype=np.float32)
    np.testing.assert_allclose(srgb_to_linear(linear_to_srgb(x)), x, atol=1e-5)
    assert np.all(np.diff(linear_to_srgb(x)) >= 0)  # monotonic
