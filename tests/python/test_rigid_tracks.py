"""Tracks and collision events of the rigid-body method (tempera.methods.rigid.rigid_tracks)
on three scenes baked by a small 2D rigid-body integrator (a drop, a throw
against a wall, two bodies colliding): every bounce is found within +-1
frame and nothing else is."""
import json
import math

import numpy as np
import pytest

from tempera.methods.rigid import rigid_tracks as rt

W, H = 640, 360
G = np.array([0.0, 0.8])  # px per frame^2, down the image


def bake(balls, frames, steps=64, restitution=0.7):
    """Sub-stepped 2D balls with a floor, two walls and ball-ball collisions.
    Returns centres (per ball, F x 2) and the collisions (time, ball, |dv|)."""
    pos = [np.array(b[0], float) for b in balls]
    vel = [np.array(b[1], float) for b in balls]
    rad = [b[2] for b in balls]
    centres = [[] for _ in balls]
    hits = []
    for f in range(frames):
        for i in range(len(balls)):
            centres[i].append(pos[i].copy())
        for k in range(steps):
            t = f + (k + 1) / steps
            for i in range(len(balls)):
                vel[i] = vel[i] + G / steps
                pos[i] = pos[i] + vel[i] / steps
                for axis, lo, hi in ((1, None, H), (0, 0, W)):
                    if hi is not None and pos[i][axis] + rad[i] > hi and vel[i][axis] > 0:
                        before = vel[i].copy()
                        pos[i][axis] = hi - rad[i]
                        vel[i][axis] *= -restitution
                        hits.append((t, i, float(np.linalg.norm(vel[i] - before))))
                    if lo is not None and pos[i][axis] - rad[i] < lo and vel[i][axis] < 0:
                        before = vel[i].copy()
                        pos[i][axis] = lo + rad[i]
                        vel[i][axis] *= -restitution
                        hits.append((t, i, float(np.linalg.norm(vel[i] - before))))
            for i in range(len(balls)):
                for j in range(i + 1, len(balls)):
                    d = pos[j] - pos[i]
                    dist = float(np.linalg.norm(d))
                    n = d / dist
                    closing = float((vel[i] - vel[j]) @ n)
                    if dist < rad[i] + rad[j] and closing > 0:
                        dv = (1 + restitution) * closing / 2 * n
                        vel[i] = vel[i] - dv
                        vel[j] = vel[j] + dv
                        hits.append((t, i, float(np.linalg.norm(dv))))
                        hits.append((t, j, float(np.linalg.norm(dv))))
    return [np.array(c) for c in centres], rad, hits


SCENES = {
    "drop": ([((320, 60), (0, 0), 20)], 90),
    "throw": ([((60, 200), (9, -12), 20)], 90),
    "two bodies": ([((100, 150), (6, -6), 20), ((540, 150), (-6, -6), 24)], 90),
}


@pytest.mark.parametrize("scene", SCENES)
def test_every_bounce_found_within_a_frame(scene):
    balls, frames = SCENES[scene]
    centres, radii, hits = bake(balls, frames)
    tau = float(np.linalg.norm(G)) + 0.5
    for i, c in enumerate(centres):
        others = {f"ball{j}": (centres[j], radii[j]) for j in range(len(centres)) if j != i}
        events = rt.find_events(c, radii[i], G, others=others)
        found = [e["frame"] for e in events]
        # Bounces that change the velocity clearly more than the threshold
        # must be found; every event must be some collision.
        clear = [t for t, b, dv in hits if b == i and dv > 2 * tau and t < frames - 1.5]
        hit_times = [t for t, b, dv in hits if b == i]
        assert clear, "the scene must bounce"
        for t in clear:
            assert any(abs(f - t) <= 1.0 for f in found), f"{scene}: bounce at {t:.2f} missed (found {found})"
        for f in found:
            assert any(abs(f - t) <= 1.0 for t in hit_times), f"{scene}: false event at {f} (hits {hit_times})"


def test_event_normal_contact_and_obstacle():
    centres, radii, hits = bake(SCENES["two bodies"][0], 90)
    events = rt.find_events(centres[0], radii[0], G, others={"ball1": (centres[1], radii[1])})
    floor = [e for e in events if e["normal"][1] < -0.9]
    assert floor, "a floor bounce has an upward normal"
    e = floor[0]
    # The contact point is on the rim, at the floor.
    assert abs(e["contact"][1] - H) <= 12  # within a frame's fall
    assert e["obstacle"] == "static"
    bodies = [e for e in events if e["obstacle"] == "ball1"]
    assert bodies, "the collision with the other ball names it"
    n = np.array(bodies[0]["normal"])
    towards_other = centres[1][bodies[0]["frame"]] - centres[0][bodies[0]["frame"]]
    assert n @ towards_other < 0  # pushed away from the other ball


def test_no_events_in_free_flight_or_at_rest():
    t = np.arange(40, dtype=float)
    flight = np.stack([10 + 5 * t, 50 + 0.5 * G[1] * t * t], axis=1)
    assert rt.find_events(flight, 10, G) == []
    rest = np.tile([[100.0, H - 10.0]], (30, 1))
    assert rt.find_events(rest, 10, G) == []


def test_track_angles_and_round_trip(tmp_path):
    t = np.arange(20, dtype=float)
    centres = np.stack([10 + 4 * t, 100 + 0 * t], axis=1)
    theta = 0.1 * t
    track = rt.make_track(centres, theta, 12.0, G)
    assert np.allclose(track["velocity"], [[4, 0]] * 20)
    assert np.allclose(track["delta"], 0)
    assert np.allclose(track["alpha"], np.angle(np.exp(1j * theta)))
    rt.write_tracks(tmp_path, {"Ball": track}, 1, G)
    data = rt.read_tracks(tmp_path)
    assert data["objects"]["Ball"]["radius"][0] == 12.0
    assert not list(tmp_path.glob(".tracks.*"))  # no temporary file left
    (tmp_path / rt.TRACKS_NAME).write_text(json.dumps({"format": 99}))
    with pytest.raises(ValueError, match="format"):
        rt.read_tracks(tmp_path)
    with pytest.raises(FileNotFoundError, match="no rigid-body tracks"):
        rt.read_tracks(tmp_path / "nowhere")


def test_planarity_warning():
    assert rt.planarity_warning([0, 1, 0], [0, -1, 0]) is None
    assert rt.planarity_warning([0, 0, 0], [0, -1, 0]) is None
    tilted = [math.sin(math.radians(30)), math.cos(math.radians(30)), 0]
    assert "30 degrees" in rt.planarity_warning(tilted, [0, 1, 0])
