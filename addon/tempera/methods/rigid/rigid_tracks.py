"""Tracks and collision events of rigid bodies, for the rigid-body method
(Dvorožňák et al. 2017), with no bpy.

A track is, per frame of one object: the screen centroid c (px, x right,
y down), the velocity v = (c[f+1] - c[f-1]) / 2 (px per frame; one-sided at
the ends), the trajectory direction delta = atan2(v), the rotation theta,
alpha = theta - delta (the rotation relative to the trajectory, §4) and the
screen radius r. Frames at rest keep the last direction.

Blender does not expose contacts to Python, so collision events are found
from the motion [design]: the impulse J[f] = |c[f+1] - 2 c[f] + c[f-1] - g|
(the change of velocity that gravity g, px per frame^2, does not explain) is
a local maximum above a threshold. The normal is that velocity change,
normalized; the contact point is the proxy's rim along -n; the obstacle is the
nearest other object then, or "static" (a passive body) when none is near.

tracks.json in the guide cache holds every object's track and events
(docs/rigid_bodies.md). The Blender side (projecting a baked rigid-body world
through the camera) is tempera.blender.rigid_tracks.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from ... import _native
from ...app.frames import MAX_FRAME

TRACKS_NAME = "tracks.json"
TRACKS_VERSION = 1


def velocities(centres):
    """Central differences of (F, 2) centres, one-sided at the ends."""
    c = np.asarray(centres, dtype=float)
    if c.ndim != 2 or c.shape[1] != 2 or len(c) < 2:
        raise ValueError("centres must be an (F, 2) array with at least 2 frames")
    v = np.empty_like(c)
    v[1:-1] = (c[2:] - c[:-2]) / 2
    v[0] = c[1] - c[0]
    v[-1] = c[-1] - c[-2]
    return v


def trajectory_angles(v, theta, rest_speed=1e-3):
    """delta = atan2(v) (kept through rests) and alpha = theta - delta, wrapped to (-pi, pi]."""
    delta = np.zeros(len(v))
    last = 0.0
    for f, (vx, vy) in enumerate(v):
        if math.hypot(vx, vy) > rest_speed:
            last = math.atan2(vy, vx)
        delta[f] = last
    alpha = np.angle(np.exp(1j * (np.asarray(theta, dtype=float) - delta)))
    return delta, alpha


def impulse(centres, gravity):
    """J[f] = |c[f+1] - 2 c[f] + c[f-1] - g| (0 at the ends)."""
    c = np.asarray(centres, dtype=float)
    j = np.zeros(len(c))
    if len(c) >= 3:
        j[1:-1] = np.linalg.norm(c[2:] - 2 * c[1:-1] + c[:-2] - np.asarray(gravity, dtype=float), axis=1)
    return j


def find_events(centres, radius, gravity, threshold=None, others=None, near=1.5):
    """Collision events of one object: local maxima of the impulse above
    `threshold` (default: |g| + 0.5 px/frame, so that neither a free flight,
    whose impulse is rounding only, nor a body resting on the floor, whose
    impulse is exactly -g, makes one).

    A bounce between two frames spreads its impulse over both; the larger
    one is the event frame. `others` maps names to (centres, radius) of the
    other objects; the nearest one whose rim is within `near` radii and
    that lies behind the normal is the obstacle. Returns dicts {frame, impulse, normal, contact, obstacle}.
    """
    c = np.asarray(centres, dtype=float)
    g = np.asarray(gravity, dtype=float)
    j = impulse(c, g)
    tau = float(np.linalg.norm(g)) + 0.5 if threshold is None else float(threshold)
    events = []
    for f in range(1, len(c) - 1):
        if j[f] <= tau or j[f] < j[f - 1] or j[f] < j[f + 1]:
            continue
        if events and events[-1]["frame"] == f - 1:  # a plateau: keep the first
            continue
        dv = c[f + 1] - 2 * c[f] + c[f - 1] - g
        n = dv / np.linalg.norm(dv)
        r = float(np.broadcast_to(radius, (len(c),))[f])
        events.append({
            "frame": f,
            "impulse": float(j[f]),
            "normal": [float(n[0]), float(n[1])],
            "contact": [float(c[f, 0] - r * n[0]), float(c[f, 1] - r * n[1])],
            "obstacle": _obstacle(c[f], r, n, f, others or {}, near),
        })
    return events


def _obstacle(centre, radius, normal, frame, others, near):
    """The nearest other object within `near` radii that lies behind the
    normal (it pushed the body along n), else "static"."""
    best, best_gap = "static", math.inf
    for name, (oc, orad) in others.items():
        o = np.asarray(oc, dtype=float)[frame]
        away = centre - o
        dist = float(np.linalg.norm(away))
        gap = dist - radius - float(np.ravel(orad)[frame] if np.ndim(orad) else orad)
        if gap < best_gap and gap <= near * radius and dist > 0 and float(away @ normal) > 0.7 * dist:
            best, best_gap = name, gap
    return best


def make_track(centres, theta, radius, gravity, others=None, threshold=None):
    """Everything the method needs of one object, as a JSON-ready dict."""
    c = np.asarray(centres, dtype=float)
    v = velocities(c)
    delta, alpha = trajectory_angles(v, theta)
    return {
        "centre": c.tolist(),
        "velocity": v.tolist(),
        "theta": np.asarray(theta, dtype=float).tolist(),
        "delta": delta.tolist(),
        "alpha": alpha.tolist(),
        "radius": np.broadcast_to(np.asarray(radius, dtype=float), (len(c),)).tolist(),
        "events": find_events(c, radius, gravity, threshold, others),
    }


def write_tracks(cache_dir, tracks, frame_start, gravity):
    """Writes <cache>/tracks.json atomically (temporary file, then rename):
    {"format", "frame_start", "gravity", "objects": {name: track}}. The same
    tracks again leave the file as it is, so a rerun of the guide render keeps
    the frames made from them current (their records stamp the file)."""
    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    data = {"format": TRACKS_VERSION, "frame_start": int(frame_start),
            "gravity": [float(x) for x in gravity], "objects": tracks}
    text = json.dumps(data, indent=1, sort_keys=True)
    try:
        if (cache_dir / TRACKS_NAME).read_text(encoding="utf-8") == text:
            return
    except (OSError, UnicodeDecodeError):
        pass
    fd, tmp = tempfile.mkstemp(prefix=".tracks.", suffix=".partial", dir=cache_dir)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, cache_dir / TRACKS_NAME)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def read_tracks(cache_dir):
    """The tracks of a guide cache; a missing or malformed file is named."""
    path = Path(cache_dir) / TRACKS_NAME
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no rigid-body tracks in this guide cache (render the guides of a "
                                "baked rigid-body world first)")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except RecursionError:
        raise ValueError(f"{path}: unreadable tracks (nested too deeply)") from None
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: unreadable tracks ({e})") from e
    if not isinstance(data, dict) or data.get("format") != TRACKS_VERSION or not isinstance(data.get("objects"), dict):
        raise ValueError(f"{path}: not a tracks file of format {TRACKS_VERSION}")
    _check_tracks(data, path)
    return data


def _check_tracks(data, path):
    """ValueError naming the file, the object and the value: tracks.json is user input, and NaN, inf,
    1e300 or a string where numbers belong made blank frames or tracebacks."""
    start = data.get("frame_start")
    if type(start) is not int or not 0 <= start <= MAX_FRAME:
        raise ValueError(f"{path}: frame_start must be a whole number from 0 to {MAX_FRAME}, got {start!r}")
    gravity = data.get("gravity")
    if (not isinstance(gravity, list) or len(gravity) != 2
            or not all(type(g) in (int, float) and math.isfinite(g) for g in gravity)):
        raise ValueError(f"{path}: gravity must be 2 finite numbers, got {gravity!r}")
    for name, track in data["objects"].items():
        try:
            if not isinstance(track, dict):
                raise ValueError("not a track")
            _native.check_rigid_track(track)
        except (TypeError, ValueError, RuntimeError) as e:  # RuntimeError: a value pybind11 cannot convert
            raise ValueError(f"{path}: object '{name}': {e}") from None


def frame_size(cache_dir):
    """(width, height) of a guide cache's frames (its manifest.json), checked like an image's."""
    path = Path(cache_dir) / "manifest.json"
    try:
        resolution = json.loads(path.read_text(encoding="utf-8"))["resolution"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        raise ValueError(f"{cache_dir}: no manifest.json with the frames' resolution") from None
    if (not isinstance(resolution, list) or len(resolution) != 2
            or not all(type(x) is int and x >= 1 for x in resolution)):
        raise ValueError(f"{path}: the resolution must be 2 whole numbers >= 1, got {resolution!r}")
    width, height = resolution
    if width * height > _native.max_image_pixels():
        raise ValueError(f"{path}: the resolution {width}x{height} is more than the limit of "
                         f"{_native.max_image_pixels()} pixels (raise it with TEMPERA_MAX_IMAGE_PIXELS if real)")
    return width, height


def planarity_warning(axis_world, view_axis_world, limit_degrees=10.0):
    """A warning text when an object's rotation axis is more than
    `limit_degrees` from the view axis (the method is 2D), else None."""
    a = np.asarray(axis_world, dtype=float)
    b = np.asarray(view_axis_world, dtype=float)
    if np.linalg.norm(a) < 1e-9:
        return None  # not rotating
    cos = abs(float(a @ b)) / (np.linalg.norm(a) * np.linalg.norm(b))
    angle = math.degrees(math.acos(min(1.0, cos)))
    if angle <= limit_degrees:
        return None
    return (f"rotation axis {angle:.0f} degrees from the view axis: the rigid-body method is 2D, keep the "
            "objects' rotation about the camera's axis")
