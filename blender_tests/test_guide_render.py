"""tempera.blender.guide_render on a tiny animated scene rendered headless:
a cube moving right with linear keyframes in front of a static backdrop."""
import math
import tempfile
from pathlib import Path

import bpy
import numpy as np
import pytest
from bpy_extras.object_utils import world_to_camera_view
from guide_scene import CUBE_START, CUBE_STEP, FRAMES, PARAMS, SIZE
from guide_scene import build_scene as _build_scene
from guide_scene import remove_scene as _remove_scene
from mathutils import Vector
from tempera.blender import compat


def rna_dump(struct, prefix, out, depth=0):
    """Every RNA property of `struct` into `out` as {"prefix.name": value};
    nested structs too (IDs by name); collections and the depsgraph are skipped."""
    for prop in struct.bl_rna.properties:
        name = prop.identifier
        # dimensions: derived from the evaluated geometry, which 4.x/5.0 evaluate lazily.
        if name in ("rna_type", "depsgraph", "dimensions") or prop.type == "COLLECTION":
            continue
        value = getattr(struct, name, None)
        key = f"{prefix}.{name}"
        if prop.type == "POINTER":
            if value is None or isinstance(value, bpy.types.ID):
                out[key] = getattr(value, "name", None)
            elif depth < 3:
                rna_dump(value, key, out, depth + 1)
        else:
            out[key] = tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value
    return out


def scene_dump(scene):
    out = {"frame": (scene.frame_current, scene.frame_subframe)}
    rna_dump(scene.render, "render", out)
    rna_dump(scene.cycles, "cycles", out)
    for layer in scene.view_layers:
        rna_dump(layer, f"view_layers[{layer.name}]", out)
    for obj in scene.objects:
        rna_dump(obj, f"objects[{obj.name}]", out)
    return out


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """The scene, its settings before, the .blend saved before, and its guides of FRAMES."""
    from tempera.blender.guide_render import render_guides

    tmp = tmp_path_factory.mktemp("guide_render")
    scene = _build_scene()
    scene.frame_set(1)
    before = scene_dump(scene)
    window_scene = bpy.context.window.scene.name
    blend = tmp / "scene.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    blend_bytes = blend.read_bytes()
    calls = []
    temp_dirs = set(Path(tempfile.gettempdir()).glob("tempera-guides-*"))
    report = render_guides(scene, FRAMES, tmp / "cache", PARAMS, progress=lambda *a: calls.append(a))
    yield {"scene": scene, "before": before, "blend": blend, "blend_bytes": blend_bytes,
           "cache": tmp / "cache", "window_scene": window_scene,
           "temp_dirs_left": set(Path(tempfile.gettempdir()).glob("tempera-guides-*")) - temp_dirs,
           "report": report, "progress": calls}
    _remove_scene(scene)


def frame(rendered, f):
    from tempera.app import guide_cache

    return guide_cache.read_frame(rendered["cache"], f)


def screen_position(scene, point):
    """Pixel position (x right, y down, pixel centres at .5) of a world point."""
    camera = scene.camera  # static: its matrix does not depend on the frame
    assert (camera.matrix_world.translation - camera.location).length < 1e-6  # not a stale matrix
    ndc = world_to_camera_view(scene, camera, Vector(point))
    return np.array([ndc.x * SIZE[0], (1 - ndc.y) * SIZE[1]])


