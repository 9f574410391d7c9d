"""Stylize Frame / Stylize Animation (tempera.blender.stylize_operator) end
to end on the tiny scene of guide_scene.py: the exemplar is the same scene's
frame 2 with a painting made from its render, so frame 2 must come back as
the painting; the moving cube's frames must carry the painting's colours.
Cancelling, resuming and the errors an artist can run into are checked
through the operator (its report) and the job (its exception)."""
import subprocess
import time

import bpy
import numpy as np
import pytest
from fake_ui import modal_run
from tempera.blender import compat
from guide_scene import FRAMES, PARAMS, SIZE, build_scene, remove_scene

SCENE = "Stylize test"


def psnr(a, b):
    mse = float(np.mean((np.asarray(a, np.float64) - np.asarray(b, np.float64)) ** 2))
    return 10 * np.log10(1.0 / max(mse, 1e-12))


@pytest.fixture(scope="module")
def exemplar(tmp_path_factory):
    """(painting path, guide cache) of the scene's frame 2: a two-tone drawing
    whose colour follows the render's brightness, with a stroke texture."""
    import tempera
    from tempera.app import guide_cache
    from tempera.blender.guide_render import render_guides
    from tempera.engine.guides import tonemap

    folder = tmp_path_factory.mktemp("exemplar")
    scene = build_scene("Stylize exemplar")
    try:
        render_guides(scene, [FRAMES[0]], folder / "guides", dict(guide_cache.DEFAULT_PARAMS, **PARAMS))
    finally:
        remove_scene(scene)
    full = tonemap(guide_cache.read_frame(folder / "guides", FRAMES[0], ["FULL"])["FULL"]).mean(axis=2)
    rng = np.random.default_rng(3)
    strokes = np.repeat(rng.uniform(0.85, 1.0, (full.shape[0], 1)), full.shape[1], axis=1)  # horizontal streaks
    ink, paper = np.array([0.15, 0.2, 0.6]), np.array([1.0, 0.9, 0.6])
    painting = (full[:, :, None] * paper + (1 - full[:, :, None]) * ink) * strokes[:, :, None]
    path = folder / "painting.png"
    tempera.write_image(str(path), np.ascontiguousarray(painting, np.float32))
    return path, folder / "guides"


@pytest.fixture
def scene(tmp_path, exemplar):
    """The test scene, shown in the window, set up to stylize frames 2-4 into tmp_path."""
    scene = build_scene(SCENE)
    shown = bpy.context.window.scene.name
    bpy.context.window.scene = scene
    settings = scene.tempera
    settings.exemplar_source = "CUSTOM"
    settings.exemplar_style, settings.exemplar_guide_dir = str(exemplar[0]), str(exemplar[1])
    settings.output_dir, settings.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    settings.guide_frame_range = "CUSTOM"
    settings.guide_frame_start, settings.guide_frame_end = FRAMES[0], FRAMES[-1]
    settings.guide_samples = PARAMS["samples"]
    settings.quality = "preview"
    settings.make_video = True
    yield scene
    if shown in bpy.data.scenes:
        bpy.context.window.scene = bpy.data.scenes[shown]
    if SCENE + " Tempera" in bpy.data.scenes:
        bpy.data.scenes.remove(bpy.data.scenes[SCENE + " Tempera"])
    remove_scene(bpy.data.scenes[SCENE])


def frame_files(folder):
    return sorted(p.name for p in folder.glob("*") if p.name.startswith(("frame_", ".")) or "tmp" in p.name)


