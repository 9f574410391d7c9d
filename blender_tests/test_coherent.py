"""The coherent method from the panel (Method "Temporally Coherent (Bénard
2013)"): Add Keyframe from the frame's StyLit result or its render, Import
Key, the keyframe list, Stylize Animation one segment per step with the key
coming out as painted, Esc within a segment, and resume."""
import bpy
import numpy as np
import pytest
from fake_ui import modal_run
from guide_scene import FRAMES, SIZE

from test_stylize import exemplar, frame_files, scene  # noqa: F401 (fixtures)


@pytest.fixture
def coherent(scene, tmp_path):
    settings = scene.tempera
    settings.method = "TCIA"
    settings.keyframe_dir = str(tmp_path / "keys")
    settings.make_video = False
    settings.load_result = "IMAGE"
    return scene


def test_method_choice_and_keyframe_list_in_the_panel(coherent, tmp_path):
    from test_addon import _Recorder
    from tempera.blender.properties import METHOD_ITEMS

    assert ("TCIA", "Temporally Coherent (Bénard 2013)") == METHOD_ITEMS[1][:2]
    bpy.context.window.scene = coherent
    bpy.ops.tempera.import_keyframe(filepath=__file__, frame=FRAMES[0])
    calls = []
    bpy.types.TEMPERA_PT_output.draw(type("FakePanel", (), {"layout": _Recorder(calls)})(), bpy.context)
    props = [name for kind, name in calls if kind == "prop"]
    assert props[props.index("method") + 1:props.index("method") + 5] == ["painting", "mask", "keyframe_dir",
                                                                          "line_weight"]
    assert ("template_list", "keyframes") in calls
    operators = [name for kind, name in calls if kind == "operator"]
    assert operators.count("tempera.add_keyframe") == 2 and "tempera.import_keyframe" in operators
    coherent.tempera.method = "STYLIT"
    calls.clear()
    bpy.types.TEMPERA_PT_output.draw(type("FakePanel", (), {"layout": _Recorder(calls)})(), bpy.context)
    assert ("template_list", "keyframes") not in calls


def test_add_keyframe_paint_it_and_stylize_coherently(coherent, tmp_path):
    import tempera
    from tempera.blender.stylize_operator import StylizeRun

    scene, settings = coherent, coherent.tempera
    key_frame = FRAMES[1]
    scene.frame_set(key_frame)
    # No result and no guides yet: a clear error, nothing registered.
    with pytest.raises(RuntimeError, match=f"Frame {key_frame} has no StyLit result and no guides yet"):
        bpy.ops.tempera.add_keyframe()
    assert len(settings.keyframes) == 0
    assert bpy.ops.tempera.stylize(mode="FRAME") == {"FINISHED"}
    assert bpy.ops.tempera.add_keyframe() == {"FINISHED"}
    key_path = tmp_path / "keys" / f"key_{key_frame:04d}.png"
    stylit = tempera.read_image(str(tmp_path / "out" / "frames" / f"frame_{key_frame:04d}.png"))
    assert [(k.frame, k.painting) for k in settings.keyframes] == [(key_frame, str(key_path))]
    np.testing.assert_allclose(tempera.read_image(str(key_path)), stylit[:, :, :3], atol=1 / 255)

    # The artist paints over it in Blender (not saved yet): a red block.
    image = next(i for i in bpy.data.images if bpy.path.abspath(i.filepath) == str(key_path))
    pixels = np.array(image.pixels[:], np.float32).reshape(SIZE[1], SIZE[0], 4)
    pixels[10:30, 10:40, :3] = (0.9, 0.1, 0.1)  # Blender's rows go bottom-up
    image.pixels[:] = pixels.ravel()
    assert image.is_dirty

    run = StylizeRun.from_settings(scene, "ANIMATION")
    assert type(run).__name__ == "CoherentRun" and run.segments == [(FRAMES[0], key_frame), (key_frame, FRAMES[-1])]
    assert run.total == len(FRAMES) + 2
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out = tmp_path / "out" / "frames"
    painted = tempera.read_image(str(key_path))
    assert np.abs(painted[SIZE[1] - 30:SIZE[1] - 10, 10:40] - (0.9, 0.1, 0.1)).max() < 2 / 255  # saved first
    result = tempera.read_image(str(out / f"frame_{key_frame:04d}.png"))
    assert np.abs(result[:, :, :3] - painted[:, :, :3]).max() <= 1 / 255 + 1e-6  # the key as painted
    assert (tmp_path / "out" / "contact_sheet.png").is_file()

    again = StylizeRun.from_settings(scene, "ANIMATION")
    while not again.finished:
        again.step()
    assert [r["status"] for r in again.segment_results] == ["skipped", "skipped"]
    assert "3 already done" in again.summary()
    settings.line_weight = 4.0  # the line term (eq. 9) on the cache's line distance: both segments redone
    lines = StylizeRun.from_settings(scene, "ANIMATION")
    while not lines.finished:
        lines.step()
    assert [r["status"] for r in lines.segment_results] == ["stylized", "stylized"]