def test_manifest_and_channels(rendered):
    from tempera.app import guide_cache
    from tempera import image_info

    report, cache = rendered["report"], rendered["cache"]
    assert report["rendered"] == list(FRAMES) and report["skipped"] == []
    assert rendered["progress"][-1][:2] == (len(FRAMES), len(FRAMES))
    assert not rendered["temp_dirs_left"]
    manifest = guide_cache.read_manifest(cache)
    assert manifest["resolution"] == list(SIZE) and manifest["frame_range"] == [2, 4]
    assert manifest["camera"] == "GuideCamera" and manifest["params"]["samples"] == 8
    assert manifest["blender_version"] == bpy.app.version_string
    assert manifest["masks"]["mask.OB_MovingCube"] == {"kind": "object", "name": "MovingCube"}
    assert manifest["masks"]["mask.CO_Movers"] == {"kind": "collection", "name": "Movers"}
    assert sorted(p.name for p in cache.iterdir()) == ["frame_0002.exr", "frame_0003.exr", "frame_0004.exr",
                                                       "manifest.json"]
    channels = image_info(str(cache / "frame_0003.exr"))["channels"]
    for name in ("FULL.R", "LD12E.B", "velocity_forward.X", "occlusion_backward.V", "tensor.XY",
                 "line_distance.V", "mask.OB_MovingCube.V", "alpha.A"):
        assert name in channels


def test_every_channel_is_finite_and_full_size(rendered):
    for f in FRAMES:
        for name, array in frame(rendered, f).items():
            assert array.shape[:2] == (SIZE[1], SIZE[0]), name
            assert np.all(np.isfinite(array)), f"{name} of frame {f} is not finite"


def test_velocity_matches_the_analytic_screen_motion(rendered):
    scene = rendered["scene"]
    guides = frame(rendered, 3)
    front = CUBE_START + 2 * CUBE_STEP + Vector((0, -0.75, 0))  # centre of the cube's front face at frame 3
    p2, p3, p4 = (screen_position(scene, front + d * CUBE_STEP) for d in (-1, 0, 1))
    x, y = np.floor(p3).astype(int)
    window = np.s_[y - 1:y + 2, x - 1:x + 2]
    assert guides["mask.OB_MovingCube"][window].min() == 1
    assert (p4 - p3)[0] > 3 and (p4 - p3)[1] < -1  # it does move, right and up the image
    for measured in guides["velocity_forward"][window].reshape(-1, 2):
        np.testing.assert_allclose(measured, p4 - p3, atol=0.5)
    for measured in guides["velocity_backward"][window].reshape(-1, 2):
        np.testing.assert_allclose(measured, p3 - p2, atol=0.5)
    background = guides["velocity_forward"][2:6, 2:6]  # top left: the static backdrop
    assert np.abs(background).max() < 0.01


def _erode(mask, n=1):
    for _ in range(n):
        padded = np.pad(mask, 1)
        mask = mask & padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return mask


def test_disoccluded_region_is_zero_and_its_neighbours_one(rendered):
    previous, current = frame(rendered, 2), frame(rendered, 3)
    cube_before, cube_now = previous["mask.OB_MovingCube"] > 0.5, current["mask.OB_MovingCube"] > 0.5
    revealed = _erode(cube_before & ~cube_now)  # backdrop the cube covered at frame 2
    assert revealed.sum() >= 10
    chi = current["occlusion_backward"]
    assert np.all(chi[revealed] == 0)
    away = _erode(~(cube_before | cube_now), 2)  # backdrop 2+ px away from the cube, then and now
    assert np.all(chi[away] == 1) and np.all(chi[_erode(cube_before & cube_now, 1)] == 1)
    # Forward: the backdrop the cube is about to cover is chi+ = 0.
    following = frame(rendered, 4)
    covered = _erode((following["mask.OB_MovingCube"] > 0.5) & ~cube_now)
    assert covered.sum() >= 10 and np.all(current["occlusion_forward"][covered] == 0)


def test_ld12e_is_at_most_full_gi(rendered):
    """The scene emits nothing, so the first two diffuse bounces are part of all light."""
    for f in FRAMES:
        guides = frame(rendered, f)
        ld12e, full = guides["LD12E"], guides["FULL"]
        assert ld12e.max() > 0.05
        assert np.all(ld12e <= full * (1 + 1e-5) + 1e-6)  # float rounding only


