"""Issue 18, part 1: what the artist sees, with the real operators.

The result is shown (Image Editor, the result's sequencer scene), kept on
save and reloaded on a rerun; the result scene shows paint as painted
(Standard view, checked in rendered pixels); one job runs at a time; long
runs ask first; the ETA waits until it means something; the exemplar has a
thumbnail, an image-only picker, and buttons for the painting template and
for registering a photo of it."""
import os

import bpy
import numpy as np
import pytest
from guide_scene import FRAMES, PARAMS, build_scene, remove_scene

SCENE = "Journey test"


@pytest.fixture
def scene(tmp_path):
    scene = build_scene(SCENE)
    shown = bpy.context.window.scene.name
    bpy.context.window.scene = scene
    settings = scene.tempera
    settings.output_dir, settings.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    settings.guide_frame_range = "CUSTOM"
    settings.guide_frame_start, settings.guide_frame_end = FRAMES[0], FRAMES[-1]
    settings.guide_samples = PARAMS["samples"]
    settings.quality = "preview"
    yield scene
    bpy.context.window.scene = bpy.data.scenes[shown]
    if SCENE + " Tempera" in bpy.data.scenes:
        bpy.data.scenes.remove(bpy.data.scenes[SCENE + " Tempera"])
    remove_scene(bpy.data.scenes[SCENE])


@pytest.fixture
def image_editor():
    """An area of the window turned into an Image Editor for the test."""
    area = bpy.context.window.screen.areas[0]
    saved = area.type
    area.type = "IMAGE_EDITOR"
    yield area
    area.type = saved


def test_stylize_frame_shows_its_frame_in_the_image_editor_and_reloads_on_rerun(scene, tmp_path, image_editor):
    import tempera

    scene.frame_set(FRAMES[1])
    assert bpy.ops.tempera.stylize(mode="FRAME") == {"FINISHED"}
    image = image_editor.spaces.active.image
    assert image is not None and image.name == f"Tempera frames {FRAMES[1]}"
    assert image.use_fake_user  # kept when the file is saved, even if no editor shows it
    path = tmp_path / "out" / "frames" / f"frame_{FRAMES[1]:04d}.png"
    other = bpy.data.images.load(str(path), check_existing=False)  # the artist opened the file too
    before = np.array(other.pixels[:]).copy()
    scene.tempera.seed = 99  # another result for the rerun
    assert bpy.ops.tempera.stylize(mode="FRAME") == {"FINISHED"}
    on_disk = tempera.read_image(str(path))[::-1, :, :3]  # Blender's rows run bottom-up
    shown = np.array(other.pixels[:]).reshape(on_disk.shape[0], on_disk.shape[1], 4)[:, :, :3]
    assert not np.allclose(shown, before.reshape(shown.shape[0], shown.shape[1], 4)[:, :, :3])
    np.testing.assert_allclose(shown, on_disk, atol=1.5 / 255)
    bpy.data.images.remove(other)


def test_result_scene_is_shown_kept_and_standard(scene, tmp_path):
    from tempera import write_image
    from tempera.blender import results

    paths = []
    for f in FRAMES:
        path = tmp_path / f"frame_{f:04d}.png"
        write_image(str(path), np.full((48, 64, 3), 0.5, np.float32))
        paths.append(str(path))
    result = results.load(scene, paths, list(FRAMES), "SEQUENCER")
    where = results.show(bpy.context, result, "SEQUENCER", interactive=True)
    try:
        assert bpy.context.window.scene == result and result.name in where and "Space" in where
        assert result.view_settings.view_transform == "Standard" and result.view_settings.look == "None"
        assert result.use_fake_user
        # The Tempera panel is not offered in the result scene.
        assert not bpy.types.TEMPERA_PT_output.poll(bpy.context)
    finally:
        bpy.context.window.scene = scene
    assert bpy.types.TEMPERA_PT_output.poll(bpy.context)


def test_paper_keeps_its_colour_in_the_result_scene(scene, tmp_path):
    """Filmic dimmed paper rgb(241,236,223) to rgb(201,199,194): rendered
    through the result's sequencer, the frame's pixels must come back."""
    import tempera
    from tempera.blender import results

    paper = np.array([241, 236, 223]) / 255.0
    path = tmp_path / "frames" / "frame_0001.png"
    path.parent.mkdir()
    tempera.write_image(str(path), np.ascontiguousarray(np.broadcast_to(paper, (24, 32, 3)), np.float32))
    result = results.load(scene, [str(path)], [1], "SEQUENCER")
    result.render.filepath = str(tmp_path / "render.png")
    result.render.image_settings.file_format = "PNG"
    result.render.use_sequencer = True
    bpy.ops.render.render(write_still=True, scene=result.name)
    rendered = tempera.read_image(str(tmp_path / "render.png"))[:, :, :3]
    np.testing.assert_allclose(rendered.reshape(-1, 3).mean(axis=0) * 255, paper * 255, atol=1.5)


