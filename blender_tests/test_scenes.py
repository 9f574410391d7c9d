"""The scenes built in code (scenes/scene_kit.py, exemplar_kit.py, demo_scene.py)."""
import sys
from pathlib import Path

import bpy
import pytest

SCENES = Path(__file__).resolve().parent.parent / "scenes"
sys.path.insert(0, str(SCENES))
import demo_scene  # noqa: E402
import exemplar_kit  # noqa: E402
import scene_kit  # noqa: E402


@pytest.fixture
def exemplar_scene():
    scene = exemplar_kit.build_exemplar_scene("Test exemplar")
    yield scene
    scene_kit.clear_scene(scene)
    bpy.data.scenes.remove(scene)


@pytest.fixture
def demo():
    scene = bpy.data.scenes.new("Test demo")
    demo_scene.build_scene(scene)
    yield scene
    scene_kit.clear_scene(scene)
    bpy.data.scenes.remove(scene)


def objects(scene, kind):
    return [o for o in scene.collection.all_objects if o.type == kind]


def test_exemplar_is_a_sphere_on_a_table(exemplar_scene):
    names = sorted(o.name for o in objects(exemplar_scene, "MESH"))
    assert len(names) == 2 and names[0].startswith("Sphere") and names[1].startswith("Table")
    lights = objects(exemplar_scene, "LIGHT")
    assert len(lights) == 1 and lights[0].data.type == "AREA"
    assert exemplar_scene.camera is not None
    sphere = next(o for o in objects(exemplar_scene, "MESH") if o.name.startswith("Sphere"))
    assert sphere.location.z == pytest.approx(scene_kit.SPHERE_RADIUS)  # resting on the table


def test_exemplar_light_is_placed_like_the_demo_light(exemplar_scene, demo):
    """Same light, same direction as seen from the sphere (at rest in the exemplar,
    mid-roll in the demo), so the shading and shadows of both scenes agree."""
    def light_from_sphere(scene):
        light = objects(scene, "LIGHT")[0]
        sphere = next(o for o in objects(scene, "MESH") if o.name.startswith("Sphere"))
        return light, (light.location - sphere.location).normalized()

    demo.frame_set(demo_scene.FRAMES[len(demo_scene.FRAMES) // 2])
    ex_light, ex_dir = light_from_sphere(exemplar_scene)
    demo_light, demo_dir = light_from_sphere(demo)
    assert ex_dir.angle(demo_dir) < 0.25
    assert ex_light.data.energy == demo_light.data.energy
    assert ex_light.data.size == demo_light.data.size
    assert (ex_light.rotation_euler.to_quaternion().rotation_difference(
        demo_light.rotation_euler.to_quaternion()).angle) < 1e-4


def test_render_settings(exemplar_scene):
    scene_kit.configure_render(exemplar_scene, (40, 30), 2, exemplar_kit.EXEMPLAR_PASSES)
    cycles = exemplar_scene.cycles
    assert exemplar_scene.render.engine == "CYCLES"
    assert not cycles.use_denoising and cycles.sample_clamp_indirect == 0.0
    assert not exemplar_scene.render.use_motion_blur
    layer = exemplar_scene.view_layers[0]
    assert layer.use_pass_diffuse_direct and layer.use_pass_glossy_color and layer.use_pass_diffuse_indirect
    assert not layer.use_pass_vector
    with pytest.raises(ValueError, match="unknown render passes"):
        scene_kit.configure_render(exemplar_scene, (40, 30), 2, ("Combined", "Nope"))


def test_exemplar_renders_to_guides(exemplar_scene, tmp_path):
    from tempera.app.passes import read_pass
    from tempera.engine.guides import tonemap

    path = exemplar_kit.render_exemplar(exemplar_scene, tmp_path / "exemplar" / "guides.exr", (48, 36), 2)
    assert path == tmp_path / "exemplar" / "guides.exr" and path.is_file()
    assert [p.name for p in path.parent.iterdir()] == ["guides.exr"]  # no partial file left
    layer = scene_kit.view_layer_name(exemplar_scene)
    passes = {name: read_pass(path, name, layer) for name in ("Combined", "DiffDir", "DiffCol")}
    assert all(p.shape[:2] == (36, 48) for p in passes.values())
    full, lde = tonemap(passes["Combined"][:, :, :3]), tonemap(passes["DiffDir"] * passes["DiffCol"])
    assert full.mean() > 0.1 and lde.max() > 0.3  # lit, not black
    # The sphere (red albedo) is in the middle of the frame.
    assert passes["DiffCol"][18, 24, 0] > 2 * passes["DiffCol"][18, 24, 1]


def test_exemplar_variants():
    scene = exemplar_kit.build_exemplar_scene("Test variant", variant="sphere_and_box")
    try:
        names = sorted(o.name.split(".")[0] for o in objects(scene, "MESH"))
        assert names == ["Box", "Sphere", "Table"]
        box = next(o for o in objects(scene, "MESH") if o.name.startswith("Box"))
        assert box.location.z == pytest.approx(scene_kit.BOX_SIZE / 2)  # standing on the table
    finally:
        scene_kit.clear_scene(scene)
        bpy.data.scenes.remove(scene)
    with pytest.raises(ValueError, match="unknown exemplar variant 'nope'"):
        exemplar_kit.build_exemplar_scene("Test variant", variant="nope")


def test_exemplar_kit_outputs(tmp_path):
    import json

    import tempera

    kit = exemplar_kit.make_kit(tmp_path / "kit", "sphere_and_box", (48, 36), samples=2, dpi=40)
    folder = kit.parent
    assert sorted(p.name for p in folder.iterdir()) == ["guides", "guides.exr", "kit.json", "render.png", "style.png",
                                                       "template.pdf", "template.png"]
    info = json.loads(kit.read_text())
    assert info["variant"] == "sphere_and_box" and info["resolution"] == [48, 36] and len(info["marks"]) == 4
    assert tempera.image_info(str(folder / "guides.exr"))["width"] == 48
    assert tempera.read_image(str(folder / "render.png")).shape[:2] == (36, 48)
    page = tempera.read_image(str(folder / "template.png"))
    assert page.shape[:2] == (round(210 * 40 / 25.4), round(297 * 40 / 25.4))  # A4 landscape at 40 dpi
    x0, y0, x1, y1 = info["picture"]
    assert 0 < x0 < x1 < page.shape[1] and 0 < y0 < y1 < page.shape[0]
    assert (folder / "template.pdf").read_bytes().startswith(b"%PDF")
    # Ready to stylize with: the painting and the guide cache, at the kit's resolution.
    from tempera.app import exemplar_kit as bundled

    style, guides = bundled.kit_exemplar(folder.name, kit_dir=folder.parent)
    assert tempera.read_image(str(style)).shape[:2] == (36, 48)
    assert tempera.image_info(str(guides / "frame_0001.exr"))["width"] == 48