def test_masks_alpha_and_lines(rendered):
    guides = frame(rendered, 3)
    cube = guides["mask.OB_MovingCube"]
    np.testing.assert_array_equal(cube, guides["mask.CO_Movers"])
    assert np.all(cube + guides["mask.OB_Backdrop"] <= 1) and 30 < cube.sum() < 600
    assert guides["alpha"].min() > 0.99  # the backdrop fills the frame
    lines = guides["lines"] > 0.5
    border = cube.astype(bool) & ~_erode(cube.astype(bool))
    assert lines[border].mean() > 0.8  # the cube's silhouette
    assert not lines[_erode(~cube.astype(bool), 2)].any()  # nothing on the flat backdrop
    assert guides["line_distance"][lines].max() == 0 and guides["line_distance"].max() == 1
    assert guides["tensor"][:, :, 0].max() > 0  # edges have structure


def _unset_colorspace(key, before):
    """Blender 5.0 leaves an image format's linear colour space unset ('') in a
    new scene and fills in the format's default the first time file_format
    changes; '' cannot be set back, and with the scene's colour management
    followed it is not used. 5.3 adds the space's interop_id, 'NONE' while
    the name is unset, filled in with it."""
    return ((key.endswith("linear_colorspace_settings.name") and before == "")
            or (key.endswith("linear_colorspace_settings.interop_id") and before == "NONE"))


def test_the_world_has_no_velocity_while_the_camera_turns(tmp_path):
    """Velocity guides are the motion of surfaces. Blender 5.2 writes the
    world's apparent motion into the Vector pass as the camera turns, where
    3.4-5.0 and 5.3 write 0 (compat.surface_vector_pass); on the Suzanne
    turntable it moved the coherent method's background by up to 7 px a
    frame. With the camera panning over a backdrop that leaves the world in
    view, the world's pixels must have no velocity and the backdrop's must."""
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene = _build_scene("Turning camera")
    try:
        # The world shows left, right, above and below ("Backdrop.001" while another test's scene is open).
        backdrop = next(o for o in scene.objects if o.name.startswith("Backdrop"))
        backdrop.scale = (3, 0.1, 2)
        camera = scene.camera
        for f, degrees in ((1, -4.0), (5, 4.0)):
            camera.rotation_euler[2] = math.radians(degrees)
            camera.keyframe_insert("rotation_euler", frame=f)
        for fcurve in compat.action_fcurves(camera):
            for key in fcurve.keyframe_points:
                key.interpolation = "LINEAR"
        render_guides(scene, [3], tmp_path / "cache", dict(PARAMS, samples=2, ld12e_samples=1))
        g = guide_cache.read_frame(tmp_path / "cache", 3, ["velocity_backward", "velocity_forward", "alpha"])
    finally:
        _remove_scene(scene)
    world, surface = g["alpha"] == 0, g["alpha"] == 1
    assert world.sum() > 200 and surface.sum() > 200
    for name in ("velocity_backward", "velocity_forward"):
        assert not g[name][world].any(), name
        assert np.median(np.abs(g[name][surface][:, 0])) > 1, name  # 2 degrees a frame: pixels, not 0


def test_settings_and_file_are_unchanged(rendered):
    scene = rendered["scene"]
    scene.frame_set(1)
    before, after = rendered["before"], scene_dump(scene)
    changed = sorted(k for k in before.keys() | after.keys() if before.get(k, "<missing>") != after.get(k, "<missing>")
                     and not _unset_colorspace(k, before.get(k)))
    assert not changed, [(k, before.get(k), after.get(k)) for k in changed[:20]]
    assert len(before) > 500
    assert scene.render.engine == compat.eevee_engine()
    assert bpy.context.window.scene.name == rendered["window_scene"]  # the window shows what it showed
    assert rendered["blend"].read_bytes() == rendered["blend_bytes"]


def test_rerun_skips_current_frames(rendered):
    from tempera.blender.guide_render import render_guides

    cache = rendered["cache"]
    mtimes = {p.name: p.stat().st_mtime_ns for p in cache.iterdir()}
    report = render_guides(rendered["scene"], FRAMES, cache, PARAMS)
    assert report["rendered"] == [] and report["skipped"] == list(FRAMES)
    assert {p.name: p.stat().st_mtime_ns for p in cache.iterdir()} == mtimes


