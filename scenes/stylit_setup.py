"""A scene lit and painted for StyLit the way Creative Flow+ sets scenes up
(creativefloworg/creativeflow, blender/stylit_util.py; re-written here, not
copied): the scene's lights are replaced by one point light between the
camera and the subject, to the camera's right, of radius 0.3 d and power
800 d W (d: the camera's distance to the subject) whose own Max Bounces is 0;
the subject gets a Mix Shader of a red Diffuse and a red Glossy; the other
meshes lose their materials (Cycles' default surface). Used by
bench/bench_lpe_user_scene.py and bench/make_user_shot.py on dcharata/StyLit's
lpe_render_a.blend.
"""
import bpy
from mathutils import Matrix, Vector


def stylit_material():
    """Creative Flow+'s StyLit material: a Mix Shader (0.5) of a red Diffuse
    (roughness 0.25) and a red Glossy (roughness 0.1)."""
    mat = bpy.data.materials.new("stylit red")
    mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    d = tree.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value, d.inputs["Roughness"].default_value = (1, 0, 0, 1), 0.25
    g = tree.nodes.new("ShaderNodeBsdfGlossy")
    g.inputs["Color"].default_value, g.inputs["Roughness"].default_value = (1, 0.05, 0.05, 1), 0.1
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(d.outputs[0], mix.inputs[1])
    tree.links.new(g.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return mat


def set_up_for_stylit(scene, subject_name):
    for obj in [o for o in scene.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(obj)
    subject = scene.objects[subject_name]
    for obj in scene.objects:
        if obj.type == "MESH":
            obj.data.materials.clear()
    subject.data.materials.append(stylit_material())
    camera = scene.camera
    centre = subject.matrix_world @ (sum((Vector(c) for c in subject.bound_box), Vector()) / 8)
    distance = (camera.location - centre).length
    # Creative Flow+ draws the angle in [fov / 2, fov] and the distance in
    # [0.5, 0.75] d at random; the middles here.
    turn = Matrix.Rotation(-0.75 * camera.data.angle, 4, "Y")
    offset = camera.matrix_world.to_quaternion() @ turn.to_quaternion() @ Vector((0, 0, -0.625 * distance))
    data = bpy.data.lights.new("stylit key", "POINT")
    data.energy = 800.0 * distance
    data.shadow_soft_size = 0.3 * distance
    data.cycles.max_bounces = 0
    light = bpy.data.objects.new("stylit key", data)
    light.location = camera.location + offset
    scene.collection.objects.link(light)
    return {"distance": distance, "radius": data.shadow_soft_size, "power": data.energy}
