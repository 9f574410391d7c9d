"""The Tempera add-on inside Blender, installed from the add-on zip."""
import os
from types import SimpleNamespace
from pathlib import Path

import bpy
import numpy as np
import pytest

import tempera
from conftest import ADDON, INSTALL, disable, enable, is_enabled, registered_tempera_classes

EXPECTED_CLASSES = ["TEMPERA_OT_choose_painting", "TEMPERA_OT_painting_template", "TEMPERA_OT_register_painting",
                    "TEMPERA_OT_render_guides", "TEMPERA_OT_stylize", "TEMPERA_PT_output", "TemperaPreferences",
                    "TemperaSettings", "TemperaKeyframe", "TEMPERA_UL_keyframes", "TEMPERA_OT_add_keyframe",
                    "TEMPERA_OT_import_keyframe", "TEMPERA_OT_remove_keyframe", "TemperaLayer",
                    "TEMPERA_UL_tcia_layers", "TEMPERA_OT_add_tcia_layer", "TEMPERA_OT_remove_tcia_layer"]



def test_addon_is_enabled_from_the_installed_zip():
    assert is_enabled()
    installed = Path(os.environ["TEMPERA_TEST_SCRIPTS_DIR"])
    module_file = Path(tempera.__file__).resolve()
    # The zipped copy, not the source tree (which the Python tests use).
    repo_addon = Path(__file__).resolve().parent.parent / "addon"
    assert repo_addon not in module_file.parents
    if INSTALL == "legacy":
        assert module_file == installed / "addons" / "tempera" / "__init__.py"
        assert list(module_file.parent.glob("_native*.so")), "the zip carries no compiled module"
    else:
        # The extension folder holds the manifest, the shim and the wheel; the
        # package comes from the wheel, unpacked into Blender's extension site-packages.
        assert (installed / "blender_manifest.toml").is_file()
        assert list((installed / "wheels").glob("tempera_native-*.whl"))
        assert module_file.parent.parent.name == "site-packages"
        native = Path(tempera._native.__file__).resolve()
        assert native.parent.name == "tempera_native" and native.parent.parent == module_file.parent.parent
        # Blender unpacks wheels without file modes; the package gives its CLI the executable bit back.
        assert os.access(native.parent / "bin" / "tempera", os.X_OK)


def test_native_module_reads_and_writes_exr(tmp_path):
    rng = np.random.default_rng(1)
    image = rng.random((6, 9, 3), dtype=np.float32)
    names = ["ViewLayer.DiffCol.R", "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.B"]
    path = tmp_path / "guide.exr"
    tempera.write_image(str(path), image, names)
    info = tempera.image_info(str(path))
    assert (info["width"], info["height"]) == (9, 6)
    assert sorted(info["channels"]) == sorted(names)
    np.testing.assert_array_equal(tempera.read_image(str(path), names), image)
    assert tempera._native.__version__ == tempera.__version__


def test_bl_info_matches_package_version():
    assert tempera.bl_info["version"] == tuple(int(p) for p in tempera.__version__.split("."))
    assert bpy.app.version >= tempera.bl_info["blender"]


def test_classes_and_scene_settings_are_registered():
    assert hasattr(bpy.types, "TEMPERA_PT_output")
    assert registered_tempera_classes() == sorted(EXPECTED_CLASSES)
    assert bpy.types.TEMPERA_PT_output.bl_context == "output"
    assert bpy.types.TEMPERA_PT_output.bl_space_type == "PROPERTIES"
    settings = bpy.context.scene.tempera
    assert settings.output_dir == "//tempera/"
    # The panel's defaults are the engine's and StyLit's, from the native tables.
    import tempera

    engine = tempera.SynthesisOptions()
    assert settings.patch_size == engine.patch_size == 5
    assert settings.seed == engine.seed == 1
    assert settings.usage == engine.usage
    for guide in tempera._native.light_path_guides():
        assert getattr(settings, "weight_" + guide["name"].lower()) == pytest.approx(guide["weight"])
    usage_items = {item.identifier for item in settings.bl_rna.properties["usage"].enum_items}
    assert usage_items == set(tempera.USAGE_MODES)
    assert bpy.types.Scene.bl_rna.properties["tempera"].fixed_type.identifier == "TemperaSettings"


def test_addon_preferences_are_registered():
    prefs = bpy.context.preferences.addons[ADDON].preferences
    assert prefs is not None and type(prefs).__name__ == "TemperaPreferences"
    assert prefs.cli_path == ""


def test_patch_size_stays_odd_and_in_range():
    settings = bpy.context.scene.tempera
    try:
        settings.patch_size = 6
        assert settings.patch_size == 7
        settings.patch_size = 9
        assert settings.patch_size == 9
        settings.patch_size = 100
        assert settings.patch_size == 15
        settings.patch_size = 1
        assert settings.patch_size == 3
    finally:
        settings.patch_size = 5


def test_disable_leaves_no_trace():
    disable()
    assert not is_enabled()
    assert registered_tempera_classes() == []
    assert not hasattr(bpy.types, "TEMPERA_PT_output")
    assert not hasattr(bpy.types.Scene, "tempera")
    assert not hasattr(bpy.context.scene, "tempera")
    assert ADDON not in bpy.context.preferences.addons


def test_enable_disable_cycles():
    for _ in range(2):
        enable()
        assert registered_tempera_classes() == sorted(EXPECTED_CLASSES)
        assert bpy.context.scene.tempera.patch_size == 5
        disable()
        assert registered_tempera_classes() == []
        assert not hasattr(bpy.types.Scene, "tempera")
    enable()
    assert is_enabled()


