"""Issue 18 in Blender: guide rendering keeps every finished frame when
interrupted, leaves nothing in the system's temporary folder, refuses bad
parameters before rendering, and light path expressions are never compiled
while the panel draws."""
import os
import tempfile
from pathlib import Path

import bpy
import pytest
from guide_scene import FRAMES, PARAMS, build_scene, remove_scene


@pytest.fixture(scope="module")
def scene():
    scene = build_scene("Hardening test")
    shown = bpy.context.window.scene.name
    bpy.context.window.scene = scene
    yield scene
    if shown in bpy.data.scenes:
        bpy.context.window.scene = bpy.data.scenes[shown]
    remove_scene(bpy.data.scenes["Hardening test"])


def params(**extra):
    from tempera.app import guide_cache

    return {**guide_cache.DEFAULT_PARAMS, **PARAMS, **extra}


@pytest.fixture
def private_tmp(tmp_path):
    """The system temporary folder of this test alone (other processes share /tmp)."""
    folder = tmp_path / "systmp"
    folder.mkdir()
    saved, tempfile.tempdir = tempfile.tempdir, str(folder)
    yield folder
    tempfile.tempdir = saved


def test_interrupted_render_keeps_each_finished_frame(scene, tmp_path, private_tmp):
    from tempera.app import guide_cache
    from tempera.blender.guide_render import WORK_PREFIX, render_guides

    cache = tmp_path / "guides"
    (cache / f"{WORK_PREFIX}1-deadbeef").mkdir(parents=True)  # left by a run killed with -9
    (cache / f"{WORK_PREFIX}1-deadbeef" / "main_7.exr").write_bytes(b"x")
    messages = []

    def progress(done, total, message):
        messages.append(message)
        if message == f"rendering frame {FRAMES[2]}":
            raise KeyboardInterrupt  # Ctrl-C as the third frame of three starts rendering

    with pytest.raises(KeyboardInterrupt):
        render_guides(scene, FRAMES, cache, params(), progress)
    manifest = guide_cache.read_manifest(cache)
    # The first frame was finished (its successor rendered) before the interruption: it is in the cache.
    assert sorted(manifest["frames"]) == [str(FRAMES[0])]
    assert guide_cache.is_frame_current(cache, manifest, FRAMES[0], manifest["frames"][str(FRAMES[0])]["key"])
    assert sorted(p.name for p in cache.iterdir()) == ["frame_0002.exr", "manifest.json"]
    assert list(private_tmp.iterdir()) == []
    # The rerun renders only the others, and the same guides as an uninterrupted run.
    report = render_guides(scene, FRAMES, cache, params())
    assert report["rendered"] == list(FRAMES[1:]) and report["skipped"] == [FRAMES[0]]
    whole = render_guides(scene, FRAMES, tmp_path / "whole", params())
    assert whole["rendered"] == list(FRAMES)
    import numpy as np

    for f in FRAMES:
        a = guide_cache.read_frame(cache, f, ["FULL", "occlusion_backward", "occlusion_forward"])
        b = guide_cache.read_frame(tmp_path / "whole", f, ["FULL", "occlusion_backward", "occlusion_forward"])
        for name in a:
            np.testing.assert_array_equal(a[name], b[name], err_msg=f"{name} of frame {f}")


def test_corrupt_cache_frame_and_manifest_are_redone(scene, tmp_path):
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides

    cache = tmp_path / "guides"
    render_guides(scene, FRAMES[:1], cache, params())
    path = guide_cache.frame_path(cache, FRAMES[0])
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])  # truncated
    assert render_guides(scene, FRAMES[:1], cache, params())["rendered"] == [FRAMES[0]]
    (cache / "manifest.json").write_text("{ not json")
    report = render_guides(scene, FRAMES[:1], cache, params())
    assert report["rendered"] == [FRAMES[0]]
    assert any("damaged" in w for w in report["warnings"]), report["warnings"]
    assert list(cache.glob("manifest.json.corrupt-*"))


@pytest.mark.parametrize("bad, match", [({"tensor_sigma": 1e9}, "tensor_sigma"), ({"samples": 0}, "samples"),
                                        ({"occlusion_epsilon": float("nan")}, "occlusion_epsilon"),
                                        ({"lpe": ["(" * 60000 + "L" + ")" * 60000]}, "at most 1000"),
                                        ({"lpe": ["L.*D.{30}E"]}, "too complex")])
def test_bad_parameters_are_refused_before_rendering(scene, tmp_path, bad, match):
    from tempera.blender.guide_render import GuideRenderError, render_guides

    with pytest.raises((ValueError, GuideRenderError), match=match):
        render_guides(scene, FRAMES[:1], tmp_path / "g", params(**bad))
    assert not (tmp_path / "g").exists()


def test_frames_blender_cannot_render_are_refused(scene, tmp_path):
    from tempera.blender.guide_render import render_guides

    with pytest.raises(ValueError, match="outside 0-1048574"):
        render_guides(scene, [1048575], tmp_path / "g", params())
    with pytest.raises(ValueError, match="frames"):
        render_guides(scene, range(10**11), tmp_path / "g", params())


def test_panel_draw_never_compiles_light_path_expressions(scene, monkeypatch):
    import tempera.tracer.lpe
    from tempera.blender import guide_operator

    compiled = []
    monkeypatch.setattr(guide_operator, "check_lpe_expressions", lambda e: compiled.append(e))
    monkeypatch.setattr(tempera.tracer.lpe._native, "check_lpe", lambda e: compiled.append(e))
    settings = scene.tempera
    settings.guide_lpe = "L.*D.{11}E; LDE"  # the update callback checks it, outside draw()
    try:
        compiled.clear()
        text, icon = guide_operator.cache_status(scene)
        assert compiled == []
    finally:
        settings.guide_lpe = ""


def test_malformed_expression_shows_in_the_status_without_compiling(scene):
    from tempera.blender.guide_operator import cache_status

    settings = scene.tempera
    settings.guide_lpe = "L.*D.{30}E"
    try:
        text, icon = cache_status(scene)
    finally:
        settings.guide_lpe = ""
    assert icon == "ERROR" and "too complex" in text
