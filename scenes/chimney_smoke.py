"""The chimney-smoke shot for LazyFluids (docs/media_exemplars.md): a house
whose chimney emits a thin plume of Mantaflow smoke, blown sideways, seen by
an orthographic camera.

    blender -b --factory-startup --python-exit-code 1 --python scenes/chimney_smoke.py -- --out out/chimney

Builds the scene, bakes the gas domain (resolution DOMAIN_RESOLUTION, a few
seconds), then writes, for the shot's frames SHOT:
* OUT/guides/: the guide cache of the smoke alone (the house hidden), through
  the add-on's guide render (tempera.blender.guide_render): `alpha` is the
  smoke's coverage, the target X_a of LazyFluids, and `fluid_velocity` its
  flow, from the domain's grids (Cycles' Vector pass is 0 on volumes);
* OUT/plate/frame_NNNN.png: the house without the smoke (Cycles, PLATE_SAMPLES),
  the background the stylized smoke is composited over, and
  OUT/beauty/frame_NNNN.png: the same with Cycles' smoke, to compare;
* OUT/chimney.blend: the baked scene (its cache in OUT/cache/).
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
SIMULATED = range(1, 38)  # the plume needs the first frames to rise; the guides also render SHOT[-1] + 1
SHOT = range(13, 37)  # 24 frames, one second at 24 fps
DOMAIN_RESOLUTION = 40
GUIDE_SAMPLES = 8
PLATE_SAMPLES = 16
CHIMNEY_TOP = (0.9, 0.0, 2.6)
INITIAL_VELOCITY = (3.0, 0.0, 2.0)  # the smoke leaves the chimney sideways and up (m/s)
WIND_STRENGTH = 3.5  # a wind along +x keeps blowing it sideways
SKY = (0.12, 0.25, 0.6)  # linear: a deep blue, so that the sooty smoke and its light rims both read against it


def _box(scene, name, size, location, color, rotation=(0.0, 0.0, 0.0)):
    obj = scene_kit.mesh_object(scene, name, lambda bm: bmesh.ops.create_cube(bm, size=1.0),
                                scene_kit.material(name, color, 0.8), location)
    obj.scale = size
    obj.rotation_euler = rotation
    return obj


def build_house(scene):
    """Walls, a pitched roof (a box turned 45 degrees about the ridge) and the chimney."""
    return [
        _box(scene, "Walls", (2.4, 1.6, 1.4), (0, 0, 0.7), (0.85, 0.78, 0.62)),
        _box(scene, "Roof", (2.7, 1.25, 1.25), (0, 0, 1.4), (0.55, 0.16, 0.12), (math.pi / 4, 0, 0)),
        _box(scene, "Chimney", (0.3, 0.3, 0.9), (CHIMNEY_TOP[0], 0, CHIMNEY_TOP[2] - 0.45), (0.45, 0.3, 0.25)),
        _box(scene, "Ground", (12, 6, 0.1), (0, 0, -0.05), (0.3, 0.45, 0.22)),
    ]


def smoke_material():
    mat = bpy.data.materials.new("Smoke")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    volume = nodes.new("ShaderNodeVolumePrincipled")
    volume.inputs["Color"].default_value = (0.7, 0.72, 0.76, 1.0)
    volume.inputs["Density"].default_value = 4.0
    links.new(volume.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
    return mat


def build_smoke(scene, cache):
    """The gas domain beside and above the chimney, and the flow inside its top."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(2.3, 0, 3.9))
    domain = bpy.context.object
    domain.name = "Smoke"
    domain.scale = (3.4, 1.0, 2.8)
    bpy.ops.object.transform_apply(scale=True)
    settings = domain.modifiers.new("Fluid", "FLUID")
    settings.fluid_type = "DOMAIN"
    d = settings.domain_settings
    d.domain_type = "GAS"
    d.resolution_max = DOMAIN_RESOLUTION
    d.cache_directory = str(cache)
    d.cache_type = "REPLAY"  # simulated by stepping the frames (Blender 3.4's bake_all fails in background)
    d.cache_frame_start, d.cache_frame_end = SIMULATED[0], SIMULATED[-1]
    d.use_dissolve_smoke = True
    d.dissolve_speed = 60  # a thin plume that thins out as it drifts
    d.vorticity = 0.15
    domain.data.materials.append(smoke_material())

    bpy.ops.mesh.primitive_cylinder_add(radius=0.1, depth=0.1, location=CHIMNEY_TOP)
    flow = bpy.context.object
    flow.name = "Smoke source"
    settings = flow.modifiers.new("Fluid", "FLUID")
    settings.fluid_type = "FLOW"
    f = settings.flow_settings
    f.flow_type, f.flow_behavior, f.flow_source = "SMOKE", "INFLOW", "MESH"
    f.smoke_color = (0.7, 0.72, 0.76)
    f.use_initial_velocity = True
    f.velocity_coord = INITIAL_VELOCITY
    f.surface_distance = 1.0
    flow.hide_render = True
    # A wind blows along its object's Z axis: turned to +x.
    bpy.ops.object.effector_add(type="WIND", location=CHIMNEY_TOP, rotation=(0, math.pi / 2, 0))
    bpy.context.object.field.strength = WIND_STRENGTH
    return domain, flow