def test_motion_blur_is_refused_with_a_clear_message(rendered, tmp_path):
    from tempera.blender.guide_render import GuideRenderError, render_guides

    scene = rendered["scene"]
    scene.render.use_motion_blur = True
    try:
        with pytest.raises(GuideRenderError, match="Motion blur is on .* Turn off Render Properties > Motion Blur"):
            render_guides(scene, FRAMES, tmp_path / "cache", PARAMS)
    finally:
        scene.render.use_motion_blur = False
    assert not (tmp_path / "cache").exists()


def test_no_camera_is_refused(rendered, tmp_path):
    from tempera.blender.guide_render import GuideRenderError, render_guides

    scene = rendered["scene"]
    camera, scene.camera = scene.camera, None
    try:
        with pytest.raises(GuideRenderError, match="no active camera"):
            render_guides(scene, FRAMES, tmp_path / "cache", PARAMS)
    finally:
        scene.camera = camera


def test_settings_come_back_when_rendering_fails(rendered, tmp_path):
    """An error (here: a progress callback cancelling once the first frame is
    written) leaves the scene, the window and the temporary folders as they
    were, and keeps the frame finished before it (issue 18)."""
    from tempera.blender.guide_render import render_guides

    scene = rendered["scene"]
    scene.frame_set(1)
    before = scene_dump(scene)
    private_tmp = tmp_path / "systmp"  # this test's own system temporary folder (others share /tmp)
    private_tmp.mkdir()
    saved_tempdir, tempfile.tempdir = tempfile.tempdir, str(private_tmp)

    class Cancel(Exception):
        pass

    def cancel(done, total, message):
        if done == 1:
            raise Cancel()

    try:
        with pytest.raises(Cancel):
            render_guides(scene, (2, 3), tmp_path / "cache", {"samples": 2, "ld12e_samples": 2}, progress=cancel)
    finally:
        tempfile.tempdir = saved_tempdir
    after = scene_dump(scene)
    assert [k for k in before if before[k] != after.get(k)] == []
    assert bpy.context.window.scene.name == rendered["window_scene"]
    assert list(private_tmp.iterdir()) == []
    assert sorted(p.name for p in (tmp_path / "cache").iterdir()) == ["frame_0002.exr", "manifest.json"]


def test_workbench_scene_gets_cycles_guides_and_keeps_its_engine(rendered, tmp_path):
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene = rendered["scene"]
    scene.render.engine = "BLENDER_WORKBENCH"
    try:
        render_guides(scene, (3,), tmp_path / "cache", {"samples": 2, "ld12e_samples": 2, "masks": "none"})
        assert scene.render.engine == "BLENDER_WORKBENCH"
    finally:
        scene.render.engine = compat.eevee_engine()
    guides = guide_cache.read_frame(tmp_path / "cache", 3)
    assert guides["FULL"].max() > 0.1 and guides["LDDE"].max() > 0  # Cycles light paths
    assert not [g for g in guides if g.startswith("mask.")]
    assert guides["occlusion_backward"].min() == 0  # neighbours from motion-only renders


