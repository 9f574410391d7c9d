"""The rigid-body demo (docs/rigid_bodies.md): three balls and a box
colliding on ramps in a Blender rigid-body world, stylized from the
project's generated "hand-drawn" exemplar, with no external file.

    blender -b --factory-startup --python scenes/rigid_demo.py -- --out build/demo-rigid

Builds and bakes the scene (96 frames, orthographic camera along +Y), takes
the tracks (tempera.blender.rigid_tracks), fits the generated exemplars (a
thrown ball, and a tumbling box for the box) and writes, per frame, the
stylized objects composited by depth on paper (frame_NNNN.png), the oracle
outlines (D_gen applied to the target tracks, oracle_NNNN.png) and
tracks.json. The floor and the ramps are drawn in the same pencil, with a
fresh jitter every frame.
"""
import argparse
import math
import sys
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
from tempera import _native
from tempera.methods.rigid import rigid, rigid_strokes, rigid_tracks  # noqa: E402
from tempera.blender import rigid_tracks as brt  # noqa: E402

W, H = 640, 360
FRAMES = 96
PAPER = np.asarray((0.97, 0.96, 0.92), np.float32)
GRAPHITE = np.asarray((0.16, 0.16, 0.20), np.float32)  # the generated exemplar's pencil (rigid_exemplar.cpp)


def scenery_segments(scene, planes):
    """The passive planes seen edge-on by the camera along +Y: each one's
    image segment (its leftmost and rightmost projected vertices)."""
    from bpy_extras.object_utils import world_to_camera_view

    segments = []
    for plane in planes:
        points = [world_to_camera_view(scene, scene.camera, plane.matrix_world @ v.co) for v in plane.data.vertices]
        pixels = sorted((p.x * W, (1 - p.y) * H) for p in points)
        segments.append((np.asarray(pixels[0]), np.asarray(pixels[-1])))
    return segments


def draw_scenery(segments, frame, width=2.5, wobble=0.6):
    """Alpha of the scenery in pencil (the exemplar's line width and wobble):
    each segment a line whose path wobbles by a smooth random offset, fresh
    every frame, as the drawn bodies boil."""
    rng = np.random.default_rng(1000 + frame)
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float32)
    alpha = np.zeros((H, W), np.float32)
    for a, b in segments:
        a, b = np.clip(a, -10, W + 10), np.clip(b, -10, W + 10)
        n = max(2, int(np.hypot(*(b - a)) / 12))
        t = np.linspace(0, 1, n + 1)[:, None]
        normal = np.array([a[1] - b[1], b[0] - a[0]]) / max(np.hypot(*(b - a)), 1e-6)
        points = a + t * (b - a) + normal * rng.uniform(-wobble, wobble, (n + 1, 1))
        for p, q in zip(points, points[1:]):
            alpha = np.maximum(alpha, np.clip(width / 2 + 0.5 - rigid_strokes.segment_distance(xs, ys, p, q), 0, 1))
    return alpha


def _body(obj, passive=False, shape="SPHERE"):
    bpy.context.view_layer.objects.active = obj
    bpy.ops.rigidbody.object_add()
    obj.rigid_body.type = "PASSIVE" if passive else "ACTIVE"
    obj.rigid_body.restitution = 0.8
    obj.rigid_body.collision_shape = shape
    return obj


def build(scene):
    for o in list(scene.objects):
        bpy.data.objects.remove(o)
    if scene.rigidbody_world is None:
        bpy.ops.rigidbody.world_add()
    scene.rigidbody_world.point_cache.frame_end = FRAMES
    bpy.ops.mesh.primitive_plane_add(size=40, location=(0, 0, 0))
    planes = [_body(bpy.context.object, passive=True, shape="MESH")]
    for x, z, angle in ((-3.2, 2.6, 25), (3.0, 1.6, -20)):
        bpy.ops.mesh.primitive_plane_add(size=2.6, location=(x, 0, z), rotation=(0, math.radians(angle), 0))
        planes.append(_body(bpy.context.object, passive=True, shape="MESH"))
    balls = []
    for i, (x, z) in enumerate(((-3.4, 5.0), (3.2, 4.4), (0.3, 5.6))):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(x, 0, z))
        ball = bpy.context.object
        ball.name = f"Ball{i + 1}"
        balls.append(_body(ball))
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(-0.8, 0, 3.2), rotation=(0, 0.4, 0))
    box = bpy.context.object
    box.name = "Box"
    _body(box, shape="BOX")
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 11
    scene.collection.objects.link(cam)
    cam.location = (0, -12, 2.9)
    cam.rotation_euler = (math.pi / 2, 0, 0)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = W, H, 100
    scene.frame_start, scene.frame_end = 1, FRAMES
    return balls + [box], planes


