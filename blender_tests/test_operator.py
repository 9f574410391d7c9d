"""The Render Guides operator (tempera.blender.guide_operator) headless, on the
tiny scene of guide_scene.py: settings -> parameters and frames, a custom
range rendered by bpy.ops.tempera.render_guides(), reruns, errors, the
panel's cache line and the settings in a saved .blend."""
import time

import bpy
import pytest
from fake_ui import modal_run
from guide_scene import build_scene, remove_scene

GUIDE_SETTINGS = {"guide_frame_range": "CUSTOM", "guide_frame_start": 2, "guide_frame_end": 3,
                  "guide_samples": 4, "guide_masks": "OBJECTS"}


@pytest.fixture(scope="module")
def scene():
    """The test scene, shown in the window (bpy.ops works on context.scene)."""
    scene = build_scene("Operator test")
    shown = bpy.context.window.scene.name
    bpy.context.window.scene = scene
    yield scene
    # By name: test_settings_survive_save_and_reload loads a file, which
    # replaces every data-block (and Python reference to one).
    if shown in bpy.data.scenes:
        bpy.context.window.scene = bpy.data.scenes[shown]
    if "Operator test" in bpy.data.scenes:
        remove_scene(bpy.data.scenes["Operator test"])


@pytest.fixture(scope="module")
def first_run(scene, tmp_path_factory):
    """The operator run on frames 2-3 into a fresh absolute folder."""
    from tempera.app import guide_cache

    cache = tmp_path_factory.mktemp("operator") / "guides"
    settings = scene.tempera
    for name, value in GUIDE_SETTINGS.items():
        setattr(settings, name, value)
    settings.guide_dir = str(cache)
    start = time.monotonic()
    result = bpy.ops.tempera.render_guides()
    return {"result": result, "cache": cache, "seconds": time.monotonic() - start,
            "manifest": guide_cache.read_manifest(cache)}


def test_default_settings_are_the_default_params():
    from tempera.app import guide_cache
    from tempera.blender.guide_operator import guide_params

    settings = bpy.context.scene.tempera
    assert settings.guide_dir == "//tempera/guides/"
    assert settings.guide_frame_range == "SCENE"
    assert guide_params(settings) == guide_cache.DEFAULT_PARAMS


def test_settings_map_to_params_and_frames(scene):
    from tempera.blender.guide_operator import guide_frames, guide_params

    settings = scene.tempera
    saved = {name: getattr(settings, name) for name in type(settings).__annotations__ if name.startswith("guide_")}
    try:
        settings.guide_samples = 7
        settings.guide_occlusion_epsilon = 3.5
        settings.guide_line_d_max = 6
        settings.guide_masks = "COLLECTIONS"
        settings.guide_orientation_aov = " stroke_dir "
        params = guide_params(settings)
        assert params["orientation_aov"] == "stroke_dir"
        assert (params["samples"], params["ld12e_samples"]) == (7, 7)
        assert (params["occlusion_epsilon"], params["line_d_max"], params["masks"]) == (3.5, 6.0, "collections")
        scene.frame_set(4)
        settings.guide_frame_range = "CURRENT"
        assert guide_frames(scene, settings) == [4]
        settings.guide_frame_range = "SCENE"
        assert guide_frames(scene, settings) == [1, 2, 3, 4, 5]
        settings.guide_frame_range = "CUSTOM"
        settings.guide_frame_start, settings.guide_frame_end = 3, 8
        assert guide_frames(scene, settings) == [3, 4, 5, 6, 7, 8]
        settings.guide_frame_start = 10  # End follows: the range never is empty
        assert (settings.guide_frame_start, settings.guide_frame_end) == (10, 10)
        settings.guide_frame_end = 9
        assert (settings.guide_frame_start, settings.guide_frame_end) == (9, 9)
    finally:
        for name, value in saved.items():
            setattr(settings, name, value)
        scene.frame_set(1)


def test_relative_folder_needs_a_saved_file(tmp_path):
    from tempera.blender.guide_operator import resolve_guide_dir

    with pytest.raises(ValueError, match="Save the .blend file first"):
        resolve_guide_dir("//tempera/guides/", blend_filepath="")
    with pytest.raises(ValueError, match="Set a Guide Folder"):
        resolve_guide_dir("  ", blend_filepath="")
    blend = tmp_path / "shot.blend"
    assert resolve_guide_dir("//tempera/guides/", blend_filepath=str(blend)) == str(tmp_path / "tempera" / "guides")
    assert resolve_guide_dir(str(tmp_path / "abs"), blend_filepath="") == str(tmp_path / "abs")


