"""The render under an RGBA result (fluids, natural media): the guide
cache's FULL guide (Cycles' Combined pass, linear, film transparent) in
display sRGB, clipped as Blender's Standard view shows it, as PNG frames.

The guide cache holds no separate beauty render, and rendering one would
cost a second Cycles render per frame; the FULL guide is that render at the
guide samples (docs/user_guide.md). The background is black where the film
is transparent: the artist's own render can replace the strip."""
import os

import numpy as np

from . import guide_cache
from ..engine.color import linear_to_srgb


def render_path(folder, frame):
    return os.path.join(folder, f"frame_{frame:04d}.png")


def render_image(guides, frame):
    """Frame `frame`'s render from the guide cache `guides`, (H, W, 3) sRGB in [0, 1]."""
    full = guide_cache.read_frame(guides, frame, ["FULL"])["FULL"]
    return np.ascontiguousarray(linear_to_srgb(full))


def write_render_frames(guides, frames, folder):
    """The render PNG of every frame in `folder` (made when missing or older
    than its guide frame, written atomically); their paths, in order."""
    from .. import write_image

    os.makedirs(folder, exist_ok=True)
    paths = []
    for frame in frames:
        path = render_path(folder, frame)
        source = guide_cache.frame_path(guides, frame)
        if not os.path.exists(path) or os.path.getmtime(path) < os.path.getmtime(source):
            write_image(path, render_image(guides, frame), [])
        paths.append(path)
    return paths
