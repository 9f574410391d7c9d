"""The growing-ink shot (scenes/growing_ink.py): the blot grows steadily and
its guide cache carries the target Fluidymation needs, an object mask and a
Vector-pass flow that follows the outline outwards."""
import math
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

SCENES = Path(__file__).resolve().parent.parent / "scenes"
sys.path.insert(0, str(SCENES))
import growing_ink  # noqa: E402
import scene_kit  # noqa: E402


@pytest.fixture
def ink_scene():
    scene = bpy.data.scenes.new("Test growing ink")
    _, ink = growing_ink.build(scene)
    yield scene, ink
    scene_kit.clear_scene(scene)
    bpy.data.scenes.remove(scene)


def _outline_radius(scene, ink, frame):
    """Mean distance of the blot's outline from its centre, in pixels."""
    from tempera.blender.scene_export import evaluated_depsgraph

    evaluated = ink.evaluated_get(evaluated_depsgraph(scene, scene.view_layers[0], frame))
    mesh = evaluated.to_mesh()
    try:
        points = [evaluated.matrix_world @ v.co for v in mesh.vertices]
        count = len(mesh.vertices)
    finally:
        evaluated.to_mesh_clear()
    centre = points[0]
    units = sum((p - centre).length for p in points[1:]) / (count - 1)
    return units * scene.render.resolution_x / scene.camera.data.ortho_scale, count


def test_blot_grows_steadily_with_one_topology(ink_scene):
    scene, ink = ink_scene
    radii, counts = zip(*(_outline_radius(scene, ink, f) for f in growing_ink.SHOT))
    assert len(set(counts)) == 1, "the blot keeps its vertices, so the Vector pass can follow it"
    steps = np.diff(radii)
    assert steps.min() > 0 and steps.max() < 1.2 * steps.min(), steps
    assert 1.0 < steps.mean() < 4.0  # px per frame: a blot that visibly spreads over the shot


def test_guides_have_the_mask_and_an_outward_flow(ink_scene, tmp_path):
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene, ink = ink_scene
    frame = growing_ink.SHOT[len(growing_ink.SHOT) // 2]
    render_guides(scene, [frame], tmp_path, {"samples": 2, "ld12e_samples": 1, "masks": "objects"})
    g = guide_cache.read_frame(tmp_path, frame, ["mask.OB_Ink", "velocity_forward"])
    mask = g["mask.OB_Ink"].reshape(g["mask.OB_Ink"].shape[:2]) > 0.5
    ys, xs = np.nonzero(mask)
    r = np.hypot(xs - xs.mean(), ys - ys.mean())
    v = g["velocity_forward"][ys, xs]
    radial = ((xs - xs.mean()) * v[:, 0] + (ys - ys.mean()) * v[:, 1]) / np.maximum(r, 1e-6)
    edge = r > 0.8 * r.max()
    growth = _outline_radius(scene, ink, frame + 1)[0] - _outline_radius(scene, ink, frame)[0]
    assert math.isclose(radial[edge].mean(), growth, rel_tol=0.2), (radial[edge].mean(), growth)
    yy, xx = np.mgrid[0:mask.shape[0], 0:mask.shape[1]]
    paper = np.hypot(xx - xs.mean(), yy - ys.mean()) > r.max() + 3  # clear of the blot's antialiased edge
    assert np.abs(g["velocity_forward"][paper]).max() < 0.05, "the paper does not move"