def test_operator_renders_a_custom_range(first_run):
    cache = first_run["cache"]
    assert first_run["result"] == {"FINISHED"}
    assert sorted(p.name for p in cache.iterdir()) == ["frame_0002.exr", "frame_0003.exr", "manifest.json"]
    manifest = first_run["manifest"]
    assert manifest["frame_range"] == [2, 3] and sorted(manifest["frames"]) == ["2", "3"]
    assert manifest["params"]["samples"] == 4 and manifest["params"]["masks"] == "objects"
    assert not [g for g in manifest["guides"] if g.startswith("mask.CO_")]


def test_second_run_skips_current_frames(scene, first_run):
    cache = first_run["cache"]
    mtimes = {p.name: p.stat().st_mtime_ns for p in cache.iterdir()}
    start = time.monotonic()
    assert bpy.ops.tempera.render_guides() == {"FINISHED"}
    seconds = time.monotonic() - start
    assert {p.name: p.stat().st_mtime_ns for p in cache.iterdir()} == mtimes
    assert seconds < max(1.0, first_run["seconds"] / 4), (seconds, first_run["seconds"])


def test_panel_line_counts_current_frames(scene, first_run):
    from tempera.blender.guide_operator import cache_status
    from tempera.blender.guide_render import scene_fingerprint

    # cache_status takes one fingerprint for the whole range: they differ only by the frame.
    first = scene_fingerprint(scene, 2)
    for f in (3, 5):
        assert scene_fingerprint(scene, f) == dict(first, frame=f)
    settings = scene.tempera
    assert cache_status(scene) == ("2/2 frames cached and current", "CHECKMARK")
    settings.guide_frame_end = 4
    try:
        assert cache_status(scene) == ("2/3 frames cached and current", "INFO")
    finally:
        settings.guide_frame_end = 3
    settings.guide_samples = 5  # other parameters: nothing in the cache is current
    try:
        assert cache_status(scene)[0] == "0/2 frames cached and current"
    finally:
        settings.guide_samples = 4
    backdrop = scene.objects["Backdrop"]
    backdrop.location.z += 1  # a changed scene
    try:
        assert cache_status(scene)[0] == "0/2 frames cached and current"
    finally:
        backdrop.location.z -= 1
    assert cache_status(scene)[0] == "2/2 frames cached and current"


def test_job_steps_one_frame_at_a_time(scene, tmp_path):
    """The modal run's step, stopped after the first frame (as Esc does):
    that frame stays in the cache, the next run renders only the rest."""
    from tempera.app import guide_cache
    from tempera.blender.guide_operator import GuideJob

    settings = scene.tempera
    saved = settings.guide_dir
    settings.guide_dir = str(tmp_path / "guides")
    try:
        job = GuideJob.from_settings(scene)
        assert job.frames == [2, 3] and job.eta_seconds() is None
        assert job.status_text() == "Tempera: guides frame 1/2 (Esc to stop)"
        fractions = []
        job.step(fractions.append)
        assert fractions[-1] == 1.0 and job.index == 1 and job.rendered == [2]
        # One rendered frame (it also paid Cycles' start-up) gives no ETA yet.
        assert job.status_text() == "Tempera: guides frame 2/2 (Esc to stop)"
        assert job.eta_seconds() is None
        assert "1 not done" in job.summary()
        assert sorted(guide_cache.read_manifest(tmp_path / "guides")["frames"]) == ["2"]
        rerun = GuideJob.from_settings(scene)
        while not rerun.finished:
            rerun.step()
        assert rerun.skipped == [2] and rerun.rendered == [3]
    finally:
        settings.guide_dir = saved


def _modal_run(scene, events, after_start=None):
    from tempera.blender.guide_operator import TEMPERA_OT_render_guides, GuideJob

    return modal_run(TEMPERA_OT_render_guides, scene, GuideJob.from_settings(scene), events, after_start)


