"""Both fluid methods on a liquid scene made by someone else: Blender's own
Quick Liquid (Object > Quick Effects), as shipped, on the factory cube, the
liquid falling from where the cube was.

What a user must change, and nothing else (as for Quick Smoke,
test_quick_smoke.py):
- the scene, camera, light and render as there (160 x 120, film transparent);
- the cube (now the liquid's flow): hidden from the render. Quick Liquid's
  "Render Liquid Objects" off only shows it as wire, and a user wants the
  liquid seen, not the cube it starts as;
- the domain: Mesh on (Quick Liquid bakes particles only; the mesh is what
  renders, its Glass material as Quick Liquid made it), and its cache in a
  temporary folder, type All (baked here, frames 1..BAKE_END). Resolution
  (32), the collision borders and the material are Quick Liquid's.
"""
import bpy
import numpy as np
import pytest
from test_quick_smoke import (INK, SIZE, _frames, _guides, _iou, _panel_settings, _run_cli, baked_and_stylized,
                              film_the_domain, warp_error)

SCENE = "Quick Liquid test"
FRAMES = [8, 9, 10]  # 1/3 s in: the block of water falling (it lands near frame 19)
BAKE_END = FRAMES[-1]


def _quick_liquid_scene(cache_dir):
    scene = bpy.data.scenes.new(SCENE)
    bpy.context.window.scene = scene
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 0.0))
    cube = bpy.context.active_object
    assert bpy.ops.object.quick_liquid() == {"FINISHED"}
    domain = bpy.context.active_object  # "Liquid Domain", made last
    assert domain.name.startswith("Liquid Domain")
    assert cube.modifiers["Fluid"].flow_settings.flow_behavior == "GEOMETRY"  # as Quick Liquid made it
    cube.hide_render = True
    settings = domain.modifiers["Fluid"].domain_settings
    settings.use_mesh = True
    film_the_domain(scene, domain, cache_dir, BAKE_END)
    return scene, domain


@pytest.fixture(scope="module")
def liquid(tmp_path_factory):
    """The baked Quick Liquid scene and the LazyFluids panel run on it."""
    yield from baked_and_stylized(tmp_path_factory, _quick_liquid_scene, FRAMES)


def test_falling_liquid_moves_down_the_screen(liquid):
    """fluid_velocity from the liquid mesh: downward (image y down) on most
    of the liquid, and faster at the later frame (gravity)."""
    speeds = []
    for frame in FRAMES:
        g = _guides(liquid["tmp"], frame)
        seen = g["alpha"] > 0.5
        assert seen.sum() > 200, frame
        flow = g["fluid_velocity"][seen]
        assert (flow[:, 1] > 0.2).mean() > 0.9, frame
        assert np.median(flow[:, 1]) > 2 * np.abs(np.median(flow[:, 0])), frame  # down, not sideways
        speeds.append(float(np.median(flow[:, 1])))
    print("median downward speed, px/frame:", ", ".join(f"{v:.2f}" for v in speeds))
    assert speeds[-1] > speeds[0]


def test_lazyfluids_from_the_panel_and_the_cli_follow_the_liquid(liquid):
    tmp = liquid["tmp"]
    panel = _frames(tmp / "out" / "lazyfluids" / "frames", FRAMES)
    cli = _run_cli(tmp / "guides", liquid["still"], tmp / "cli", frames=FRAMES)
    independent = _run_cli(tmp / "guides", liquid["still"], tmp / "cli0", "--lambda", "0", frames=FRAMES)
    for frame, a, b in zip(FRAMES, panel, cli):
        alpha = _guides(tmp, frame)["alpha"]
        for img in (a, b):
            assert img.shape == (SIZE[1], SIZE[0], 4)
            assert _iou(img[..., 3] > 0.5, alpha > 0.5) >= 0.9, frame
            assert img[..., :3][img[..., 3] > 0.5].std() > 0.02, frame  # textured, not flat
    errors = warp_error(panel, tmp, FRAMES), warp_error(independent, tmp, FRAMES)
    print(f"warp error: lambda 0.2 {errors[0]:.4f}, lambda 0 {errors[1]:.4f}")
    assert errors[0] < errors[1]
    assert SCENE + " Tempera Composite" in bpy.data.scenes


def test_natural_media_on_the_liquid_takes_its_fluid_velocity(liquid, tmp_path):
    import tempera
    from tempera.app import media_exemplars
    from tempera.blender.stylize_operator import StylizeRun

    ink = tmp_path / "ink"
    ink.mkdir()
    for i, (rgb, mask) in enumerate(zip(*media_exemplars.ink_video(INK[0], INK[0], INK[1], 1.0, seed=5))):
        tempera.write_image(str(ink / f"ink_{i + 1:04d}.png"), np.dstack([rgb, mask]), [])
    scene = liquid["scene"]
    s = _panel_settings(scene, liquid["tmp"], "FLUIDYMATION", FRAMES)  # the same guide cache
    s.media_exemplar_kind, s.media_exemplar = "SEQUENCE", str(ink / "ink_0001.png")
    s.fm_target_object = s.fm_target_collection = None  # target mask = alpha
    run = StylizeRun.from_settings(scene, "ANIMATION")
    while not run.finished:
        run.step()
    assert run.job.summary == "flow from fluid_velocity"
    assert [r["status"] for r in run.results] == ["stylized"] * len(FRAMES)
    for frame, img in zip(FRAMES, _frames(liquid["tmp"] / "out" / "fluidymation" / "frames", FRAMES)):
        alpha = _guides(liquid["tmp"], frame)["alpha"]
        assert _iou(img[..., 3] > 0.5, alpha > 0.5) >= 0.9, frame
        assert img[..., :3][img[..., 3] > 0.5].std() > 0.02, frame
