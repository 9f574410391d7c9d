"""tempera.blender.compat in this Blender (3.4, 4.5 and 5.0 run the same tests)."""
import bpy
import pytest
from tempera.blender import compat


@pytest.fixture()
def scene():
    scene = bpy.data.scenes.new("Compat test")
    yield scene
    bpy.data.scenes.remove(scene)


def test_multilayer_exr_can_be_chosen_and_restored(scene):
    settings = scene.render.image_settings
    names = [n for n in compat.IMAGE_FORMAT_SETTINGS if hasattr(settings, n)]
    saved = [(n, getattr(settings, n)) for n in names]
    compat.set_file_format(settings, "OPEN_EXR_MULTILAYER")
    settings.color_depth = "32"
    assert settings.file_format == "OPEN_EXR_MULTILAYER"
    for name, value in saved:  # in IMAGE_FORMAT_SETTINGS order, as guide_render restores them
        setattr(settings, name, value)
    assert settings.file_format == "PNG" and [(n, getattr(settings, n)) for n in names] == saved


def test_compositor_tree_is_made_and_found(scene):
    assert compat.compositor_node_tree(scene) is None or not compat.compositor_node_tree(scene).nodes
    tree = compat.compositor_node_tree(scene, create=True)
    assert tree is not None and tree.bl_idname == "CompositorNodeTree"
    assert compat.compositor_node_tree(scene) == tree


def test_sequencer_strips(scene, tmp_path):
    import numpy as np
    import tempera

    path = tmp_path / "frame_0001.png"
    tempera.write_image(str(path), np.zeros((4, 4, 3), np.float32))
    editor = scene.sequence_editor_create()
    strips = compat.sequencer_strips(editor)
    strip = strips.new_image("Still", str(path), channel=1, frame_start=1)
    assert [s.name for s in compat.sequencer_strips(editor)] == [strip.name]


def test_principled_sockets_by_their_3x_names():
    material = bpy.data.materials.new("Compat material")
    try:
        material.use_nodes = True
        node = material.node_tree.nodes["Principled BSDF"]
        for name in ("Emission", "Specular", "Transmission", "Base Color"):
            assert compat.principled_socket(node, name).is_linked is False
        with pytest.raises(KeyError, match="has no input 'Sparkle'"):
            compat.principled_socket(node, "Sparkle")
    finally:
        bpy.data.materials.remove(material)


def test_fcurves_of_animated_and_still_objects(scene):
    obj = bpy.data.objects.new("Compat mover", None)
    scene.collection.objects.link(obj)
    try:
        assert compat.action_fcurves(obj) == []
        obj.keyframe_insert("location", frame=1)
        curves = compat.action_fcurves(obj)
        assert sorted((c.data_path, c.array_index) for c in curves) == [("location", i) for i in range(3)]
    finally:
        bpy.data.objects.remove(obj)


def test_exr_pass_names_short_or_long():
    long_file = ["ViewLayer.Diffuse Direct.R", "ViewLayer.Combined.R"]
    short_file = ["ViewLayer.DiffDir.R", "ViewLayer.Combined.R"]
    assert compat.exr_pass_name(long_file, "ViewLayer", "DiffDir") == "Diffuse Direct"
    assert compat.exr_pass_name(short_file, "ViewLayer", "DiffDir") == "DiffDir"
    assert compat.exr_pass_name(long_file, "ViewLayer", "Combined") == "Combined"
    assert compat.exr_pass_name([], "ViewLayer", "DiffDir") == "DiffDir"  # the error then names it


def test_corner_normals_of_a_flat_quad():
    import numpy as np

    mesh = bpy.data.meshes.new("Compat quad")
    try:
        mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
        normals = compat.corner_normals(mesh)
        assert normals.shape == (4, 3)
        np.testing.assert_allclose(normals, [[0, 0, 1]] * 4, atol=1e-6)
    finally:
        bpy.data.meshes.remove(mesh)


def test_eevee_engine_id_is_accepted(scene):
    scene.render.engine = compat.eevee_engine()
    assert scene.render.engine == compat.eevee_engine()
