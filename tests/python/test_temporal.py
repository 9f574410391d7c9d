import numpy as np

from tempera.engine import temporal


def vector_pass(h, w, dx):
    """Blender Vector pass of content moving right by dx pixels per frame:
    XY = p(f-1) - p(f) = (-dx, 0), ZW = p(f) - p(f+1) = (-dx, 0) (y up)."""
    v = np.zeros((h, w, 4), np.float32)
    v[..., 0] = v[..., 2] = -dx
    return v


def test_flicker_is_zero_for_paint_that_moves_with_the_surface():
    rng = np.random.default_rng(0)
    h, w, dx = 20, 30, 2
    previous = rng.random((h, w, 3), dtype=np.float32)
    current = np.roll(previous, dx, axis=1)  # the paint moved with the surface
    backward, visible = temporal.motion(vector_pass(h, w, dx), vector_pass(h, w, dx))
    assert np.allclose(backward[..., 0], dx)
    assert visible[:, dx:].all() and not visible[:, :1].any()  # entered from outside the frame
    assert temporal.flicker(previous, current, backward, visible) < 1e-6
    still = temporal.flicker(previous, previous, backward, visible)  # paint stuck to the screen
    assert still > 0.2