def test_modal_steps_show_progress_and_finish(scene, tmp_path):
    settings = scene.tempera
    saved = settings.guide_dir
    settings.guide_dir = str(tmp_path / "guides")
    try:
        events = [("MOUSEMOVE", "NOTHING"), ("TIMER", "NOTHING"), ("TIMER", "NOTHING"), ("TIMER", "NOTHING")]
        results, log, reports, timers, op = _modal_run(scene, events)
    finally:
        settings.guide_dir = saved
    assert results == [{"PASS_THROUGH"}, {"PASS_THROUGH"}, {"FINISHED"}]
    statuses = [entry[1] for entry in log if entry[0] == "status"]
    assert statuses[0] == "Tempera: guides frame 1/2 (Esc to stop)"
    assert statuses[1] == "Tempera: guides frame 2/2 (Esc to stop)" and statuses[-1] is None
    assert ("progress_update", 1) in log and log[-2:] == [("progress_end",), ("status", None)]
    assert not timers and __import__('tempera.blender.job_operator', fromlist=['x']).running_job() is None
    assert reports == [({"INFO"}, f"Tempera guides: 2 rendered in {tmp_path / 'guides'}")]
    assert sorted(p.name for p in (tmp_path / "guides").glob("*.exr")) == ["frame_0002.exr", "frame_0003.exr"]


def test_modal_esc_stops_after_the_current_frame(scene, tmp_path):
    settings = scene.tempera
    saved = settings.guide_dir
    settings.guide_dir = str(tmp_path / "guides")
    try:
        results, log, reports, timers, _ = _modal_run(scene, [("TIMER", "NOTHING"), ("ESC", "PRESS")])
    finally:
        settings.guide_dir = saved
    assert results == [{"PASS_THROUGH"}, {"CANCELLED"}]
    assert not timers and ("progress_end",) in log
    assert reports[0][0] == {"WARNING"} and "1 rendered, 1 not done" in reports[0][1]
    assert sorted(p.name for p in (tmp_path / "guides").glob("*.exr")) == ["frame_0002.exr"]


def test_modal_error_is_reported_and_cleans_up(scene, tmp_path):
    settings = scene.tempera
    saved = settings.guide_dir
    settings.guide_dir = str(tmp_path / "guides")
    try:
        def motion_blur_on():  # after the checks of the start, as if the artist switched it on mid-run
            scene.render.use_motion_blur = True

        results, log, reports, timers, op = _modal_run(scene, [("TIMER", "NOTHING")], motion_blur_on)
    finally:
        scene.render.use_motion_blur = False
        settings.guide_dir = saved
    assert results == [{"CANCELLED"}]
    assert not timers and ("progress_end",) in log and log[-1] == ("status", None)
    assert __import__('tempera.blender.job_operator', fromlist=['x']).running_job() is None
    assert len(reports) == 1 and reports[0][0] == {"ERROR"}
    assert reports[0][1].startswith("Guides of frame 2 failed: Motion blur is on")


def test_motion_blur_is_reported_not_raised(scene, tmp_path):
    from tempera.blender.guide_operator import render_guide_frame
    from tempera.blender.guide_render import GuideRenderError

    settings = scene.tempera
    saved = settings.guide_dir
    settings.guide_dir = str(tmp_path / "guides")
    scene.render.use_motion_blur = True
    try:
        # An ERROR report of an operator called from Python becomes a RuntimeError
        # carrying the message (in the UI: the message, no traceback).
        with pytest.raises(RuntimeError, match="Motion blur is on"):
            bpy.ops.tempera.render_guides()
        with pytest.raises(GuideRenderError, match="Motion blur is on"):
            render_guide_frame(scene, 2, tmp_path / "guides", {"samples": 2, "ld12e_samples": 2})
        from tempera.blender.guide_operator import cache_status
        text, icon = cache_status(scene)
        assert icon == "ERROR" and "Motion blur" in text
    finally:
        scene.render.use_motion_blur = False
        settings.guide_dir = saved
    assert not (tmp_path / "guides").exists()
    assert bpy.types.TEMPERA_OT_render_guides.poll(bpy.context)  # not left "running"


def test_settings_survive_save_and_reload(tmp_path):
    """Last in this module: loading the file replaces the fixture's scene."""
    blend = tmp_path / "guides.blend"
    settings = bpy.context.scene.tempera
    values = {"guide_dir": "//cache/shot_010/", "guide_frame_range": "CUSTOM", "guide_frame_start": 12,
              "guide_frame_end": 48, "guide_samples": 32, "guide_occlusion_epsilon": 1.5,
              "guide_line_d_max": 15.0, "guide_masks": "NONE"}
    for name, value in values.items():
        setattr(settings, name, value)
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    settings.guide_dir, settings.guide_frame_range, settings.guide_samples = "//other/", "CURRENT", 8
    settings.guide_masks = "OBJECTS"
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    loaded = bpy.context.scene.tempera
    assert {name: getattr(loaded, name) for name in values} == values