def test_stylize_animation_end_to_end(scene, tmp_path, exemplar):
    import tempera

    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out = tmp_path / "out"
    frames = out / "frames"
    assert frame_files(frames) == [f"frame_{f:04d}.png" for f in FRAMES]
    painting = tempera.read_image(str(exemplar[0]))[:, :, :3]
    images = {f: tempera.read_image(str(frames / f"frame_{f:04d}.png"))[:, :, :3] for f in FRAMES}
    assert all(image.shape == (SIZE[1], SIZE[0], 3) for image in images.values())
    # Frame 2 is the exemplar itself: its guides match, the painting comes back.
    assert psnr(images[FRAMES[0]], painting) > 24
    # Later frames are made of the painting's colours (the ink-to-paper ramp),
    # not of anything new: every pixel lies near a colour the painting has.
    palette = painting.reshape(-1, 3)[::7]
    for f in FRAMES[1:]:
        pixels = images[f].reshape(-1, 3)
        nearest = np.min(np.linalg.norm(pixels[:, None, :] - palette[None, :, :], axis=2), axis=1)
        assert np.mean(nearest) < 0.05, f
    # Outputs: contact sheet, video of every frame, the sequencer scene.
    assert (out / "contact_sheet.png").is_file()
    video = out / "stylized.mp4"
    count = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
                            "-show_entries", "stream=nb_read_frames", "-of", "csv=p=0", str(video)],
                           capture_output=True, text=True, check=True).stdout.strip()
    assert int(count) == len(FRAMES)
    result = bpy.data.scenes[SCENE + " Tempera"]
    strip = compat.sequencer_strips(result.sequence_editor)[0]
    assert [e.filename for e in strip.elements] == [f"frame_{f:04d}.png" for f in FRAMES]
    assert (result.frame_start, result.frame_end) == (FRAMES[0], FRAMES[-1])


def test_stylize_frame_does_only_the_current_frame(scene, tmp_path):
    scene.frame_set(FRAMES[1])
    assert bpy.ops.tempera.stylize(mode="FRAME") == {"FINISHED"}
    assert frame_files(tmp_path / "out" / "frames") == [f"frame_{FRAMES[1]:04d}.png"]
    assert f"Tempera frames {FRAMES[1]}" in bpy.data.images


def hold_until_esc(job, op):
    """From now on the solver's progress reports wait for Esc, so that Esc
    surely comes while a frame is being stylized, however fast the machine."""
    run_frame = job.run_frame

    def held_run_frame(index, progress=None):
        def held(fraction):
            deadline = time.monotonic() + 60
            while not op._stop and time.monotonic() < deadline:
                time.sleep(0.01)
            return progress(fraction)

        return run_frame(index, held)

    job.run_frame = held_run_frame


def test_esc_during_the_second_frame_keeps_the_first_and_a_rerun_completes(scene, tmp_path):
    from tempera.blender.stylize_operator import TEMPERA_OT_stylize, StylizeRun

    run = StylizeRun.from_settings(scene)

    def events(op):
        """Ticks render the guides and stylize the first frame in the worker;
        once it is collected, one tick starts the second frame and Esc
        comes at once, in the middle of it."""
        for _ in range(400):
            yield ("TIMER", "NOTHING")
            if op._future is None and run.index == len(FRAMES) + 1:
                break
        hold_until_esc(run.job, op)
        yield ("TIMER", "NOTHING")
        yield ("ESC", "PRESS")

    results, log, reports, timers, op = modal_run(TEMPERA_OT_stylize, scene, run, events, tick=0.05)
    assert results[-1] == {"CANCELLED"} and not timers and __import__('tempera.blender.job_operator', fromlist=['x']).running_job() is None
    assert reports[-1][0] == {"WARNING"} and "1 stylized, 2 not done" in reports[-1][1], reports
    frames = tmp_path / "out" / "frames"
    assert frame_files(frames) == [f"frame_{FRAMES[0]:04d}.png"]  # no partial or temporary file
    statuses = [entry[1] for entry in log if entry[0] == "status"]
    assert "Tempera: stylizing frame 2/3 (Esc to stop)" in statuses, statuses  # no ETA from one frame

    first_bytes = (frames / f"frame_{FRAMES[0]:04d}.png").read_bytes()
    rerun = StylizeRun.from_settings(scene)
    while not rerun.finished:
        rerun.step()
    assert [r["status"] for r in rerun.results] == ["skipped", "stylized", "stylized"]
    assert (frames / f"frame_{FRAMES[0]:04d}.png").read_bytes() == first_bytes
    assert frame_files(frames) == [f"frame_{f:04d}.png" for f in FRAMES]


