"""The growing-ink shot for Fluidymation (docs/media_exemplars.md): a blot
of ink, a flat mesh of wavy outline, that grows over a sheet of paper,
lobes unevenly, while the camera looks straight down.

    blender -b --factory-startup --python-exit-code 1 --python scenes/growing_ink.py -- --out out/ink

Writes OUT/guides/, the guide cache of SHOT through the add-on's guide render
(tempera.blender.guide_render): the blot's object mask `mask.OB_Ink` (the
target mask of Fluidymation) and its `velocity_forward` / `velocity_backward`
(the exact target flow: the blot is one mesh whose shape key and scale are
animated, so the Vector pass follows its outline), OUT/paper.png (the paper
alone, the background of the stylized ink) and OUT/ink.blend.
"""
import math
import sys
from pathlib import Path

import bmesh
import bpy

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
sys.path.insert(0, str(ROOT / "scenes"))
import scene_kit  # noqa: E402

RESOLUTION = (256, 192)
SHOT = range(1, 25)  # 24 frames, one second at 24 fps
GUIDE_SAMPLES = 8
OUTLINE_POINTS = 96
START_SCALE, END_SCALE = 0.25, 0.85  # the blot's size at the first and the last frame
PAPER_COLOR = (0.92, 0.9, 0.84)
# Lobes of the outline: (number around, relative amplitude, phase) before and after growing.
LOBES_START = ((3, 0.10, 0.3), (5, 0.06, 1.1))
LOBES_END = ((3, 0.16, 0.8), (5, 0.12, 2.0), (8, 0.05, 0.4))


def _outline(lobes):
    """Points of the blot's outline, radius 1 modulated by the lobes."""
    points = []
    for i in range(OUTLINE_POINTS):
        angle = 2 * math.pi * i / OUTLINE_POINTS
        r = 1 + sum(a * math.cos(k * angle + p) for k, a, p in lobes)
        points.append((r * math.cos(angle), r * math.sin(angle), 0.0))
    return points


def add_blot(scene):
    """The ink blot: a filled polygon on z = 0.01 with a shape key to the grown
    outline, both animated linearly over SHOT (with the object's scale)."""
    def build(bm):
        centre = bm.verts.new((0, 0, 0))
        ring = [bm.verts.new(p) for p in _outline(LOBES_START)]
        for a, b in zip(ring, ring[1:] + ring[:1]):
            bm.faces.new((centre, a, b))

    ink = scene_kit.mesh_object(scene, "Ink", build, scene_kit.material("Ink", (0.05, 0.08, 0.3), 0.9),
                                (0, 0, 0.01))
    ink.shape_key_add(name="Basis")
    grown = ink.shape_key_add(name="Grown")
    for i, p in enumerate(_outline(LOBES_END)):
        grown.data[i + 1].co = p
    for frame, value, scale in ((SHOT[0], 0.0, START_SCALE), (SHOT[-1], 1.0, END_SCALE)):
        grown.value = value
        grown.keyframe_insert("value", frame=frame)
        ink.scale = (scale, scale, 1.0)
        ink.keyframe_insert("scale", frame=frame)
    from tempera.blender import compat

    for animated in (ink, ink.data.shape_keys):
        for fcurve in compat.action_fcurves(animated):
            for key in fcurve.keyframe_points:
                key.interpolation = "LINEAR"
    return ink


def build(scene):
    scene_kit.clear_scene(scene)
    paper = scene_kit.mesh_object(
        scene, "Paper", lambda bm: bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=3.0),
        scene_kit.material("Paper", PAPER_COLOR, 1.0), (0, 0, 0))
    ink = add_blot(scene)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 3.6
    camera.location = (0, 0, 5)  # looking straight down, x right, y up on the paper
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", type="SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    scene_kit.set_world(scene, (0.3, 0.3, 0.3))
    scene.render.engine = "CYCLES"
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = SHOT[0], SHOT[-1]
    return paper, ink


def render_paper(scene, ink, out):
    """OUT/paper.png: the sheet without the ink."""
    ink.hide_render = True
    scene_kit.render_png(scene, out / "paper.png", GUIDE_SAMPLES)
    ink.hide_render = False


def main():
    out = scene_kit.script_out_dir("scenes/growing_ink.py", ROOT / "out" / "ink")
    scene = bpy.context.scene
    _, ink = build(scene)
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "ink.blend"))
    scene_kit.render_shot_guides(scene, SHOT, out / "guides",
                                 {"samples": GUIDE_SAMPLES, "ld12e_samples": 4, "masks": "objects"}, "ink")
    render_paper(scene, ink, out)
    print(f"ink: frames {SHOT[0]}-{SHOT[-1]} in {out}")


if __name__ == "__main__":
    main()