def exemplars():
    """The generated exemplars: a thrown ball, and a box tumbling as it goes."""
    ball, box = rigid.generated_track("circle"), rigid.generated_track("box")
    return (rigid.fit_exemplar(ball, rigid.generated_exemplar(ball, W, H)),
            rigid.fit_exemplar(box, rigid.generated_exemplar(box, W, H, shape="box"), shape="box"))


def outline_mask(track, f, D, shape):
    """The proxy's outline through D, as 1 px dots (the oracle picture)."""
    c, r, th = np.asarray(track["centre"][f]), track["radius"][f], track["theta"][f]
    t = np.linspace(0, 2 * np.pi, 900, endpoint=False)
    u = np.stack([np.cos(t), np.sin(t)], 1)
    if shape == "box":
        m = np.maximum(np.abs(np.cos(t - th)), np.abs(np.sin(t - th)))
        u = u / (m[:, None] * math.sqrt(2))
    mono = np.stack([u[:, 0], u[:, 1], u[:, 0] ** 2, u[:, 1] ** 2, u[:, 0] * u[:, 1], np.ones(len(t))], 1)
    p = c + r * (mono @ np.asarray(D).T)
    mask = np.zeros((H, W), np.float32)
    ok = (p[:, 0] >= 0) & (p[:, 0] < W) & (p[:, 1] >= 0) & (p[:, 1] < H)
    mask[p[ok, 1].astype(int), p[ok, 0].astype(int)] = 1
    return mask


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="rigid_demo.py")
    parser.add_argument("--out", default=str(ROOT / "build" / "demo-rigid"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = bpy.context.scene
    bodies, planes = build(scene)
    tracks, gravity, warnings = brt.extract_tracks(scene, bodies)
    segments = scenery_segments(scene, planes)  # after frame_set: the camera's matrix is evaluated
    for w in warnings:
        print("rigid demo: warning:", w)
    rigid_tracks.write_tracks(out, tracks, scene.frame_start, gravity)
    ball_ex, box_ex = exemplars()
    layers = []
    for o in bodies:
        is_box = o.name == "Box"
        frames = rigid.stylize([box_ex if is_box else ball_ex], tracks[o.name], W, H,
                               symmetry=4 if is_box else 0)
        oracle = rigid.oracle_maps(tracks[o.name], shape="box" if is_box else "circle")
        layers.append((o.name, frames, oracle, "box" if is_box else "circle"))
        print(f"rigid demo: {o.name}: {len(tracks[o.name]['events'])} events")
    # All bodies lie in the XZ plane: composite in a fixed order (by depth).
    for f in range(FRAMES):
        img = np.broadcast_to(PAPER, (H, W, 3)).copy()
        ora = img.copy()
        ground = draw_scenery(segments, f)[:, :, None]
        img = GRAPHITE * ground + img * (1 - ground)
        for name, frames, oracle, shape in layers:
            rgba = frames[f][0]
            a = rgba[:, :, 3:4]
            img = rgba[:, :, :3] * a + img * (1 - a)
            m = outline_mask(tracks[name], f, oracle[f], shape)[:, :, None]
            ora = np.asarray((0.8, 0.1, 0.1), np.float32) * m + ora * (1 - m)
        _native.write_image(str(out / f"frame_{f + 1:04d}.png"), np.ascontiguousarray(img, np.float32), [])
        _native.write_image(str(out / f"oracle_{f + 1:04d}.png"), np.ascontiguousarray(ora, np.float32), [])
    print(f"rigid demo: {FRAMES} frames in {out}")


if __name__ == "__main__":
    main()