def bake(scene, domain):
    """Simulates SIMULATED in order into the domain's replay cache and checks
    that the smoke reached the shot (the evaluated domain's density grid)."""
    for frame in SIMULATED:
        scene.frame_set(frame)
    scene.frame_set(SHOT[0])
    evaluated = domain.evaluated_get(bpy.context.evaluated_depsgraph_get())
    density = evaluated.modifiers["Fluid"].domain_settings.density_grid
    if not len(density) or max(density) <= 0:
        raise RuntimeError(f"no smoke in the domain at frame {SHOT[0]}: the simulation failed")


def build(scene, cache):
    scene_kit.clear_scene(scene)
    house = build_house(scene)
    domain, _ = build_smoke(scene, cache)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 3.2
    camera.location = (2.0, -10, 3.1)
    camera.rotation_euler = (math.pi / 2, 0, 0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", type="SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(50), 0, math.radians(-30))
    scene.collection.objects.link(sun)
    scene_kit.set_world(scene, SKY)
    scene.render.engine = "CYCLES"
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = SHOT[0], SHOT[-1]
    return house, domain


def render_frames(scene, folder, hidden=()):
    """SHOT rendered opaque at PLATE_SAMPLES into folder/frame_NNNN.png, with `hidden` left out."""
    for obj in hidden:
        obj.hide_render = True
    scene.render.film_transparent = False
    try:
        for frame in SHOT:
            scene_kit.render_png(scene, folder / f"frame_{frame:04d}.png", PLATE_SAMPLES, frame)
    finally:
        for obj in hidden:
            obj.hide_render = False
        scene.render.film_transparent = True


def render_smoke_guides(scene, house, out):
    """The guide cache of the smoke alone: the house hidden, so alpha is the smoke's."""
    for obj in house:
        obj.hide_render = True
    try:
        scene_kit.render_shot_guides(scene, SHOT, out / "guides", {"samples": GUIDE_SAMPLES, "ld12e_samples": 4},
                                     "chimney")
    finally:
        for obj in house:
            obj.hide_render = False


def main():
    out = scene_kit.script_out_dir("scenes/chimney_smoke.py", ROOT / "out" / "chimney")
    scene = bpy.context.scene
    house, domain = build(scene, out / "cache")
    bake(scene, domain)
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "chimney.blend"))
    render_smoke_guides(scene, house, out)
    render_frames(scene, out / "plate", hidden=[domain])
    render_frames(scene, out / "beauty")
    print(f"chimney: frames {SHOT[0]}-{SHOT[-1]} in {out}")


if __name__ == "__main__":
    main()