def test_settings_survive_disable_and_enable():
    settings = bpy.context.scene.tempera
    settings.seed = 31
    disable()
    enable()
    assert bpy.context.scene.tempera.seed == 31
    bpy.context.scene.tempera.seed = 0


def test_settings_survive_save_and_reload(tmp_path):
    blend = tmp_path / "settings.blend"
    settings = bpy.context.scene.tempera
    settings.output_dir = "//stylized/shot_010/"
    settings.seed = 1234
    settings.patch_size = 9
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    assert blend.is_file()
    # Change them in memory, then load the file back: the saved values return.
    settings.output_dir, settings.seed, settings.patch_size = "//elsewhere/", 7, 3
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    loaded = bpy.context.scene.tempera
    assert (loaded.output_dir, loaded.seed, loaded.patch_size) == ("//stylized/shot_010/", 1234, 9)
    assert is_enabled()


class _Recorder:
    """Stands in for bpy.types.UILayout: records prop() and label() calls and
    checks that every drawn property exists."""

    def __init__(self, calls):
        self.calls = calls

    def prop(self, data, name, **kwargs):
        assert name in data.bl_rna.properties, f"{type(data).__name__} has no property {name!r}"
        self.calls.append(("prop", name))

    def label(self, text="", **kwargs):
        self.calls.append(("label", text))

    def operator(self, idname, **kwargs):
        category, _, name = idname.partition(".")
        getattr(getattr(bpy.ops, category), name).get_rna_type()  # KeyError if not registered
        self.calls.append(("operator", idname))
        return SimpleNamespace()  # the operator's properties, set by the panel

    def _sub(self, *args, **kwargs):
        return _Recorder(self.calls)

    def template_icon(self, icon_value=0, scale=1.0):
        self.calls.append(("template_icon", icon_value))

    def template_list(self, list_type, list_id, data, prop, active_data, active_prop, **kwargs):
        assert hasattr(bpy.types, list_type) and prop in data.bl_rna.properties
        self.calls.append(("template_list", prop))

    row = column = box = split = column_flow = _sub


def test_output_panel_draws_settings_with_the_frames_by_the_buttons():
    calls = []
    fake = type("FakePanel", (), {"layout": _Recorder(calls)})()
    bpy.types.TEMPERA_PT_output.draw(fake, bpy.context)
    props = [name for kind, name in calls if kind == "prop"]
    labels = [text for kind, text in calls if kind == "label"]
    assert props == ["guide_frame_range", "exemplar_source", "weight_full", "weight_lde", "weight_lse",
                     "weight_ldde", "weight_ld12e", "method", "quality", "usage", "temporal_weight", "warm_start", "patch_size",
                     "seed",
                     "noise_level",
                     "output_dir", "output_format", "make_video", "load_result",
                     "guide_dir", "guide_samples",
                     "guide_occlusion_epsilon", "guide_line_d_max", "guide_masks",
                     "guide_orientation_aov", "guide_lpe"]
    assert {"Exemplar", "Light Path Guides", "Synthesis", "Output", "Guides"} <= set(labels)
    assert [name for kind, name in calls if kind == "operator"] == [
        "tempera.stylize", "tempera.stylize", "tempera.render_guides", "tempera.painting_template",
        "tempera.register_painting"]
    # The frame range sits with the stylize buttons: right after them, before any box.
    order = [(kind, name) for kind, name in calls if kind in ("operator", "prop")]
    assert order[3] == ("prop", "guide_frame_range")
    # The version is in the panel's header.
    header = []
    bpy.types.TEMPERA_PT_output.draw_header_preset(type("FakePanel", (), {"layout": _Recorder(header)})(),
                                                   bpy.context)
    assert header == [("label", f"v{tempera.__version__}")]
    # LPE Samples only matter, and only show, once there are expressions.
    settings = bpy.context.scene.tempera
    settings.guide_lpe = "LDE"
    try:
        calls.clear()
        bpy.types.TEMPERA_PT_output.draw(fake, bpy.context)
    finally:
        settings.guide_lpe = ""
    assert [name for kind, name in calls if kind == "prop"][-2:] == ["guide_lpe", "guide_lpe_samples"]
    # Temporal Noise on: its width, Guided Noise, the map picker and the chosen map's field.
    settings.noise_level, settings.noise_map_source = 4, "OBJECT"
    try:
        calls.clear()
        bpy.types.TEMPERA_PT_output.draw(fake, bpy.context)
    finally:
        settings.noise_level, settings.noise_map_source = 0, "NONE"
    props = [name for kind, name in calls if kind == "prop"]
    assert props[props.index("noise_level") + 1:][:3] == ["noise_guided", "noise_map_source", "noise_map_object"]
    assert any(kind == "label" and text.startswith("f = 2.2 px") for kind, text in calls)


def test_preferences_draw_reports_the_cli(tmp_path):
    cli = os.environ.get("TEMPERA_CLI") or str(Path(__file__).resolve().parent.parent / "build" / "bin" / "tempera")
    prefs = bpy.context.preferences.addons[ADDON].preferences
    for path, expected in [(cli, f"tempera {tempera.__version__} at"), (str(tmp_path / "nope"), "not found")]:
        prefs.cli_path = path
        calls = []
        fake = type("FakePrefs", (), {"layout": _Recorder(calls), "cli_path": prefs.cli_path,
                                      "bl_rna": prefs.bl_rna})()
        type(prefs).draw(fake, bpy.context)
        assert any(expected in text for kind, text in calls if kind == "label"), calls
    prefs.cli_path = ""
