"""The rigid-body method on a scene made the way a new user makes one, only
with Blender's own operators and their defaults (scenes/rigid_fractured_cube.py:
a cube broken by Cell Fracture falling onto a plane). The method then
runs from the panel (Stylize Animation) and as the CLI's job on the guide
cache (`tempera stylize --method rigid --object SHARD`, each shard on its
own): every shard is drawn where it is, its first collision is on the
floor, no drawing goes through the floor at a contact, no map folds, and
the panel's frames are the shards laid far to near."""
import math
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest
from guide_scene import remove_scene

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scenes"))
import rigid_fractured_cube  # noqa: E402

SCENE = "Rigid user scene"
SIZE = (240, 135)
FRAMES = (8, 23)  # the fall, the impact (frame ~14) and the scatter: two chunks


def _exemplar(folder):
    """A tumbling box drawn from the generated exemplar (the project's own)."""
    from tempera import _native
    from tempera.methods.rigid import rigid, rigid_tracks

    track = _native.bouncing_ball((40, 40), (3.0, 0), 14, 1.0, 110, 0.65, 0.12, 36)
    rigid_tracks.write_tracks(folder, {"Box": track}, 1, (0, 1.0))
    (folder / "drawn").mkdir(parents=True)
    for i, d in enumerate(rigid.generated_exemplar(track, *SIZE, shape="box", line_width=1.5)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


@pytest.fixture
def fractured_scene(tmp_path):
    if not rigid_fractured_cube.has_cell_fracture():
        pytest.skip("this Blender has no Cell Fracture add-on")
    scene = bpy.data.scenes.new(SCENE)
    shown = bpy.context.window.scene
    bpy.context.window.scene = scene
    shards = rigid_fractured_cube.build(scene, SIZE)
    _exemplar(tmp_path / "examples" / "box")
    settings = scene.tempera
    settings.method, settings.rigid_shape = "RIGID", "box"
    settings.rigid_examples = str(tmp_path / "examples")
    settings.output_dir, settings.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    settings.guide_frame_range = "CUSTOM"
    settings.guide_frame_start, settings.guide_frame_end = FRAMES
    settings.guide_samples = 2
    settings.guide_lpe = ""
    settings.make_video = False
    settings.load_result = "NONE"
    yield scene, sorted(o.name for o in shards)
    bpy.context.window.scene = shown
    remove_scene(scene)


def _lowest_z(scene, name, frame):
    scene.frame_set(frame)
    o = scene.objects[name]
    return min((o.matrix_world @ v.co).z for v in o.data.vertices)


def _min_det(D):
    """Least det J of the 2 x 6 map D over the unit disc (the fold guard's region)."""
    t, r = np.meshgrid(np.linspace(0, 2 * np.pi, 24), np.linspace(0, 1, 6))
    x, y = (r * np.cos(t)).ravel(), (r * np.sin(t)).ravel()
    D = np.asarray(D)
    jx = D[:, 0][:, None] + 2 * D[:, 2][:, None] * x + D[:, 4][:, None] * y
    jy = D[:, 1][:, None] + 2 * D[:, 3][:, None] * y + D[:, 4][:, None] * x
    return float((jx[0] * jy[1] - jx[1] * jy[0]).min())


def _fitted(folder):
    """The exemplar FOLDER fitted (as the job fits it): its maps D, frame by frame."""
    import tempera
    from tempera.methods.rigid import rigid, rigid_tracks

    track = rigid_tracks.read_tracks(folder)["objects"]["Box"]
    drawn = [tempera.read_image(str(folder / "drawn" / f"{1 + i:04d}.png")) for i in range(len(track["centre"]))]
    return rigid.fit_exemplar(track, drawn, shape="box")


def _premultiplied(rgba):
    return np.concatenate([rgba[:, :, :3] * rgba[:, :, 3:], rgba[:, :, 3:]], axis=2)


def _laid_far_to_near(layers, depths):
    """The straight-alpha LAYERS (by name) laid over each other, far to near
    (ties in name order), premultiplied."""
    out = None
    for name in sorted(sorted(layers), key=lambda n: -depths[n]):
        p = _premultiplied(layers[name])
        out = p if out is None else p + out * (1 - p[:, :, 3:])
    return out


def test_fractured_cube_from_the_panel_and_the_cli(fractured_scene, tmp_path):
    import tempera
    from tempera.methods import registry
    from tempera.methods.rigid import rigid, rigid_tracks

    scene, shards = fractured_scene
    assert len(shards) >= 4
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    tracks = rigid_tracks.read_tracks(tmp_path / "guides")
    assert sorted(tracks["objects"]) == shards
    start = tracks["frame_start"]
    out = tmp_path / "out" / "rigid"
    cli = tmp_path / "cli"  # each shard on its own, as `tempera stylize --method rigid --object NAME` runs it
    frames = list(range(FRAMES[0], FRAMES[1] + 1))
    for name in shards:
        job = registry.make_job("rigid", tmp_path / "examples" / "box", tmp_path / "guides", frames, cli / name,
                                options=[("object", name), ("shape", "box")])
        assert {job.run_frame(i)["status"] for i in range(len(frames))} == {"stylized"}
    exemplar = _fitted(tmp_path / "examples" / "box")
    floor_events = 0
    for name in shards:
        track = tracks["objects"][name]
        # Events: each shard's first collision comes at the impact. One that
        # the bake shows above the floor then landed on another shard (one on
        # the floor may name the floor or a shard beside it: they touch).
        assert track["events"], name
        first = track["events"][0]
        assert abs(first["frame"] + start - 14) <= 3, name
        on_floor = _lowest_z(scene, name, first["frame"] + start) < 0.15
        assert on_floor or first["obstacle"] in shards, (name, first)
        floor_events += first["obstacle"] == "static"
        # Every shard drawn where it is, in every frame.
        for f in range(FRAMES[0], FRAMES[1] + 1):
            layer = tempera.read_image(str(cli / name / "frames" / f"frame_{f:04d}.png"))
            ys, xs = np.nonzero(layer[:, :, 3] > 0.5)
            (cx, cy), r = track["centre"][f - start], track["radius"][f - start]
            assert len(xs) > 10, (name, f)
            assert math.hypot(xs.mean() - cx, ys.mean() - cy) < 0.8 * r, (name, f)
        # No fold: every blended map keeps a positive Jacobian on the body.
        for frame in rigid.deformations([exemplar], track, symmetry=4):
            assert _min_det(frame[0]) > 0, name
    assert floor_events >= 2
    # Contacts: at a floor event the drawing does not go through the floor.
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector

    for name in shards:
        for e in tracks["objects"][name]["events"]:
            f = e["frame"] + start
            if e["obstacle"] != "static" or not FRAMES[0] <= f <= FRAMES[1]:
                continue
            scene.frame_set(f)
            o = scene.objects[name]
            # The floor row under the shard: its nearest point on the floor
            # (perspective: nearer floor is lower in the image).
            near_y = min((o.matrix_world @ v.co).y for v in o.data.vertices)
            floor = world_to_camera_view(scene, scene.camera, Vector((o.matrix_world.translation.x, near_y, 0.0)))
            floor_row = (1 - floor.y) * SIZE[1]
            layer = tempera.read_image(str(cli / name / "frames" / f"frame_{f:04d}.png"))
            rows = np.nonzero(layer[:, :, 3].max(axis=1) > 0.5)[0]
            r = tracks["objects"][name]["radius"][e["frame"]]
            ys, xs = np.nonzero(layer[:, :, 3] > 0.5)
            pen = ((xs - e["contact"][0]) * -e["normal"][0] + (ys - e["contact"][1]) * -e["normal"][1]).max()
            # The drawing touches the event's contact line (the contact fix:
            # neither a gap nor a penetration over 1.5 px) and ends at the
            # floor the render shows (within the box proxy's slack).
            assert abs(pen) <= 1.5, (name, f, pen)
            assert rows.max() <= floor_row + 0.25 * r, (name, f, rows.max(), floor_row)
    # The panel's frames are the shards laid far to near by camera depth.
    for f in (FRAMES[0], 14, FRAMES[1]):
        layers = {n: tempera.read_image(str(cli / n / "frames" / f"frame_{f:04d}.png")) for n in shards}
        depths = {n: tracks["objects"][n]["depth"][f - start] for n in shards}
        composite = tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png"))
        assert np.abs(_premultiplied(composite) - _laid_far_to_near(layers, depths)).max() < 3 / 255, f
