"""Light path expression guides: the scene exporter (tempera.blender.scene_export)
and Tempera's path tracer against Cycles on small scenes (scenes/lpe_scene.py).

Tolerances: the tracer's and Cycles' images are compared over lit pixels
(Cycles' luminance above 2 % of its 99th percentile, alpha > 0.5) at the same
sample count by
* the relative error of the mean, |mean(tracer) - mean(Cycles)| / mean(Cycles),
  per channel: at most MEAN_TOLERANCE = 5 % (the renderers must agree on
  the amount of light), and
* the mean absolute difference of 4 x 4 pixel block averages relative to the
  mean: at most BLOCK_TOLERANCE = 15 % (light in the right place; what is
  left is mostly the noise of both renderers at these sample counts).
"""
import math
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest
from mathutils import Vector
from tempera.blender import compat

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scenes"))
import lpe_scene  # noqa: E402

SIZE = (96, 72)
SAMPLES = 64  # Cycles and tracer alike
MEAN_TOLERANCE = 0.05
BLOCK_TOLERANCE = 0.15
COMPARED = {"LDE": "LDE", "LSE": "LSE", "LDDE": "L.*DDE"}  # Cycles guide -> tracer expression
NOTHING = "L[^LDST]E"  # a well-formed expression no path can match


def compare(traced, reference, alpha):
    """(relative error of the mean (worst channel), relative block error) over lit pixels."""
    luminance = reference @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    lit = (luminance > 0.02 * np.percentile(luminance, 99)) & (alpha > 0.5)
    assert lit.sum() > 500, "too few lit pixels to compare"
    mean_error = np.max(np.abs(traced[lit].mean(0) - reference[lit].mean(0)) / reference[lit].mean(0))

    def blocks(a):
        h, w = (a.shape[0] // 4) * 4, (a.shape[1] // 4) * 4
        return a[:h, :w].reshape(h // 4, 4, w // 4, 4, -1).mean(axis=(1, 3))

    fully_lit = blocks(lit[:, :, None].astype(np.float32))[:, :, 0] == 1
    block_error = np.abs(blocks(traced) - blocks(reference))[fully_lit].mean() / blocks(reference)[fully_lit].mean()
    return float(mean_error), float(block_error)


def render(scene, cache, expressions, samples=SAMPLES):
    """Cycles guides and the tracer's guides of frame 1, through render_guides."""
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    report = render_guides(scene, [1], cache, {"samples": samples, "ld12e_samples": 1, "masks": "none",
                                               "lpe": expressions, "lpe_samples": samples})
    assert report["rendered"] == [1]
    return guide_cache.read_frame(cache, 1), report


def trace(scene, expressions, samples=SAMPLES):
    """The tracer's images and alpha of the scene at its current frame."""
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene
    from tempera.tracer.lpe import trace_lpe

    depsgraph = evaluated_depsgraph(scene, scene.view_layers[0], scene.frame_current)
    scene_dict, warnings = export_scene(scene, depsgraph, SIZE)
    images, alpha = trace_lpe(scene_dict, expressions, samples=samples, max_bounces=scene.cycles.max_bounces)
    return images, alpha, warnings


@pytest.fixture(scope="module")
def metal(tmp_path_factory):
    """Principled floor, wall, cube and a rough gold sphere under a point light."""
    scene = lpe_scene.build_scene("LPE metal", SIZE)
    expressions = ["L.*E", "LDE", "LSE", "L.*DDE", NOTHING]
    guides, report = render(scene, tmp_path_factory.mktemp("lpe") / "metal", expressions)
    yield {"scene": scene, "guides": guides, "report": report, "cache": report["manifest"].parent,
           "expressions": expressions}
    lpe_scene.remove_scene(scene)


@pytest.fixture(scope="module")
def diffuse(tmp_path_factory):
    """The same scene with Diffuse BSDFs only: Cycles' DiffInd with caustics off is then all of L.*DDE."""
    scene = lpe_scene.build_scene("LPE diffuse", SIZE, sphere="diffuse", diffuse_only=True)
    guides, _ = render(scene, tmp_path_factory.mktemp("lpe") / "diffuse", ["LDE", "L.*DDE"])
    yield guides
    lpe_scene.remove_scene(scene)


def traced(guides, expression):
    from tempera.app import guide_cache

    return guides[guide_cache.lpe_guide(expression)]


# --------------------------------------------------------------------------- tracer against Cycles

@pytest.mark.parametrize("guide", ["LDE", "LSE"])
def test_direct_light_matches_cycles(metal, guide):
    guides = metal["guides"]
    mean_error, block_error = compare(traced(guides, COMPARED[guide]), guides[guide], guides["alpha"])
    print(f"{guide}: mean error {mean_error:.4f}, block error {block_error:.4f}")
    assert mean_error <= MEAN_TOLERANCE and block_error <= BLOCK_TOLERANCE


@pytest.mark.parametrize("guide", ["LDE", "LDDE"])
def test_diffuse_scene_matches_cycles(diffuse, guide):
    mean_error, block_error = compare(traced(diffuse, COMPARED[guide]), diffuse[guide], diffuse["alpha"])
    print(f"{guide} (diffuse scene): mean error {mean_error:.4f}, block error {block_error:.4f}")
    assert mean_error <= MEAN_TOLERANCE and block_error <= BLOCK_TOLERANCE


def test_expression_matching_nothing_is_black(metal):
    assert traced(metal["guides"], NOTHING).max() == 0
    assert traced(metal["guides"], "L.*E").max() > 0.1


def test_alpha_matches_cycles(metal):
    _, alpha, _ = trace(metal["scene"], ["LDE"], samples=16)
    cycles = metal["guides"]["alpha"] > 0.5
    ours = alpha > 0.5
    iou = (cycles & ours).sum() / (cycles | ours).sum()
    print(f"alpha IoU {iou:.4f}")
    assert 0.1 < cycles.mean() < 0.9  # background and geometry both in view
    assert iou >= 0.99


@pytest.mark.parametrize("kind,size,fit,shift", [("PERSP", (60, 90), "HORIZONTAL", (0.15, -0.1)),
                                                 ("PERSP", (96, 60), "VERTICAL", (-0.1, 0.2)),
                                                 ("ORTHO", (96, 72), "AUTO", (0.1, 0.15))])
def test_alpha_matches_cycles_for_other_cameras(kind, size, fit, shift, tmp_path):
    """The tracer's own camera (not only the exported numbers) against Cycles:
    portrait and landscape, sensor fits, shifts, orthographic."""
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene
    from tempera.tracer.lpe import trace_lpe

    scene = lpe_scene.build_scene(f"LPE {kind} {fit}", size)
    camera = scene.camera.data
    camera.type, camera.sensor_fit, camera.ortho_scale = kind, fit, 5.0
    camera.shift_x, camera.shift_y = shift
    try:
        render_guides(scene, [1], tmp_path / "cache", {"samples": 32, "ld12e_samples": 1, "masks": "none"})
        cycles = guide_cache.read_frame(tmp_path / "cache", 1, ["alpha"])["alpha"] > 0.5
        scene_dict, _ = export_scene(scene, evaluated_depsgraph(scene, scene.view_layers[0], 1), size)
        _, alpha = trace_lpe(scene_dict, ["LDE"], samples=32, max_bounces=0)  # edge pixels: enough samples
    finally:
        lpe_scene.remove_scene(scene)
    ours = alpha > 0.5
    iou = (cycles & ours).sum() / (cycles | ours).sum()
    print(f"alpha IoU {kind} {fit} {size}: {iou:.4f}")
    assert 0.1 < cycles.mean() < 0.95 and iou >= 0.99


@pytest.mark.parametrize("light", ["POINT", "SUN", "AREA", "SPOT"])
def test_light_power_matches_cycles(light, tmp_path):
    """A diffuse floor under each light type: the unit conversions of scene_units."""
    scene = lpe_scene.build_scene(f"LPE {light}", SIZE, light=light, diffuse_only=True, objects=False)
    try:
        guides, _ = render(scene, tmp_path / "cache", ["LDE"], samples=32)
    finally:
        lpe_scene.remove_scene(scene)
    mean_error, block_error = compare(traced(guides, "LDE"), guides["LDE"], guides["alpha"])
    print(f"{light}: mean error {mean_error:.4f}, block error {block_error:.4f}")
    assert mean_error <= MEAN_TOLERANCE and block_error <= BLOCK_TOLERANCE


def test_emission_and_world_match_cycles(tmp_path):
    """A diffuse floor lit only by an emissive Principled panel and a constant
    world: emission colour x strength and background colour x strength."""
    scene = lpe_scene.build_scene("LPE emission", SIZE, diffuse_only=True, objects=False)
    panel_mesh = bpy.data.meshes.new("LPE panel")
    panel_mesh.from_pydata([(-0.6, -0.4, 0), (0.6, -0.4, 0), (0.6, 0.4, 0), (-0.6, 0.4, 0)], [], [(0, 1, 2, 3)])
    material = bpy.data.materials.new("LPE panel")
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0, 0, 0, 1)
    compat.principled_socket(bsdf, "Emission").default_value = (1.0, 0.8, 0.6, 1)
    bsdf.inputs["Emission Strength"].default_value = 20.0
    panel_mesh.materials.append(material)
    panel = bpy.data.objects.new("LPE panel", panel_mesh)
    panel.location, panel.rotation_euler = (0.3, 0.2, 1.5), (math.radians(180 - 25), 0, 0)  # facing down
    scene.collection.objects.link(panel)
    world = bpy.data.worlds.new("LPE world")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (0.3, 0.4, 0.5, 1)
    background.inputs["Strength"].default_value = 0.5
    scene.world = world
    for obj in [o for o in scene.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(obj)
    try:
        guides, report = render(scene, tmp_path / "cache", ["LDE"], samples=64)
    finally:
        lpe_scene.remove_scene(scene)
        bpy.data.worlds.remove(world)
        bpy.data.materials.remove(material)
    assert report["warnings"] == []
    mean_error, block_error = compare(traced(guides, "LDE"), guides["LDE"], guides["alpha"])
    print(f"emission and world: mean error {mean_error:.4f}, block error {block_error:.4f}")
    assert mean_error <= MEAN_TOLERANCE and block_error <= BLOCK_TOLERANCE


def test_image_texture_matches_cycles(tmp_path):
    """A floor textured with an asymmetric 8-bit sRGB image: its colours
    (decoded to linear) and its orientation (UVs, image rows) as Cycles'."""
    scene = lpe_scene.build_scene("LPE texture", SIZE, diffuse_only=True, objects=False)
    # 4 x 2 blocks of 16 x 16 texels: filtering only matters at block edges
    # (Cycles filters 8-bit sRGB images before decoding them, the tracer after).
    colours = np.array([[(0.9, 0.1, 0.1), (0.1, 0.8, 0.1), (0.1, 0.1, 0.9), (0.9, 0.9, 0.2)],  # bottom row
                        [(0.5, 0.5, 0.5), (0.9, 0.4, 0.7), (0.2, 0.7, 0.8), (0.05, 0.05, 0.05)]])
    texels = np.dstack([colours.repeat(16, axis=0).repeat(16, axis=1), np.ones((32, 64))])
    image = bpy.data.images.new("LPE checker", 64, 32)
    image.pixels.foreach_set(texels.astype(np.float32).ravel())
    floor = next(o for o in scene.objects if o.name.startswith("Floor"))
    material = floor.material_slots[0].material
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image  # Linear interpolation: bilinear, as the tracer samples textures
    tree.links.new(texture.outputs["Color"], tree.nodes["Diffuse BSDF"].inputs["Color"])
    mesh = floor.data
    uvs = mesh.uv_layers.new(name="UVMap")
    corners = np.array([mesh.vertices[loop.vertex_index].co[:2] for loop in mesh.loops])
    low, high = corners.min(axis=0), corners.max(axis=0)
    for loop, corner in zip(uvs.data, corners):
        loop.uv = (corner - low) / (high - low)  # the image once over the floor
    try:
        guides, report = render(scene, tmp_path / "cache", ["LDE"], samples=32)
    finally:
        lpe_scene.remove_scene(scene)
        bpy.data.images.remove(image)
    assert report["warnings"] == []
    mean_error, block_error = compare(traced(guides, "LDE"), guides["LDE"], guides["alpha"])
    print(f"image texture: mean error {mean_error:.4f}, block error {block_error:.4f}")
    assert mean_error <= MEAN_TOLERANCE and block_error <= BLOCK_TOLERANCE


def test_caustics_under_a_mirror_sphere():
    """LS+DE, light reflected by the mirror sphere onto the diffuse floor
    (which Cycles cannot isolate), lights the floor in front of the sphere;
    without the mirror nothing is left: the other surfaces are Diffuse BSDFs,
    which have no glossy lobe (as in Cycles)."""
    scene = lpe_scene.build_scene("LPE mirror", SIZE, sphere="mirror", light="CAUSTIC", diffuse_only=True)
    floor = np.s_[48:, :]  # the image's bottom third: floor only, in front of the objects
    try:
        (with_mirror,), _, _ = trace(scene, ["LS+DE"], samples=256)
        bpy.data.objects.remove(next(o for o in scene.objects if o.name.startswith("Sphere")))
        (without,), _, _ = trace(scene, ["LS+DE"], samples=256)
    finally:
        lpe_scene.remove_scene(scene)
    print(f"caustics on the floor: mean {with_mirror[floor].mean():.5f} with the mirror, "
          f"{without[floor].mean():.5f} without")
    assert with_mirror[floor].mean() > 5e-4
    assert without.max() == 0


# --------------------------------------------------------------------------- the guide cache

def test_render_guides_writes_the_lpe_channels(metal):
    from tempera.app import guide_cache
    from tempera import image_info

    cache, expressions = metal["cache"], metal["expressions"]
    manifest = guide_cache.read_manifest(cache)
    assert manifest["params"]["lpe"] == expressions and manifest["params"]["lpe_samples"] == SAMPLES
    assert manifest["lpe"] == {guide_cache.lpe_guide(e): e for e in expressions}
    channels = image_info(str(cache / "frame_0001.exr"))["channels"]
    for expression in expressions:
        name = guide_cache.lpe_guide(expression)
        assert name in manifest["guides"] and f"{name}.G" in channels
    assert "lpe_LDE.R" in channels and all("." not in n[:-2] for n in channels if n.startswith("lpe_"))
    assert metal["report"]["warnings"] == []  # everything in this scene is modelled


def test_animated_frames_are_traced_at_their_frame(tmp_path):
    """The moving cube of guide_scene.py: each frame's L.*E against Cycles'
    FULL of the same frame (no glossy surfaces, so they hold the same paths)."""
    from guide_scene import build_scene, remove_scene
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene = build_scene("LPE animation")
    try:
        render_guides(scene, (2, 4), tmp_path / "cache", {"samples": 32, "ld12e_samples": 1, "masks": "objects",
                                                          "lpe": ["L.*E"], "lpe_samples": 32})
    finally:
        remove_scene(scene)
    for frame in (2, 4):
        guides = guide_cache.read_frame(tmp_path / "cache", frame)
        mean_error, block_error = compare(guides[guide_cache.lpe_guide("L.*E")], guides["FULL"], guides["alpha"])
        print(f"frame {frame}: mean error {mean_error:.4f}, block error {block_error:.4f}")
        # Tighter than BLOCK_TOLERANCE: this sun-lit scene is nearly noise-free
        # (measured 0.4 %), while frame 2 traced against frame 4 gives 12 %.
        assert mean_error <= MEAN_TOLERANCE and block_error <= 0.03


def test_malformed_expression_is_refused_before_rendering(metal, tmp_path):
    from tempera.blender.guide_render import GuideRenderError, render_guides

    with pytest.raises(GuideRenderError, match=r"expression 2 'L\(DE' is malformed: .*position 4"):
        render_guides(metal["scene"], [1], tmp_path / "cache", {"lpe": ["LDE", "L(DE"]})
    with pytest.raises(GuideRenderError, match="repeats expression 1"):
        render_guides(metal["scene"], [1], tmp_path / "cache", {"lpe": ["LDE", " LDE "]})
    assert not (tmp_path / "cache").exists()


def test_operator_reports_a_malformed_expression(metal, tmp_path):
    from tempera.blender.guide_operator import cache_status

    scene = metal["scene"]
    shown = bpy.context.window.scene
    bpy.context.window.scene = scene
    settings = scene.tempera
    settings.guide_dir = str(tmp_path / "guides")
    settings.guide_frame_range = "CURRENT"
    settings.guide_lpe = "LDE; LD{2E"
    try:
        text, icon = cache_status(scene)
        assert icon == "ERROR" and "'LD{2E' is malformed" in text
        # The operator's ERROR report reaches a Python caller as a RuntimeError.
        with pytest.raises(RuntimeError, match=r"'LD\{2E' is malformed: .*position 4"):
            bpy.ops.tempera.render_guides()
    finally:
        settings.guide_lpe = ""
        bpy.context.window.scene = shown
    assert not (tmp_path / "guides").exists()


# --------------------------------------------------------------------------- the exporter

CAMERAS = [  # (type, resolution, sensor fit, shift x, shift y)
    ("PERSP", (96, 72), "AUTO", 0.1, -0.05),
    ("PERSP", (60, 90), "AUTO", 0.0, 0.2),
    ("PERSP", (60, 90), "HORIZONTAL", 0.15, 0.1),
    ("PERSP", (96, 72), "VERTICAL", -0.1, 0.0),
    ("ORTHO", (96, 72), "AUTO", 0.2, 0.1),
    ("ORTHO", (60, 90), "HORIZONTAL", -0.1, 0.3),
]


@pytest.mark.parametrize("kind,size,fit,shift_x,shift_y", CAMERAS)
def test_camera_rays_follow_blenders_projection(kind, size, fit, shift_x, shift_y):
    """Points on the exported camera's pixel rays land on the same pixel
    centres under Blender's own projection matrix."""
    from tempera.tracer import scene_units
    from tempera.blender.scene_export import evaluated_depsgraph, export_camera

    scene = bpy.data.scenes.new("LPE camera")
    camera = bpy.data.objects.new("LPE camera", bpy.data.cameras.new("LPE camera"))
    try:
        scene.collection.objects.link(camera)
        scene.camera = camera
        data = camera.data
        data.type, data.sensor_fit, data.shift_x, data.shift_y = kind, fit, shift_x, shift_y
        data.lens, data.sensor_width, data.sensor_height, data.ortho_scale = 42.0, 36.0, 20.0, 5.0
        camera.location, camera.rotation_euler = (1.0, -4.0, 2.0), (1.2, 0.1, 0.3)
        scene.render.resolution_x, scene.render.resolution_y = size
        depsgraph = evaluated_depsgraph(scene, scene.view_layers[0], 1)
        exported = export_camera(scene, depsgraph, size)
        to_world = np.array(exported["camera_to_world"], np.float64)
        evaluated = camera.evaluated_get(depsgraph)
        np.testing.assert_allclose(to_world, np.array(evaluated.matrix_world), atol=1e-5)
        projection = np.array(evaluated.calc_matrix_camera(
            depsgraph, x=size[0], y=size[1], scale_x=1, scale_y=1))
        for x, y in [(0, 0), (size[0] - 1, 0), (17, 23), (size[0] - 1, size[1] - 1), (5, size[1] - 2)]:
            origin, direction = scene_units.camera_ray(exported, x, y)
            point = origin + 3.0 * direction  # camera space, in front of the camera
            clip = projection @ np.append(point, 1.0)
            ndc = clip[:2] / clip[3]
            pixel = ((ndc[0] + 1) / 2 * size[0] - 0.5, (1 - ndc[1]) / 2 * size[1] - 0.5)
            np.testing.assert_allclose(pixel, (x, y), atol=1e-3)
    finally:
        bpy.data.objects.remove(camera)
        bpy.data.scenes.remove(scene)


def test_export_follows_animation_and_expands_instances():
    """Frame-evaluated transforms, collection instances, render visibility and the sun's units."""
    from guide_scene import CUBE_START, CUBE_STEP, build_scene, remove_scene
    from tempera.blender.scene_export import evaluated_depsgraph, export_scene

    scene = build_scene("LPE export")
    instance = bpy.data.objects.new("Movers instance", None)
    instance.instance_type = "COLLECTION"
    instance.instance_collection = bpy.data.collections["Movers"]
    instance.location = (0, 0, 10)
    scene.collection.objects.link(instance)
    try:
        for frame in (2, 4):
            depsgraph = evaluated_depsgraph(scene, scene.view_layers[0], frame)
            exported, warnings = export_scene(scene, depsgraph, (65, 48))
            vertices = exported["vertices"]
            centre = CUBE_START + (frame - 1) * CUBE_STEP
            # Two cubes (the cube, its instance 10 up) and the backdrop: 3 x 12 triangles.
            assert len(exported["triangles"]) == 36
            for offset in (Vector(), Vector((0, 0, 10))):
                near = np.linalg.norm(vertices - np.array(centre + offset), axis=1) < 1.31  # 0.75 * sqrt(3)
                assert near.sum() >= 8
            assert warnings == []
        # Disabling the collection in renders hides its cube, not the instance of it.
        bpy.data.collections["Movers"].hide_render = True
        exported, _ = export_scene(scene, depsgraph, (65, 48))
        assert len(exported["triangles"]) == 24
        centre = CUBE_START + 3 * CUBE_STEP
        assert not (np.linalg.norm(exported["vertices"] - np.array(centre), axis=1) < 1.31).any()
        sun = exported["lights"][0]
        assert sun["type"] == "sun"
        np.testing.assert_allclose(sun["irradiance"], [3.0] * 3)
        sun_matrix = np.array(scene.objects["Sun"].evaluated_get(depsgraph).matrix_world)
        np.testing.assert_allclose(sun["direction"], sun_matrix[:3, 2], atol=1e-6)
    finally:
        bpy.data.objects.remove(instance)
        remove_scene(scene)


def _surface_tree(name):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    return material, tree, tree.nodes["Material Output"].inputs["Surface"]


def test_materials_become_cycles_closures():
    from tempera.blender.scene_export import convert_material

    warnings = []
    (default,) = convert_material(None, warnings)["closures"]  # an empty slot
    # Cycles' default surface, or in 5.0 Blender's default material (compat.default_surface_is_principled)
    assert default["type"] == ("principled" if compat.default_surface_is_principled() else "diffuse")
    np.testing.assert_allclose(default["color"], [0.8, 0.8, 0.8])
    plain = bpy.data.materials.new("LPE plain")
    plain.diffuse_color = (0.2, 0.4, 0.6, 1)
    plain.use_nodes = False  # 5.0 keeps it on: materials always render their nodes there
    exported = convert_material(plain, warnings)
    if not plain.use_nodes:
        (closure,) = exported["closures"]
        assert closure["type"] == "diffuse" and warnings == []  # Cycles renders it as a diffuse BSDF
        np.testing.assert_allclose(closure["color"], [0.2, 0.4, 0.6], rtol=1e-6)
    else:  # Blender 5.0: the material's default Principled BSDF
        assert exported["closures"] and warnings == []

    textured = bpy.data.materials.new("LPE textured")
    textured.use_nodes = True
    tree = textured.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    for name, value in (("Metallic", 0.3), ("Specular", 0.6), ("Roughness", 0.2), ("Transmission", 0.1),
                        ("IOR", 1.5), ("Emission Strength", 2.0)):
        compat.principled_socket(bsdf, name).default_value = value
    compat.principled_socket(bsdf, "Emission").default_value = (1.0, 0.5, 0.0, 1)
    image = bpy.data.images.new("LPE texture", 2, 2)  # a byte image in sRGB
    image.pixels = [0.5, 0.5, 0.5, 1, 1, 0, 0, 1,  # bottom row: grey, red
                    0, 1, 0, 1, 0, 0, 1, 1]  # top row: green, blue
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    tree.links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
    principled, emission = convert_material(textured, warnings)["closures"]
    if "Coat Weight" in bsdf.inputs:  # Principled v2: rough transmission is modelled
        assert warnings == []
    else:
        assert len(warnings) == 1 and "rough transmission is traced as smooth glass" in warnings[0]
    warnings.clear()
    assert principled["type"] == "principled"
    for key, value in (("metallic", 0.3), ("specular", 0.6), ("roughness", 0.2), ("transmission", 0.1),
                       ("ior", 1.5)):
        assert principled[key] == pytest.approx(value)
    texture = principled["color_texture"]["texels"]
    assert texture.shape == (2, 2, 4) and texture.dtype == np.float32
    np.testing.assert_allclose(texture[0, :, :3], [[0, 1, 0], [0, 0, 1]], atol=1e-3)  # row 0 is the top
    np.testing.assert_allclose(texture[1, 0, :3], [0.2140] * 3, atol=2e-3)  # sRGB 0.5 -> linear
    assert emission["type"] == "emission"
    np.testing.assert_allclose(emission["color"] * emission["weight"], [2.0, 1.0, 0.0])

    # Mix Shader by Fresnel of a Diffuse and a Glossy, inside a node group.
    mixed, tree, surface = _surface_tree("LPE mixed")
    group = bpy.data.node_groups.new("LPE group", "ShaderNodeTree")
    if hasattr(group, "interface"):  # Blender 4
        group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    else:
        group.outputs.new("NodeSocketShader", "Shader")
    g_out = group.nodes.new("NodeGroupOutput")
    diffuse = group.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.7, 0.1, 0.1, 1)
    glossy = group.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution, glossy.inputs["Roughness"].default_value = "BECKMANN", 0.32
    fresnel = group.nodes.new("ShaderNodeFresnel")
    fresnel.inputs["IOR"].default_value = 1.45  # its default in 3.x (4.0: 1.5)
    mix = group.nodes.new("ShaderNodeMixShader")
    group.links.new(fresnel.outputs[0], mix.inputs["Fac"])
    group.links.new(diffuse.outputs[0], mix.inputs[1])
    group.links.new(glossy.outputs[0], mix.inputs[2])
    group.links.new(mix.outputs[0], g_out.inputs["Shader"])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    tree.links.new(node.outputs[0], surface)
    first, second = convert_material(mixed, warnings)["closures"]
    assert warnings == []
    assert first["type"] == "diffuse" and first["factors"] == [{"kind": "fresnel", "value": pytest.approx(1.45),
                                                               "invert": True}]
    np.testing.assert_allclose(first["color"], [0.7, 0.1, 0.1], rtol=1e-6)
    assert second["type"] == "glossy" and second["distribution"] == "beckmann"
    assert second["roughness"] == pytest.approx(0.32) and not second["factors"][0]["invert"]

    # Colour nodes are folded: the new Mix node (Blender 3.4+) multiplying two colours, through a reroute.
    folded, tree, surface = _surface_tree("LPE folded")
    diffuse_node = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse_node.outputs[0], surface)
    mix_node = tree.nodes.new("ShaderNodeMix")
    mix_node.data_type, mix_node.blend_type = "RGBA", "MULTIPLY"
    sockets = {s.name: s for s in mix_node.inputs if s.enabled}
    sockets["Factor"].default_value = 1.0
    sockets["A"].default_value = (0.5, 0.8, 1.0, 1)
    sockets["B"].default_value = (0.4, 0.5, 0.2, 1)
    reroute = tree.nodes.new("NodeReroute")
    colour_out = next(s for s in mix_node.outputs if s.enabled)
    tree.links.new(colour_out, reroute.inputs[0])
    tree.links.new(reroute.outputs[0], diffuse_node.inputs["Color"])
    (closure,) = convert_material(folded, warnings)["closures"]
    assert warnings == []
    np.testing.assert_allclose(closure["color"], [0.2, 0.4, 0.2], rtol=1e-5)

    # A shader the tracer does not model: a warning naming it, and a diffuse lobe of its own colour.
    velvet_material, tree, surface = _surface_tree("LPE velvet")
    velvet_material.diffuse_color = (0.1, 0.9, 0.1, 1)  # the viewport colour must not be used
    velvet = tree.nodes.new(compat.sheen_bsdf_node_type())
    velvet.inputs["Color"].default_value = (0.3, 0.2, 0.6, 1)
    tree.links.new(velvet.outputs[0], surface)
    (closure,) = convert_material(velvet_material, warnings)["closures"]
    assert closure["type"] == "diffuse"
    np.testing.assert_allclose(closure["color"], [0.3, 0.2, 0.6], rtol=1e-6)
    assert len(warnings) == 1 and "LPE velvet" in warnings[0] and velvet.name in warnings[0]
    for material in (plain, textured, mixed, folded, velvet_material):
        bpy.data.materials.remove(material)
    bpy.data.node_groups.remove(group)
    bpy.data.images.remove(image)


