"""Temporal behaviour of a stylized sequence from rendered motion, without
Blender: per-frame motion and visibility (Bénard et al. 2013's χ−) from
Blender's Vector passes, and the flicker figure of two stylized frames.

The temporal guide itself (the previous stylized frame advected along the
motion, weighted by χ−) is part of StyLit per frame: tempera.stylize
(native/src/stylit.cpp); flicker() here is the same native figure.
"""
import numpy as np

from . import _native, guides
from .guide_cache import velocities_from_vector_pass


def motion(vector_pass, previous_vector_pass, epsilon=2.0):
    """(velocity_backward, χ−) of a frame from its Vector pass and the previous
    frame's (Blender's layout, see guide_cache.velocities_from_vector_pass)."""
    backward, _ = velocities_from_vector_pass(vector_pass)
    _, previous_forward = velocities_from_vector_pass(previous_vector_pass)
    return backward, guides.occlusion_backward(backward, previous_forward, epsilon)


def flicker(previous_stylized, stylized, velocity_backward, visible):
    """Mean absolute colour change along valid motion between two stylized
    frames (0 = the paint moves perfectly with the surface)."""
    def image(a):
        a = np.ascontiguousarray(a, dtype=np.float32)
        return a[:, :, None] if a.ndim == 2 else a

    visible = np.asarray(visible)
    return _native.flicker(image(previous_stylized), image(stylized), image(velocity_backward),
                           image((visible != 0).astype(np.float32)))
