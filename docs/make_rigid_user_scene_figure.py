"""Makes docs/images/rigid_user_scene.png: the rigid-body method on a scene
made only with Blender's operators (scenes/rigid_fractured_cube.py: a cube
broken by Cell Fracture falling onto a plane). Top: Blender's render (Cycles,
a few samples); bottom: the shards drawn from the generated tumbling-box
exemplar, composited by depth on paper.

    blender -b --factory-startup --python docs/make_rigid_user_scene_figure.py
"""
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "addon"), str(ROOT / "scenes")]
import rigid_fractured_cube  # noqa: E402
from tempera import _native
from tempera.methods.rigid import rigid  # noqa: E402
from tempera.blender import rigid_tracks as brt  # noqa: E402

W, H = 480, 270
SHOWN = (10, 14, 17, 24)  # falling, the impact, breaking apart, scattered
PAPER = np.asarray((0.97, 0.96, 0.92), np.float32)
CROP = (slice(60, 230), slice(100, 380))


def box_exemplar():
    track = _native.bouncing_ball((80, 80), (6.0, 0), 28, 2.0, 220, 0.65, 0.12, 36)
    return rigid.fit_exemplar(track, rigid.generated_exemplar(track, W, H, shape="box", line_width=2.0), shape="box")


def render(scene, frame, folder):
    scene.frame_set(frame)
    scene.render.filepath = str(Path(folder) / f"render_{frame:04d}.png")
    bpy.ops.render.render(write_still=True)
    return np.asarray(_native.read_image(scene.render.filepath, None), np.float32)[:, :, :3]


def main():
    if not rigid_fractured_cube.has_cell_fracture():
        sys.exit("make_rigid_user_scene_figure.py: this Blender has no Cell Fracture add-on")
    scene = bpy.context.scene
    for o in list(scene.objects):
        bpy.data.objects.remove(o)
    shards = rigid_fractured_cube.build(scene, (W, H))
    scene.render.engine, scene.cycles.samples, scene.cycles.use_denoising = "CYCLES", 8, False
    bpy.ops.object.light_add(type="SUN", location=(2, -4, 6), rotation=(0.6, 0.3, 0))
    tracks, _gravity, warnings = brt.extract_tracks(scene, shards)
    print("warnings:", *warnings, sep="\n  ")
    exemplar = box_exemplar()
    drawn = {o.name: rigid.stylize([exemplar], tracks[o.name], W, H, symmetry=4) for o in shards}
    top, bottom = [], []
    with tempfile.TemporaryDirectory() as folder:
        for f in SHOWN:
            top.append(render(scene, f, folder)[CROP])
            img = np.broadcast_to(PAPER, (H, W, 3)).copy()
            i = f - scene.frame_start
            for name in sorted(drawn, key=lambda n: -tracks[n]["depth"][i]):  # far to near
                rgba = drawn[name][i][0]
                img = rgba[:, :, :3] * rgba[:, :, 3:] + img * (1 - rgba[:, :, 3:])
            bottom.append(img[CROP])
    figure = np.concatenate([np.concatenate(top, 1), np.concatenate(bottom, 1)], 0)
    out = ROOT / "docs" / "images" / "rigid_user_scene.png"
    _native.write_image(str(out), np.ascontiguousarray(figure, np.float32), [])
    print("wrote", out)


if __name__ == "__main__":
    main()