def test_import_key_and_remove(coherent, tmp_path):
    import tempera

    settings = coherent.tempera
    painting = tmp_path / "painted_elsewhere.png"
    tempera.write_image(str(painting), np.full((SIZE[1], SIZE[0], 3), 0.5, np.float32))
    with pytest.raises(RuntimeError, match="No key painting chosen"):
        bpy.ops.tempera.import_keyframe(filepath=str(tmp_path / "nothing.png"))
    assert bpy.ops.tempera.import_keyframe(filepath=str(painting), frame=FRAMES[2]) == {"FINISHED"}
    assert bpy.ops.tempera.import_keyframe(filepath=str(painting), frame=FRAMES[2]) == {"FINISHED"}  # re-pointed
    assert [(k.frame, k.painting) for k in settings.keyframes] == [(FRAMES[2], str(painting))]
    assert bpy.ops.tempera.remove_keyframe() == {"FINISHED"} and len(settings.keyframes) == 0


def test_esc_within_a_segment_writes_nothing_then_resume(coherent, tmp_path):
    from tempera.blender.stylize_operator import TEMPERA_OT_stylize, StylizeRun

    run = StylizeRun.from_settings(coherent, "ANIMATION")
    for _ in FRAMES:  # the guides
        run.step()

    def events(op):
        yield ("TIMER", "NOTHING")  # starts the segment in the worker
        yield ("ESC", "PRESS")

    results, _log, reports, timers, _op = modal_run(TEMPERA_OT_stylize, coherent, run, events, tick=0.02)
    assert results[-1] == {"CANCELLED"} and not timers
    assert "Stopped" in reports[-1][1]
    assert frame_files(tmp_path / "out" / "frames") == []  # nothing half-written
    rerun = StylizeRun.from_settings(coherent, "ANIMATION")
    while not rerun.finished:
        rerun.step()
    assert [r["status"] for r in rerun.segment_results] == ["stylized"]
    assert len(rerun.results) == len(FRAMES)


def test_temporal_noise_after_the_coherent_method(coherent, tmp_path):
    """Temporal Noise with Method "Temporally Coherent": the segments run,
    then every frame boils from the coherent frames into OUT/noisy."""
    import tempera
    from tempera.blender.stylize_operator import StylizeRun

    coherent.tempera.noise_level = 4  # f = 2.2
    run = StylizeRun.from_settings(coherent, "ANIMATION")
    assert type(run).__name__ == "CoherentRun" and run.total == 2 * len(FRAMES) + len(run.segments)
    while not run.finished:
        assert run.status_text()
        run.step()
    assert [r["status"] for r in run.segment_results] == ["stylized"]
    assert [r["status"] for r in run.noise_results] == ["made"] * len(FRAMES)
    for f in FRAMES:
        frame = tempera.read_image(str(tmp_path / "out" / "frames" / f"frame_{f:04d}.png"))
        boiled = tempera.read_image(str(tmp_path / "out" / "noisy" / f"frame_{f:04d}.png"))
        assert boiled.shape == frame.shape and np.abs(boiled - frame).mean() > 0.005, f


def test_layers_picked_from_collections_give_per_layer_frames_and_their_composite(coherent, tmp_path):
    """Layers (Bénard 2013 Fig. 10): two collections, the moving cube's and
    the backdrop's, each solved alone into OUT/frames/layers/NAME/ (RGBA, its
    collection's mask as alpha) and composited by depth into the frames."""
    import tempera
    from test_addon import _Recorder
    from tempera.app import guide_cache
    from tempera.blender.stylize_operator import StylizeRun

    scene, settings = coherent, coherent.tempera
    back = bpy.data.collections.new("Back")
    scene.collection.children.link(back)
    backdrop = bpy.data.objects["Backdrop"]
    back.objects.link(backdrop)
    scene.collection.objects.unlink(backdrop)
    bpy.context.window.scene = scene
    for _ in range(2):
        assert bpy.ops.tempera.add_tcia_layer() == {"FINISHED"}
    assert [l.collection.name for l in settings.tcia_layers] == ["Movers", "Back"]
    calls = []
    bpy.types.TEMPERA_PT_output.draw(type("FakePanel", (), {"layout": _Recorder(calls)})(), bpy.context)
    assert ("template_list", "tcia_layers") in calls and ("prop", "tcia_layer_order") in [c[:2] for c in calls]
    run = StylizeRun.from_settings(scene, "ANIMATION")
    assert run.layers == [("Movers", "mask.CO_Movers", None, []), ("Back", "mask.CO_Back", None, [])]
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out = tmp_path / "out" / "frames"
    for f in FRAMES:
        masks = guide_cache.read_frame(str(tmp_path / "guides"), f, ["mask.CO_Movers", "mask.CO_Back"])
        cube = tempera.read_image(str(out / "layers" / "Movers" / f"frame_{f:04d}.png"))
        wall = tempera.read_image(str(out / "layers" / "Back" / f"frame_{f:04d}.png"))
        frame = tempera.read_image(str(out / f"frame_{f:04d}.png"))
        assert cube.shape == (SIZE[1], SIZE[0], 4) and wall.shape == cube.shape
        assert np.abs(cube[:, :, 3] - masks["mask.CO_Movers"]).max() <= 1 / 255
        on_cube, on_wall = cube[:, :, 3] == 1, (cube[:, :, 3] == 0) & (wall[:, :, 3] == 1)
        assert on_cube.sum() > 50 and on_wall.sum() > 500, f
        # The cube is nearer: on top where it is, the wall elsewhere.
        assert np.abs(frame[on_cube][:, :3] - cube[on_cube][:, :3]).max() <= 1 / 255
        assert np.abs(frame[on_wall][:, :3] - wall[on_wall][:, :3]).max() <= 1 / 255
        assert np.abs(cube[on_cube][:, :3] - wall[on_cube][:, :3]).mean() > 0.01  # two solves, not one