def test_one_tempera_job_at_a_time(scene):
    from fake_ui import modal_run
    from tempera.blender.guide_operator import GuideJob, TEMPERA_OT_render_guides
    from tempera.blender.job_operator import running_job

    seen = {}

    def look():
        seen["polls"] = [bpy.ops.tempera.render_guides.poll(), bpy.ops.tempera.stylize.poll()]
        seen["running"] = running_job()

    job = GuideJob.from_settings(scene, [FRAMES[0]])
    modal_run(TEMPERA_OT_render_guides, scene, job, [("TIMER", "NOTHING")] * 4, after_start=look)
    assert seen["polls"] == [False, False] and seen["running"]
    assert running_job() is None
    assert bpy.ops.tempera.render_guides.poll() and bpy.ops.tempera.stylize.poll()


def test_long_runs_ask_first(scene):
    from tempera.blender.guide_operator import GuideJob, TEMPERA_OT_render_guides, long_run_question
    from tempera.blender.stylize_operator import StylizeRun, TEMPERA_OT_stylize

    assert long_run_question(50, 599, "stylize") is None
    assert "51 frames" in long_run_question(51, 10, "stylize")
    assert "about 10 minutes" in long_run_question(3, 601, "stylize")
    short = StylizeRun(scene, FRAMES)
    assert TEMPERA_OT_stylize.confirmation(None, short) is None
    long = StylizeRun(scene, range(1, 61))
    assert "stylize 60 frames" in TEMPERA_OT_stylize.confirmation(None, long)
    assert "render the guides of 60 frames" in TEMPERA_OT_render_guides.confirmation(
        None, GuideJob.from_settings(scene, range(1, 61)))
    # A big render of few frames asks too.
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 3840, 2160, 100
    assert TEMPERA_OT_stylize.confirmation(None, StylizeRun(scene, range(1, 11))) is not None


def test_eta_waits_for_two_computed_frames(scene):
    from tempera.blender.guide_operator import GuideJob

    job = GuideJob.from_settings(scene, range(1, 11))
    assert "ETA" not in job.status_text()
    job.rendered, job.index, job.render_seconds = [1], 1, 30.0
    assert "ETA" not in job.status_text()  # one frame: it also paid Cycles' start-up
    job.rendered, job.index, job.render_seconds = [1, 2], 2, 40.0
    assert "ETA 2:40" in job.status_text()


def test_exemplar_thumbnail_and_image_only_picker(scene, tmp_path):
    from tempera.blender.panels import draw_exemplar

    from test_addon import _Recorder

    calls = []
    draw_exemplar(_Recorder(calls), scene.tempera)
    icons = [value for kind, value in calls if kind == "template_icon"]
    assert len(icons) == 1, calls  # the bundled kit's painting (icon ids are 0 in background mode)
    assert ("label", "style.png") in calls
    from tempera.blender.kit_operators import painting_preview
    from tempera.app.exemplar_kit import kit_exemplar

    assert tuple(painting_preview(str(kit_exemplar()[0])).image_size)[0] > 0  # the thumbnail was decoded
    picker = bpy.ops.tempera.choose_painting.get_rna_type().properties
    assert picker["filter_image"].default and picker["filter_folder"].default
    assert "*.png" in picker["filter_glob"].default and "*.blend" not in picker["filter_glob"].default
    painting = tmp_path / "mine.png"
    import tempera

    tempera.write_image(str(painting), np.full((8, 8, 3), 0.3, np.float32))
    assert bpy.ops.tempera.choose_painting(filepath=str(painting)) == {"FINISHED"}
    assert scene.tempera.exemplar_source == "CUSTOM" and scene.tempera.exemplar_style == str(painting)


def test_painting_template_and_photo_registration_from_blender(scene, tmp_path):
    import tempera
    from tempera.methods.stylit.registration import estimate_homography, simulate_photo

    assert bpy.ops.tempera.painting_template() == {"FINISHED"}
    kit = tmp_path / "out" / "painting_kit"
    assert {"template.pdf", "template.png", "kit.json"} <= {p.name for p in kit.iterdir()}
    page = tempera.read_image(str(kit / "template.png"))[:, :, :3]
    h, w = page.shape[:2]
    to_photo = estimate_homography(np.array([[0, 0], [w, 0], [w, h], [0, h]], float),
                                   np.array([[60, 40], [1180, 70], [1150, 860], [40, 820]], float))
    photo = tmp_path / "photo.jpg"
    tempera.write_image(str(photo), simulate_photo(page, to_photo, (1240, 900)))
    assert bpy.ops.tempera.register_painting(filepath=str(photo)) == {"FINISHED"}
    settings = scene.tempera
    assert settings.exemplar_source == "CUSTOM"
    assert settings.exemplar_style == str(kit / "painting.png")
    from tempera.app.exemplar_kit import kit_exemplar

    guides = kit_exemplar()[1]
    assert os.path.samefile(settings.exemplar_guide_dir, guides)
    info = tempera.image_info(settings.exemplar_style)
    guide_info = tempera.image_info(str(next(guides.glob("frame_*.exr"))))
    assert (info["width"], info["height"]) == (guide_info["width"], guide_info["height"])


def test_messages_and_tooltips_name_what_the_artist_sees(scene):
    props = bpy.types.Scene.bl_rna.properties["tempera"].fixed_type.properties
    assert "frames/" in props["output_dir"].description and "contact_sheet" in props["output_dir"].description
    assert "Typical" in props["guide_occlusion_epsilon"].description
    from tempera.blender.stylize_operator import flicker_text

    assert "steady" in flicker_text(0.01) and "Temporal Coherence" in flicker_text(0.08)
