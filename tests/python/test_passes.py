import numpy as np
import pytest

import tempera
from tempera.app import passes


def test_channel_names_follow_blender_multilayer_exr():
    assert passes.channel_names("DiffDir") == ["ViewLayer.DiffDir.R", "ViewLayer.DiffDir.G", "ViewLayer.DiffDir.B"]
    assert passes.channel_names("Vector", "Shot") == [f"Shot.Vector.{c}" for c in "XYZW"]
    assert passes.channel_names("Combined")[-1] == "ViewLayer.Combined.A"


def test_unknown_pass_lists_known_ones():
    with pytest.raises(ValueError, match="DiffDir"):
        passes.channel_names("Diffuse")


def test_every_pass_has_a_view_layer_switch():
    for render_pass in passes.PASSES.values():
        assert render_pass.view_layer_property.startswith("use_pass_")
        assert render_pass.components


def test_read_pass(tmp_path):
    names = passes.channel_names("Normal") + passes.channel_names("DiffCol")
    data = np.random.default_rng(3).random((4, 5, 6), dtype=np.float32)
    path = tmp_path / "frame_0001.exr"
    tempera.write_image(str(path), data, names)
    np.testing.assert_array_equal(passes.read_pass(path, "DiffCol"), data[:, :, 3:])
    with pytest.raises(ValueError, match="ViewLayer.GlossDir.R"):
        passes.read_pass(path, "GlossDir")
