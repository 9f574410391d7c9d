"""The render strip under the fluid and natural-media results, and the mask
guides those methods have the guide render make."""
import os

import numpy as np
import pytest

import tempera
from tempera.app import beauty, guide_cache
from tempera.engine.color import linear_to_srgb
from synthetic_cache import light_paths, make_cache


def test_render_frames_are_the_full_guide_in_srgb_and_remade_when_stale(tmp_path):
    cache = make_cache(tmp_path / "guides", frames=(1, 2))
    out = tmp_path / "render"
    paths = beauty.write_render_frames(cache, [1, 2], out)
    assert paths == [str(out / "frame_0001.png"), str(out / "frame_0002.png")]
    got = tempera.read_image(paths[1])
    want = linear_to_srgb(light_paths(22.0)["FULL"])  # frame 2: the blob at 20 + 2
    assert got.shape == want.shape and np.abs(got - want).max() < 1.0 / 255
    assert got.std() > 0.05  # the image, not a flat colour
    # Current: left alone; older than its guide frame: remade.
    os.utime(paths[0], (1, 1))
    stamp = os.path.getmtime(paths[1])
    beauty.write_render_frames(cache, [1, 2], out)
    assert os.path.getmtime(paths[1]) == stamp and os.path.getmtime(paths[0]) > 1


@pytest.mark.parametrize("mode, kind, widened", [
    ("none", "OB", "objects"), ("collections", "OB", "objects+collections"), ("objects", "OB", "objects"),
    ("objects+collections", "CO", "objects+collections"), ("objects", "CO", "objects+collections"),
    ("none", "CO", "collections")])
def test_masks_widened_to_render_the_target(mode, kind, widened):
    assert guide_cache.masks_including(mode, kind) == widened
