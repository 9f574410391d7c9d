"""Small still scenes for the light-path-expression tracer: its validation
against Cycles (blender_tests/test_lpe.py) and its figure
(docs/make_lpe_figures.py). A floor, a back wall, a red cube and a metal
sphere under one light, seen from the front with background above the wall.

    scene = build_scene("LPE", size=(96, 72), sphere="metal", light="POINT")

sphere: "metal" (rough gold), "mirror" (perfect mirror), "diffuse" (a Diffuse
BSDF) or None; diffuse_only=True makes the floor, wall and cube (and a metal
sphere, not a mirror) plain Diffuse BSDFs (no glossy lobe: with a diffuse sphere, Cycles' DiffInd with caustics
off is exactly L.*DDE); objects=False leaves only the floor (light power checks).
"""
import math

import bmesh
import bpy
from mathutils import Vector

import scene_kit  # noqa: E402  (scenes/ is on sys.path wherever this module is imported)

SPHERE_CENTRE = (0.75, -0.1, 0.55)
# name -> (type, power or strength, location, point it aims at, extra settings)
LIGHTS = {
    "POINT": ("POINT", 400.0, (1.5, -1.5, 3.0), (0, 0, 0), {"shadow_soft_size": 0.1}),
    "SPOT": ("SPOT", 600.0, (1.0, -1.5, 3.0), (0, 0, 0),
             {"shadow_soft_size": 0.1, "spot_size": math.radians(70), "spot_blend": 0.2}),
    "SUN": ("SUN", 3.0, (0, 0, 5), (-1.5, 2.0, 2.0), {"angle": math.radians(2)}),
    "AREA": ("AREA", 300.0, (0.5, -1.0, 2.5), (0.3, 0, 0), {"shape": "RECTANGLE", "size": 1.0, "size_y": 0.5}),
    # Low and to the side, aimed at the sphere: a mirror sphere throws a caustic onto the floor.
    "CAUSTIC": ("AREA", 500.0, (2.0, -0.8, 1.8), SPHERE_CENTRE, {"shape": "DISK", "size": 1.0}),
}


def _material(name, color, diffuse_only, **principled):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    tree = mat.node_tree
    if diffuse_only:
        tree.nodes.remove(tree.nodes["Principled BSDF"])
        node = tree.nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = (*color, 1)
        tree.links.new(node.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
        return mat
    node = tree.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (*color, 1)
    from tempera.blender import compat

    for key, value in principled.items():
        compat.principled_socket(node, key).default_value = value
    return mat


def _object(scene, name, build, material, location=(0, 0, 0), rotation=(0, 0, 0), smooth=False):
    """scene_kit.mesh_object, turned by the Euler angles `rotation`."""
    obj = scene_kit.mesh_object(scene, name, build, material, location, smooth)
    obj.rotation_euler = rotation
    return obj


def _aim(location, target):
    """Euler rotation pointing local -Z from `location` at `target`, +Y up."""
    return (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def build_scene(name="LPE", size=(96, 72), sphere="metal", light="POINT", diffuse_only=False, objects=True):
    scene = bpy.data.scenes.new(name)
    scene.render.engine = "CYCLES"
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.frame_start = scene.frame_end = scene.frame_current = 1
    # The same bounce limit for both renderers, deep enough for what is left to be negligible.
    cycles = scene.cycles
    cycles.max_bounces = cycles.diffuse_bounces = cycles.glossy_bounces = 6
    scene.world = None  # black: all light comes from the light

    def plane(bm):
        bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.0)

    grey = 0.5
    _object(scene, "Floor", plane, _material("Floor", (grey, grey, grey), diffuse_only, Roughness=0.6),
            location=(0, 0, 0), rotation=(0, 0, 0)).scale = (2.5, 2.0, 1)
    if objects:
        wall = _object(scene, "Wall", plane, _material("Wall", (0.6, 0.45, 0.3), diffuse_only, Roughness=0.7),
                       location=(0, 2.0, 1.0), rotation=(math.radians(90), 0, 0))
        wall.scale = (2.5, 1.0, 1)
        _object(scene, "Cube", lambda bm: bmesh.ops.create_cube(bm, size=0.8),
                _material("Red", (0.7, 0.15, 0.1), diffuse_only, Roughness=0.5),
                location=(-0.8, 0.3, 0.4), rotation=(0, 0, math.radians(30)))
        if sphere:
            kind = sphere
            settings = {"metal": ((0.9, 0.65, 0.3), {"Metallic": 1.0, "Roughness": 0.25}),
                        "mirror": ((0.95, 0.95, 0.95), {"Metallic": 1.0, "Roughness": 0.0}),
                        "diffuse": ((0.2, 0.3, 0.7), {"Specular": 0.0})}[kind]
            _object(scene, "Sphere",
                    lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=0.55),
                    _material("Sphere", settings[0], (diffuse_only and kind != "mirror") or kind == "diffuse",
                              **settings[1]),
                    location=SPHERE_CENTRE, smooth=True)

    kind, power, location, target, extra = LIGHTS[light]
    data = bpy.data.lights.new(f"{name} {light}", kind)
    data.energy = power
    for key, value in extra.items():
        setattr(data, key, value)
    from tempera.blender import compat

    compat.hard_light_falloff(data)  # what the tracer models
    lamp = bpy.data.objects.new(f"{name} light", data)
    lamp.location = location
    lamp.rotation_euler = _aim(location, target)  # lights shine down their local -Z
    scene.collection.objects.link(lamp)

    camera = bpy.data.objects.new(f"{name} camera", bpy.data.cameras.new(f"{name} camera"))
    camera.data.lens = 35
    camera.location = (0.0, -5.5, 2.4)
    camera.rotation_euler = _aim(camera.location, (0.0, 0.4, 0.6))
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def remove_scene(scene):
    for obj in list(scene.collection.all_objects):
        data = obj.data
        bpy.data.objects.remove(obj)
        if data is not None and data.users == 0:
            if isinstance(data, bpy.types.Mesh):
                bpy.data.meshes.remove(data)
            elif isinstance(data, bpy.types.Light):
                bpy.data.lights.remove(data)
            elif isinstance(data, bpy.types.Camera):
                bpy.data.cameras.remove(data)
    bpy.data.scenes.remove(scene)
