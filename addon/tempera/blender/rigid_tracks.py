"""Tracks of a baked rigid-body world, projected through the scene camera,
into the guide cache's tracks.json (the math: tempera.methods.rigid.rigid_tracks).

For every object and frame (after frame_set, so the bake is evaluated):
the screen centroid (the origin, which the recommended setup puts at the
centre of mass), theta (the projected local X axis), the screen radius
(half the largest dimension, projected at the object's depth), and a warning
when the object turns about an axis more than 10 degrees from the view
axis, since the method is 2D; the depth (distance along the view axis, for
compositing the drawn bodies far to near). Gravity is projected the same way, in px per
frame^2, for the event finder.
"""
import math

from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

from ..methods.rigid import rigid_tracks


def _pixel(scene, camera, co, width, height):
    p = world_to_camera_view(scene, camera, co)
    return (p.x * width, (1.0 - p.y) * height)


def _size(scene):
    r = scene.render
    return (round(r.resolution_x * r.resolution_percentage / 100),
            round(r.resolution_y * r.resolution_percentage / 100))


def extract_tracks(scene, objects, camera=None):
    """({name: track}, gravity_px, warnings) over the scene's frame range;
    the scene is back at its current frame afterwards."""
    current = scene.frame_current
    try:
        return _extract(scene, objects, camera)
    finally:
        scene.frame_set(current)


def _extract(scene, objects, camera):
    camera = camera or scene.camera
    if camera is None:
        raise ValueError("the scene has no camera to project the rigid bodies through")
    width, height = _size(scene)
    fps = scene.render.fps / scene.render.fps_base
    frames = range(scene.frame_start, scene.frame_end + 1)
    samples = {o.name: {"c": [], "theta": [], "r": [], "q": [], "depth": []} for o in objects}
    view_axis = None
    gravity = (0.0, 0.0)
    for f in frames:
        scene.frame_set(f)
        view_axis = camera.matrix_world.to_3x3() @ Vector((0, 0, 1))
        for o in objects:
            m = o.matrix_world
            loc = m.translation
            c = _pixel(scene, camera, loc, width, height)
            reach = max(o.dimensions) / 2 or 1e-3
            x_axis = m.to_3x3() @ Vector((1, 0, 0))
            tip = _pixel(scene, camera, loc + x_axis.normalized() * reach, width, height)
            right = camera.matrix_world.to_3x3() @ Vector((1, 0, 0))
            rim = _pixel(scene, camera, loc + right.normalized() * reach, width, height)
            s = samples[o.name]
            s["c"].append(c)
            s["theta"].append(math.atan2(tip[1] - c[1], tip[0] - c[0]))
            s["r"].append(math.hypot(rim[0] - c[0], rim[1] - c[1]))
            s["q"].append(m.to_quaternion())
            s["depth"].append(-(camera.matrix_world.inverted() @ loc).z)
            if f == scene.frame_start and o is objects[0]:
                g = scene.gravity if scene.use_gravity else Vector((0, 0, 0))
                fall = _pixel(scene, camera, loc + g * (1.0 / fps) ** 2, width, height)
                gravity = (fall[0] - c[0], fall[1] - c[1])
    warnings = []
    for name, s in samples.items():
        for q0, q1 in zip(s["q"], s["q"][1:]):
            axis, angle = q0.rotation_difference(q1).to_axis_angle()
            if angle > 1e-3:
                text = rigid_tracks.planarity_warning(tuple(axis), tuple(view_axis))
                if text:
                    warnings.append(f"{name}: {text}")
                    break
    tracks = {}
    for name, s in samples.items():
        # Unwrap theta so that velocities of the angle stay small.
        theta = [s["theta"][0]]
        for t in s["theta"][1:]:
            theta.append(theta[-1] + math.remainder(t - theta[-1], 2 * math.pi))
        others = {n: (o["c"], o["r"]) for n, o in samples.items() if n != name}
        tracks[name] = rigid_tracks.make_track(s["c"], theta, s["r"], gravity, others=others)
        tracks[name]["depth"] = s["depth"]
    return tracks, gravity, warnings


def write_tracks(scene, objects, cache_dir, camera=None):
    """Extracts the tracks and writes <cache>/tracks.json; returns the warnings."""
    tracks, gravity, warnings = extract_tracks(scene, objects, camera)
    rigid_tracks.write_tracks(cache_dir, tracks, scene.frame_start, gravity)
    return warnings


def rigid_body_objects(scene):
    """The active bodies of the scene's rigid-body world."""
    world = scene.rigidbody_world
    if world is None or world.collection is None:
        return []
    return [o for o in world.collection.objects if o.rigid_body and o.rigid_body.type == "ACTIVE"]