def test_missing_exemplar_is_reported(scene, tmp_path):
    from tempera.blender.stylize_operator import StylizeRun

    scene.tempera.exemplar_style = str(tmp_path / "no_such_painting.png")
    with pytest.raises(RuntimeError, match="no_such_painting.png' does not exist"):
        bpy.ops.tempera.stylize(mode="ANIMATION")
    with pytest.raises(FileNotFoundError, match="no_such_painting.png"):
        StylizeRun.from_settings(scene)
    assert not (tmp_path / "guides").exists()  # refused before anything was rendered


def test_painting_of_another_shape_than_its_guides_is_reported(scene, tmp_path):
    import tempera
    from tempera.blender.stylize_operator import StylizeRun

    square = tmp_path / "square.png"
    tempera.write_image(str(square), np.full((40, 40, 3), 0.5, np.float32))
    scene.tempera.exemplar_style = str(square)
    with pytest.raises(RuntimeError, match="40"):
        bpy.ops.tempera.stylize(mode="FRAME")
    run = StylizeRun.from_settings(scene, "FRAME")
    with pytest.raises(ValueError, match="40"):
        while not run.finished:
            run.step()
    assert not list((tmp_path / "out").rglob("*.png"))


def test_motion_blur_is_reported(scene):
    scene.render.use_motion_blur = True
    with pytest.raises(RuntimeError, match="[Mm]otion blur"):
        bpy.ops.tempera.stylize(mode="FRAME")


def test_temporal_noise_boils_the_coherent_frames_where_the_map_says(scene, tmp_path):
    """Temporal Noise (Color Me Noisy) after the coherent pass: OUT/noisy holds
    frames that differ from the coherent ones and from each other; with the
    moving cube's mask as the map, the pixels off the cube stay the coherent
    frame bit for bit; a rerun finds every frame current."""
    import tempera
    from tempera.app import guide_cache
    from tempera.blender.stylize_operator import StylizeRun

    settings = scene.tempera
    settings.noise_level = 6  # f = 3.1
    settings.make_video = False
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out = tmp_path / "out"
    coherent = {f: tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png")) for f in FRAMES}
    noisy = {f: tempera.read_image(str(out / "noisy" / f"frame_{f:04d}.png")) for f in FRAMES}
    for f in FRAMES:
        assert noisy[f].shape == coherent[f].shape and np.abs(noisy[f] - coherent[f]).mean() > 0.005, f
    assert np.abs(noisy[FRAMES[0]] - noisy[FRAMES[1]]).mean() > 0.005
    strip = compat.sequencer_strips(bpy.data.scenes[SCENE + " Tempera"].sequence_editor)[0]
    assert strip.directory.rstrip("/\\").endswith("noisy")  # the noisy sequence is the result shown

    settings.noise_map_source = "OBJECT"
    settings.noise_map_object = bpy.data.objects["MovingCube"]
    run = StylizeRun.from_settings(scene)
    while not run.finished:
        run.step()
    assert [r["status"] for r in run.results] == ["skipped"] * len(FRAMES)
    assert [r["status"] for r in run.noise_results] == ["made"] * len(FRAMES)  # a new map: boiled again
    for f in FRAMES:
        mask = guide_cache.read_frame(tmp_path / "guides", f, ["mask.OB_MovingCube"])["mask.OB_MovingCube"]
        off = mask.reshape(mask.shape[0], mask.shape[1], -1)[:, :, 0] * 3.1 < 1.0
        assert off.any() and (~off).any()
        boiled = tempera.read_image(str(out / "noisy" / f"frame_{f:04d}.png"))
        np.testing.assert_array_equal(boiled[off], coherent[f][off])
    rerun = StylizeRun.from_settings(scene)
    while not rerun.finished:
        rerun.step()
    assert [r["status"] for r in rerun.noise_results] == ["skipped"] * len(FRAMES)
    # Guided Noise: a new setting (in the key), so every frame is boiled again.
    settings.noise_guided = True
    guided = StylizeRun.from_settings(scene)
    while not guided.finished:
        guided.step()
    assert [r["status"] for r in guided.noise_results] == ["made"] * len(FRAMES)