def test_orientation_from_guides_reaches_the_job(coherent, tmp_path):
    """Orientation from Guides: the cache's tensor turns the patches
    (`--orientation`), so the frames differ from a run without it."""
    import tempera
    from tempera.blender.stylize_operator import StylizeRun

    def run(folder, orientation):
        coherent.tempera.output_dir = str(tmp_path / folder)
        coherent.tempera.tcia_orientation = orientation
        r = StylizeRun.from_settings(coherent, "ANIMATION")
        while not r.finished:
            r.step()
        assert r.orientation is orientation and [s["status"] for s in r.segment_results] == ["stylized"]
        return [tempera.read_image(str(tmp_path / folder / "frames" / f"frame_{f:04d}.png")) for f in FRAMES]

    plain, oriented = run("plain", False), run("oriented", True)
    assert max(np.abs(a - b).mean() for a, b in zip(plain, oriented)) > 0.005


def test_a_keyframe_of_one_layer(coherent, tmp_path):
    """A keyframe whose Layer is the cube's collection: at its frame the
    composite is the painting where the cube is (in front), the wall is
    solved without a key, and the shot splits there."""
    import tempera
    from tempera.app import guide_cache
    from tempera.blender.stylize_operator import StylizeRun

    scene, settings = coherent, coherent.tempera
    bpy.context.window.scene = scene
    assert bpy.ops.tempera.add_tcia_layer() == {"FINISHED"}  # Movers: the cube
    back = bpy.data.collections.new("Back")
    scene.collection.children.link(back)
    backdrop = bpy.data.objects["Backdrop"]
    back.objects.link(backdrop)
    scene.collection.objects.unlink(backdrop)
    assert bpy.ops.tempera.add_tcia_layer() == {"FINISHED"}
    painting = tmp_path / "cube_key.png"
    rng = np.random.default_rng(5)
    tempera.write_image(str(painting), rng.uniform(0, 1, (SIZE[1], SIZE[0], 3)).astype(np.float32))
    assert bpy.ops.tempera.import_keyframe(filepath=str(painting), frame=FRAMES[1]) == {"FINISHED"}
    settings.keyframes[0].layer = bpy.data.collections["Movers"]
    run = StylizeRun.from_settings(scene, "ANIMATION")
    assert run.keys == [] and run.layers[0][3] == [(FRAMES[1], str(painting), None)]
    assert run.segments == [(FRAMES[0], FRAMES[1]), (FRAMES[1], FRAMES[-1])]
    while not run.finished:
        run.step()
    out = tempera.read_image(str(tmp_path / "out" / "frames" / f"frame_{FRAMES[1]:04d}.png"))[:, :, :3]
    cube = guide_cache.read_frame(str(tmp_path / "guides"), FRAMES[1], ["mask.CO_Movers"])["mask.CO_Movers"] == 1
    key = tempera.read_image(str(painting))[:, :, :3]
    assert cube.sum() > 50
    assert np.abs(out[cube] - key[cube]).max() <= 1 / 255 + 1e-6
    assert np.abs(out[~cube] - key[~cube]).mean() > 0.1  # the wall is not the key
    settings.keyframes[0].layer = bpy.data.collections.new("Elsewhere")
    with pytest.raises(ValueError, match="Keyframe 3 is of the collection 'Elsewhere', which is not in the Layers"):
        StylizeRun.from_settings(scene, "ANIMATION")
