"""The rigid-body method from the panel (Method "Rigid Bodies (hand-drawn)")
on a tiny baked scene: a ball dropped on a floor, drawn from the generated
exemplar. Stylize Animation renders the guides (which write tracks.json),
runs the method's native job a frame per step and loads the result; Esc
within a frame writes nothing of it, and a rerun resumes."""
import math

import bpy
import numpy as np
import pytest
from guide_scene import remove_scene
from fake_ui import esc_within_next_step

SCENE = "Rigid method test"
SIZE = (96, 72)
FLOOR_Y = SIZE[1] / 2 + 0.9 * SIZE[0] / 3.0  # the floor z = 0 in the image: camera at z 0.9, 3 m wide
FRAMES = (5, 14)  # around the bounce (frame ~12): guides of 10 frames, two chunks of the method


def _exemplar(folder):
    from tempera import _native
    from tempera.methods.rigid import rigid, rigid_tracks

    track = _native.bouncing_ball((20, 15), (2.0, 0), 8, 0.6, 62, 0.65, 0.05, 24)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 0.6))
    (folder / "drawn").mkdir(parents=True)
    for i, d in enumerate(rigid.generated_exemplar(track, *SIZE, line_width=1.5)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


@pytest.fixture
def rigid_scene(tmp_path):
    """A ball dropped 1 m onto a passive floor (baked by frame_set), an
    orthographic camera along +Y, 16 frames at 96 x 72."""
    scene = bpy.data.scenes.new(SCENE)
    shown = bpy.context.window.scene
    bpy.context.window.scene = scene
    bpy.ops.mesh.primitive_plane_add(size=20, location=(0, 0, 0))
    floor = bpy.context.object
    bpy.ops.rigidbody.world_add()
    bpy.ops.rigidbody.object_add()
    floor.rigid_body.type = "PASSIVE"
    floor.rigid_body.restitution = 0.8
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(0, 0, 1.3), segments=16, ring_count=8)
    ball = bpy.context.object
    ball.name = "Ball"
    bpy.ops.rigidbody.object_add()
    ball.rigid_body.restitution = 0.8
    ball.rigid_body.collision_shape = "SPHERE"
    cam = bpy.data.objects.new("RigidCam", bpy.data.cameras.new("RigidCam"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 3.0
    scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (0, -10, 0.9), (math.pi / 2, 0, 0)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.frame_start, scene.frame_end = 1, 16
    scene.rigidbody_world.point_cache.frame_end = 16
    _exemplar(tmp_path / "examples" / "drop")
    settings = scene.tempera
    settings.method = "RIGID"
    settings.rigid_examples = str(tmp_path / "examples")
    settings.output_dir, settings.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    settings.guide_frame_range = "CUSTOM"
    settings.guide_frame_start, settings.guide_frame_end = FRAMES
    settings.guide_samples = 4
    settings.guide_lpe = ""
    settings.make_video = False
    settings.load_result = "IMAGE"
    yield scene
    bpy.context.window.scene = shown
    composite = bpy.data.scenes.get(SCENE + " Tempera Composite")
    if composite is not None:
        bpy.data.scenes.remove(composite)
    remove_scene(scene)


def _frames(folder):
    return sorted(p.name for p in folder.glob("*") if p.name.startswith(("frame_", ".")))


def test_method_in_the_panel(rigid_scene):
    from test_addon import _Recorder
    from tempera.blender.properties import METHOD_ITEMS

    assert ("RIGID", "Rigid Bodies (hand-drawn)") == METHOD_ITEMS[2][:2]
    calls = []
    bpy.types.TEMPERA_PT_output.draw(type("FakePanel", (), {"layout": _Recorder(calls)})(), bpy.context)
    props = [name for kind, name in calls if kind == "prop"]
    i = props.index("method")
    assert props[i + 1:i + 5] == ["rigid_examples", "rigid_collection", "rigid_shape", "rigid_output"]
    assert "usage" not in props  # StyLit's settings do not apply


def test_stylize_animation_draws_the_ball_and_resumes(rigid_scene, tmp_path):
    import tempera
    from tempera.blender.stylize_operator import StylizeRun

    run = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    assert type(run).__name__ == "RigidRun"
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    frames = list(range(FRAMES[0], FRAMES[1] + 1))
    out = tmp_path / "out" / "rigid" / "frames"
    assert _frames(out) == [f"frame_{f:04d}.png" for f in frames]
    tracks = tempera.methods.rigid.rigid_tracks.read_tracks(tmp_path / "guides")
    ball = tracks["objects"]["Ball"]
    assert len(ball["depth"]) == 16 and ball["events"]
    for f in frames:
        img = tempera.read_image(str(out / f"frame_{f:04d}.png"))
        assert img.shape == (SIZE[1], SIZE[0], 4)
        ys, xs = np.nonzero(img[:, :, 3] > 0.5)
        (cx, cy), r = ball["centre"][f - 1], ball["radius"][f - 1]
        # The ink is on the ball (the contact fix may pull it down onto the
        # floor at the bounce, never through it).
        assert len(xs) > 20 and abs(xs.mean() - cx) < 0.6 * r, f
        assert ys.min() < cy + r and ys.max() > cy - r and ys.max() < FLOOR_Y + 1.5, f
    assert (tmp_path / "out" / "rigid" / "contact_sheet.png").is_file()
    image = bpy.data.images["Tempera frames"]  # loaded as today (Load Result: Image)
    assert image.source == "SEQUENCE" and bpy.path.abspath(image.filepath) == str(out / f"frame_{FRAMES[0]:04d}.png")
    # RGBA frames: also laid over the render (the guides' Combined pass) in a composite scene.
    from tempera.blender import compat

    composite = bpy.data.scenes[SCENE + " Tempera Composite"]
    strips = sorted(compat.sequencer_strips(composite.sequence_editor), key=lambda s: s.channel)
    assert [(s.name, s.channel, len(s.elements)) for s in strips] == [("Render", 1, 10), ("Tempera", 2, 10)]
    assert strips[1].blend_type == "ALPHA_OVER"
    render = tempera.read_image(str(tmp_path / "out" / "rigid" / "render" / f"frame_{FRAMES[0]:04d}.png"))
    assert render.shape == (SIZE[1], SIZE[0], 3)  # black: the test scene has no light nor world
    again = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    while not again.finished:
        again.step()
    assert {r["status"] for r in again.results} == {"skipped"}
    rigid_scene.tempera.rigid_output = "PAPER"
    paper = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    assert not paper.over_render  # opaque frames are the picture themselves
    while not paper.finished:
        paper.step()
    assert tempera.read_image(str(out / f"frame_{FRAMES[0]:04d}.png"))[:, :, 3].min() == 1.0


def test_esc_within_a_frame_writes_nothing_then_resume(rigid_scene, tmp_path):
    from tempera.blender.stylize_operator import TEMPERA_OT_stylize, StylizeRun

    run = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    while run.in_guide_phase:
        run.step()
    run.step()  # the first frame (the exemplar's fit, then its drawing)
    run_frame = run.job.run_frame

    def hold(wrap):
        run.job.run_frame = lambda index, progress=None: run_frame(index, wrap(progress))

    results, _log, reports, timers, _op = esc_within_next_step(TEMPERA_OT_stylize, rigid_scene, run, hold)
    assert results[-1] == {"CANCELLED"} and not timers and "Stopped" in reports[-1][1]
    out = tmp_path / "out" / "rigid" / "frames"
    assert _frames(out) == [f"frame_{FRAMES[0]:04d}.png"]  # the first frame only, nothing half-written
    rerun = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    while not rerun.finished:
        rerun.step()
    assert [r["status"] for r in rerun.results] == ["skipped"] + ["stylized"] * (FRAMES[1] - FRAMES[0])


def test_panel_options_reach_the_job(rigid_scene, tmp_path):
    """K, augmentation, damping and the strokes of the panel are the job's
    options (the method's flags), the panel shows them, and the strokes are
    the brush pen's."""
    from test_addon import _Recorder
    from tempera import read_image
    from tempera.blender.methods import rigid
    from tempera.blender.stylize_operator import StylizeRun
    from tempera.methods.rigid.rigid_strokes import STROKE_COLOUR

    settings = rigid_scene.tempera
    assert settings.rigid_k == rigid.OPTIONS["k"]["default"]
    settings.rigid_k, settings.rigid_augment, settings.rigid_damp = 1, False, False
    settings.rigid_strokes, settings.rigid_stroke_weight = "GENERATED", 2.5
    settings.rigid_collection = bpy.data.collections.new("Targets")
    settings.rigid_collection.objects.link(rigid_scene.objects["Ball"])
    calls = []
    bpy.types.TEMPERA_PT_output.draw(type("FakePanel", (), {"layout": _Recorder(calls)})(), bpy.context)
    props = [name for kind, name in calls if kind == "prop"]
    for name in ("rigid_k", "rigid_augment", "rigid_damp", "rigid_strokes", "rigid_stroke_weight"):
        assert name in props
    run = StylizeRun.from_settings(rigid_scene, "ANIMATION")
    assert run.options == [("shape", "circle"), ("paper", False), ("k", 1), ("augment", False), ("damp", False),
                           ("stroke-weight", 2.5), ("strokes", "generated"), ("object", "Ball")]
    while run.in_guide_phase:
        run.step()
    run.step()
    frame = read_image(run.results[0]["path"])
    ink = frame[:, :, 3] > 0.5
    assert ink.sum() > 20 and np.abs(frame[ink, :3].mean(0) - STROKE_COLOUR).max() < 0.05
    bpy.data.collections.remove(settings.rigid_collection)
    settings.rigid_strokes, settings.rigid_stroke_image = "IMAGE", "/nowhere/strokes.png"
    with pytest.raises(FileNotFoundError, match="strokes.png"):
        StylizeRun.from_settings(rigid_scene, "ANIMATION")
    settings.rigid_strokes, settings.rigid_examples = "NONE", str(tmp_path / "nowhere")
    with pytest.raises(FileNotFoundError, match="nowhere' does not exist"):
        StylizeRun.from_settings(rigid_scene, "ANIMATION")


def test_empty_examples_use_the_projects_drawn_ball(rigid_scene, tmp_path):
    """Issue 41, step 5: with no Examples folder the method uses the project's own drawn
    exemplar (the CLI's default too), written once beside the results."""
    import tempera

    rigid_scene.tempera.rigid_examples = ""
    rigid_scene.tempera.guide_frame_start, rigid_scene.tempera.guide_frame_end = 9, 10
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    generated = tmp_path / "out" / "rigid" / "exemplar_generated_circle"
    assert (generated / "tracks.json").is_file() and len(list((generated / "drawn").glob("*.png"))) == 60
    out = tmp_path / "out" / "rigid" / "frames"
    assert _frames(out) == ["frame_0009.png", "frame_0010.png"]
    assert all(tempera.read_image(str(out / name))[:, :, 3].max() > 0.5 for name in _frames(out))
