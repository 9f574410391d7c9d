"""Tracks and collision events of baked Blender rigid-body worlds
(tempera.blender.rigid_tracks): a drop, a throw (an animated start handed
over to the simulation) and two bodies; every bounce is found within +-1
frame and every event is a contact."""
import math

import bpy
import pytest

from tempera.blender import rigid_tracks as brt

FRAMES = 72


def _ball(name, location, radius=0.25):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location)
    ball = bpy.context.object
    ball.name = name
    bpy.ops.rigidbody.object_add()
    ball.rigid_body.restitution = 0.9
    ball.rigid_body.collision_shape = "SPHERE"
    return ball


@pytest.fixture
def world():
    """The context scene (operators act on it) with a passive floor, an
    orthographic camera along +Y and 72 frames; emptied again afterwards."""
    scene = bpy.context.scene
    kept = set(scene.objects)
    bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, 0))
    floor = bpy.context.object
    if scene.rigidbody_world is None:
        bpy.ops.rigidbody.world_add()
    bpy.ops.rigidbody.object_add()
    floor.rigid_body.type = "PASSIVE"
    floor.rigid_body.restitution = 0.9
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 10
    scene.collection.objects.link(cam)
    cam.location = (0, -10, 2.5)
    cam.rotation_euler = (math.pi / 2, 0, 0)
    old_camera, scene.camera = scene.camera, cam
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = 320, 240, 100
    scene.frame_start, scene.frame_end = 1, FRAMES
    scene.rigidbody_world.point_cache.frame_end = FRAMES
    yield scene
    scene.camera = old_camera
    for o in list(scene.objects):
        if o not in kept:
            bpy.data.objects.remove(o)
    bpy.ops.rigidbody.world_remove()
    scene.frame_set(1)


def _floor_bounces(track):
    """Lowest points reached while falling (image y grows downwards): the
    ground truth, from the positions (the finder uses the impulse)."""
    y = [c[1] for c in track["centre"]]
    return [f for f in range(3, len(y) - 1) if y[f] >= y[f - 1] and y[f] > y[f + 1] and y[f] - y[f - 3] > 2]


def _check(track, contacts, scene_name):
    found = [e["frame"] for e in track["events"]]
    for f in _floor_bounces(track):
        assert any(abs(e - f) <= 1 for e in found), f"{scene_name}: bounce at {f} missed (found {found})"
    for e in found:
        if e >= len(track["centre"]) - 3:
            continue  # the positions end too soon to show a lowest point there
        assert any(abs(e - f) <= 1 for f in contacts), f"{scene_name}: event at {e} is no contact ({contacts})"


def test_drop(world):
    ball = _ball("Drop", (0, 0, 3))
    tracks, gravity, warnings = brt.extract_tracks(world, [ball])
    assert gravity[1] > 0 and abs(gravity[0]) < 1e-6  # down the image
    assert warnings == []
    t = tracks["Drop"]
    assert len(_floor_bounces(t)) >= 2
    _check(t, _floor_bounces(t), "drop")
    assert all(e["normal"][1] < -0.9 and e["obstacle"] == "static" for e in t["events"])


def test_throw(world):
    # Thrown sideways by a ramp: dropped onto a passive slope of 25 degrees,
    # it bounces off to the right and on along the floor.
    bpy.ops.mesh.primitive_plane_add(size=2, location=(-3, 0, 1), rotation=(0, math.radians(25), 0))
    bpy.ops.rigidbody.object_add()
    ramp = bpy.context.object
    ramp.rigid_body.type = "PASSIVE"
    ramp.rigid_body.restitution = 0.9
    ball = _ball("Throw", (-3.1, 0, 3))
    tracks, _, _ = brt.extract_tracks(world, [ball])
    t = tracks["Throw"]
    assert t["centre"][-1][0] - t["centre"][0][0] > 30  # it travels to the right
    ramp_hit = t["events"][0]
    assert ramp_hit["normal"][0] > 0.2  # the slope's normal leans right
    assert len(_floor_bounces(t)) >= 2
    _check(t, _floor_bounces(t), "throw")


def test_two_bodies(world):
    low = _ball("Low", (0, 0, 0.26))
    high = _ball("High", (0.12, 0, 3))
    tracks, _, _ = brt.extract_tracks(world, [low, high])
    a, b = tracks["Low"], tracks["High"]
    gaps = [math.dist(p, q) - ra - rb for p, q, ra, rb in zip(a["centre"], b["centre"], a["radius"], b["radius"])]
    # Touching within a frame's relative motion (contacts fall between frames).
    rel = [math.dist(u, v) for u, v in zip(a["velocity"], b["velocity"])]
    touching = [f for f, g in enumerate(gaps) if g < 2.0 + rel[f]]
    assert touching, f"the balls must collide (least gap {min(gaps):.1f} px)"
    _check(b, _floor_bounces(b) + touching, "two bodies (high)")
    _check(a, _floor_bounces(a) + touching, "two bodies (low)")
    assert any(e["obstacle"] == "Low" for e in b["events"]), "the falling ball hits the other one"


def test_planarity_warning(world):
    ball = _ball("Spin", (0, 0, 3))
    ball.rigid_body.kinematic = True
    ball.keyframe_insert("rotation_euler", frame=1)
    ball.rotation_euler = (1.0, 0, 0)  # about X: not the view axis (Y)
    ball.keyframe_insert("rotation_euler", frame=FRAMES)
    _, _, warnings = brt.extract_tracks(world, [ball])
    assert warnings and "view axis" in warnings[0]


def test_guide_render_writes_the_tracks(world, tmp_path):
    from tempera.methods.rigid import rigid_tracks
    from tempera.blender.guide_render import render_guides

    _ball("Cached", (0, 0, 3))
    world.render.resolution_x, world.render.resolution_y = 64, 48
    world.frame_set(5)
    render_guides(world, [1, 2], tmp_path / "cache", {"samples": 2, "ld12e_samples": 2})
    assert world.frame_current == 5  # the track extraction puts the frame back
    data = rigid_tracks.read_tracks(tmp_path / "cache")
    track = data["objects"]["Cached"]
    assert len(track["centre"]) == FRAMES and data["frame_start"] == 1
    assert [e["frame"] for e in track["events"]][:1] == [18]  # the drop's first bounce (test_drop)