def test_principled_v2_inputs_are_exported():
    """Blender 4's Principled v2: its specular level and tint, coat and
    distribution reach the tracer's closure, with no warning, and compat
    selects the tracer's Principled v2 model."""
    from tempera.blender.scene_export import convert_material

    material = bpy.data.materials.new("LPE v2")
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    if "Coat Weight" not in bsdf.inputs:
        pytest.skip("Principled v1 (Blender 3.x)")
    values = {"Coat Weight": 0.7, "Coat Roughness": 0.2, "Coat IOR": 1.6, "Specular IOR Level": 0.3}
    for name, value in values.items():
        bsdf.inputs[name].default_value = value
    bsdf.inputs["Coat Tint"].default_value = (1.0, 0.5, 0.25, 1)
    bsdf.inputs["Specular Tint"].default_value = (1.0, 0.9, 0.8, 1)
    warnings = []
    (closure,) = convert_material(material, warnings)["closures"]
    assert warnings == []
    for key, name in (("clearcoat", "Coat Weight"), ("clearcoat_roughness", "Coat Roughness"),
                      ("coat_ior", "Coat IOR"), ("specular_ior_level", "Specular IOR Level")):
        assert closure[key] == pytest.approx(values[name])
    np.testing.assert_allclose(closure["coat_tint"], [1.0, 0.5, 0.25], rtol=1e-6)
    np.testing.assert_allclose(closure["specular_tint"], [1.0, 0.9, 0.8], rtol=1e-6)
    assert closure["multiscatter"]  # the node's default distribution
    bsdf.distribution = "GGX"
    assert not convert_material(material, warnings)["closures"][0]["multiscatter"]
    assert compat.cycles_closure_model()["principled_v2"]