def test_frame_key_follows_the_scene(rendered):
    from tempera.blender.guide_render import scene_fingerprint

    scene = rendered["scene"]
    first = scene_fingerprint(scene, 3)
    assert scene_fingerprint(scene, 3) == first and scene_fingerprint(scene, 4) != first
    camera, backdrop = scene.camera.data, scene.objects["Backdrop"]
    camera.lens += 10
    assert scene_fingerprint(scene, 3) != first
    camera.lens -= 10
    backdrop.location.y += 1
    assert scene_fingerprint(scene, 3) != first
    backdrop.location.y -= 1
    assert scene_fingerprint(scene, 3) == first
    # Shading and lighting edits count; saving the file does not.
    material = backdrop.material_slots[0].material
    material.use_nodes = True  # 5.0: always on (deprecated), a no-op
    with_nodes = scene_fingerprint(scene, 3)
    colour = material.node_tree.nodes["Principled BSDF"].inputs["Base Color"]
    original = tuple(colour.default_value)
    colour.default_value = (0.1, 0.9, 0.1, 1)
    assert scene_fingerprint(scene, 3) != with_nodes
    colour.default_value = original
    assert scene_fingerprint(scene, 3) == with_nodes
    material.use_nodes = False
    assert scene_fingerprint(scene, 3) == first
    sun = scene.objects["Sun"].data
    sun.energy *= 2
    assert scene_fingerprint(scene, 3) != first
    sun.energy /= 2
    assert scene_fingerprint(scene, 3) == first


def test_freestyle_lines_join_the_line_guide(rendered, tmp_path):
    """With Freestyle on, the artist's lines are part of the line guide. The
    depth and normal thresholds are set out of reach so only Freestyle draws."""
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    scene = rendered["scene"]
    no_breaks = {"samples": 2, "ld12e_samples": 2, "masks": "none", "line_depth_threshold": 1e9,
                 "line_normal_angle": 180.0}
    render_guides(scene, (3,), tmp_path / "plain", no_breaks)
    settings = scene.view_layers[0].freestyle_settings
    lineset = settings.linesets.new("Outline")  # silhouettes, borders and creases by default
    scene.render.use_freestyle = True
    try:
        render_guides(scene, (3,), tmp_path / "freestyle", no_breaks)
        assert not settings.as_render_pass  # restored
    finally:
        scene.render.use_freestyle = False
        settings.linesets.remove(lineset)
    plain = guide_cache.read_frame(tmp_path / "plain", 3, ["lines", "FULL"])
    drawn = guide_cache.read_frame(tmp_path / "freestyle", 3, ["lines", "FULL"])
    assert plain["lines"].sum() == 0
    assert drawn["lines"].sum() >= 20  # the cube's outline
    assert np.allclose(plain["FULL"], drawn["FULL"], atol=1e-4)  # lines kept out of the light paths


def test_orientation_from_the_artists_aov(rendered, tmp_path):
    """Strokes along x written to a Color AOV on the cube become the cube's
    orientation; pixels without the AOV keep the computed one."""
    from tempera.app import guide_cache
    from tempera.engine import guides
    from tempera.blender.guide_render import GuideRenderError, render_guides

    scene = rendered["scene"]
    params = {"samples": 2, "ld12e_samples": 2, "masks": "objects", "orientation_aov": "stroke_dir"}
    with pytest.raises(GuideRenderError, match="Shader AOV 'stroke_dir' is not declared"):
        render_guides(scene, (3,), tmp_path / "missing", params)
    aov = scene.view_layers[0].aovs.add()
    aov.name, aov.type = "stroke_dir", "COLOR"
    material = scene.objects["MovingCube"].material_slots[0].material
    material.use_nodes = True
    node = material.node_tree.nodes.new("ShaderNodeOutputAOV")
    compat.set_aov_output_name(node, "stroke_dir")  # the AOV it writes
    node.inputs["Color"].default_value = (1.0, 0.0, 0.0, 1.0)  # along x
    try:
        render_guides(scene, (3,), tmp_path / "aov", params)
    finally:
        material.node_tree.nodes.remove(node)
        material.use_nodes = False
    frame = guide_cache.read_frame(tmp_path / "aov", 3, ["tensor", "mask.OB_MovingCube"])
    angle, coherence = guides.orientation(frame["tensor"], tensor=True)
    cube = frame["mask.OB_MovingCube"] > 0.5
    along_x = np.minimum(angle, np.pi - angle)[cube]
    assert cube.sum() > 50 and np.percentile(along_x, 90) < 0.05
    assert np.all(coherence[cube] > 0.99)
