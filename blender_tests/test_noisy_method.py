"""Temporal Noise as a method from the panel (Color Me Noisy's 3D case): the
guide test scene's render boiled with a still medium, a frame per step into
Output Folder/noisy/frames, with a contact sheet; a rerun resumes."""
import bpy
import numpy as np
import pytest
from guide_scene import FRAMES, build_scene, remove_scene

SCENE = "Temporal noise method test"


@pytest.fixture
def noisy_scene(tmp_path):
    import tempera

    scene = build_scene(SCENE)
    scene.render.resolution_percentage = 100
    shown = bpy.context.window.scene.name
    bpy.context.window.scene = scene
    medium = np.random.default_rng(11).random((64, 64, 3), dtype=np.float32) * 0.4 + 0.3
    tempera.write_image(str(tmp_path / "medium.png"), medium, [])
    s = scene.tempera
    s.method = "NOISY"
    s.media_exemplar_kind, s.media_exemplar = "STILL", str(tmp_path / "medium.png")
    s.output_dir, s.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    s.guide_frame_range = "CUSTOM"
    s.guide_frame_start, s.guide_frame_end = FRAMES[0], FRAMES[-1]
    s.guide_samples = 4
    s.make_video = False
    s.load_result = "NONE"
    yield scene
    if shown in bpy.data.scenes:
        bpy.context.window.scene = bpy.data.scenes[shown]
    remove_scene(scene)


def test_the_panel_shows_the_medium_and_the_noise(noisy_scene):
    from test_media_methods import _panel_props

    props = _panel_props()
    assert "media_exemplar" in props and "exemplar_style" not in props
    i = props.index("method")
    assert props[i + 1:i + 3] == ["noisy_level", "seed"]


def test_the_render_boils_and_a_rerun_resumes(noisy_scene, tmp_path):
    """With the Exemplar field empty the medium is the first render under a
    paper grain (the paper asks for a medium that looks like R, §3.1). The
    frames keep the render's large shapes and differ in the fine texture."""
    import tempera
    from tempera.app import beauty
    from tempera.blender.methods.noisy import NoisyRun
    from tempera.blender.stylize_operator import StylizeRun

    noisy_scene.tempera.media_exemplar = ""
    run = StylizeRun.from_settings(noisy_scene, "ANIMATION")
    assert type(run) is NoisyRun and run.options["noise"] == 2.2 and run.exemplar == ""
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out = tmp_path / "out" / "noisy"
    assert (out / "contact_sheet.png").is_file()
    for f in FRAMES:
        got = tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png"))
        render = beauty.render_image(str(tmp_path / "guides"), f)
        assert got.shape == render.shape
        difference = np.abs(got - render).mean()
        assert difference > 0.005  # the medium's texture, synthesized again
        # ... over the render's large shapes: a 5 x 5 box of each is within 5/255 (0.0074 measured; a
        # random grey medium, whose colours are not the render's, gave 0.16)
        box = [np.mean([a[y:y + a.shape[0] - 4, x:x + a.shape[1] - 4] for y in range(5) for x in range(5)], 0)
               for a in (got, render)]
        assert np.abs(box[0] - box[1]).mean() < 0.02
    again = StylizeRun.from_settings(noisy_scene, "ANIMATION")
    while not again.finished:
        again.step()
    assert [r["status"] for r in again.results] == ["skipped"] * len(FRAMES)


def test_a_movie_as_the_medium_is_refused_naming_the_still(noisy_scene):
    from tempera.blender.stylize_operator import StylizeRun

    noisy_scene.tempera.media_exemplar_kind = "MOVIE"
    with pytest.raises(ValueError, match="still sample of the medium"):
        StylizeRun.from_settings(noisy_scene, "ANIMATION")