def test_light_units():
    """Blender's light settings -> the tracer's physical units (scene_units)."""
    from tempera.blender.scene_export import _light

    cases = {"POINT": {"energy": 100.0}, "AREA": {"energy": 50.0, "shape": "RECTANGLE", "size": 2.0,
                                                   "size_y": 0.5}}
    matrix = np.diag([1.0, 2.0, 1.0, 1.0])  # the object's scale stretches the area light along y
    matrix[:3, 3] = (1, 2, 3)
    for kind, settings in cases.items():
        light = bpy.data.lights.new(f"LPE {kind}", kind)
        for key, value in settings.items():
            setattr(light, key, value)
        obj = bpy.data.objects.new(f"LPE {kind}", light)
        try:
            exported = _light(obj, matrix, [])
            # Cycles 3.x: P / (4 A); 4.0 on: P / (pi A)
            normalisation = math.pi if compat.cycles_light_model(light)["area_emits_power"] else 4
        finally:
            bpy.data.objects.remove(obj)
            bpy.data.lights.remove(light)
        if kind == "POINT":
            np.testing.assert_allclose(exported["intensity"], [100 / (4 * math.pi)] * 3, rtol=1e-6)
            np.testing.assert_allclose(exported["position"], [1, 2, 3])
        else:
            assert (exported["size_u"], exported["size_v"]) == (2.0, 1.0)
            np.testing.assert_allclose(exported["radiance"], [50 / (normalisation * 2.0)] * 3, rtol=1e-6)
            np.testing.assert_allclose(exported["normal"], [0, 0, -1])  # Blender's area lights face -Z


def test_soft_lights_follow_this_cycles():
    """A point or spot light with a radius is the disk facing the shaded point
    in Cycles 3.x and in 4.x with Soft Falloff on, a sphere in 4.x with it
    off; only 3.x weights spots by the cosine to their axis."""
    from tempera.blender.scene_export import _light

    cycles4 = bpy.app.version >= (4, 0, 0)  # an oracle independent of compat's feature test
    light = bpy.data.lights.new("LPE soft spot", "SPOT")
    light.shadow_soft_size = 0.5
    obj = bpy.data.objects.new("LPE soft spot", light)
    try:
        shapes = []
        for soft in (True, False):
            if cycles4:
                light.use_soft_falloff = soft
            exported = _light(obj, np.eye(4), [])
            shapes.append(exported["soft_shape"])
            assert exported["spot_axis_cosine"] == (not cycles4)
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.lights.remove(light)
    assert shapes == (["disk", "sphere"] if cycles4 else ["disk", "disk"])
