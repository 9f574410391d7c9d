"""tempera.stylit_guides: StyLit's light-path guides from Blender passes."""
import numpy as np
import pytest

from tempera.color import linear_to_srgb
from tempera.stylit_guides import GUIDE_NAMES, REQUIRED_PASSES, read_stylit_passes, stylit_guides, tonemap


def random_passes(seed=0, shape=(6, 8)):
    rng = np.random.default_rng(seed)
    passes = {name: rng.uniform(0.0, 2.0, (*shape, 3)).astype(np.float32) for name in REQUIRED_PASSES}
    passes["DiffCol"] = rng.uniform(0.0, 1.0, (*shape, 3)).astype(np.float32)
    passes["GlossCol"] = rng.uniform(0.0, 1.0, (*shape, 3)).astype(np.float32)
    passes["Combined"] = rng.uniform(0.0, 3.0, (*shape, 4)).astype(np.float32)  # RGBA
    return passes


def test_names_shapes_and_range():
    guides = stylit_guides(random_passes())
    assert [name for name, _ in guides] == list(GUIDE_NAMES) == ["FULL", "LDE", "LSE", "L.*DDE"]
    for name, guide in guides:
        assert guide.shape == (6, 8, 3), name
        assert guide.dtype == np.float32, name
        assert guide.min() >= 0.0 and guide.max() < 1.0, name


def test_light_path_products():
    passes = random_passes(1)
    guides = dict(stylit_guides(passes))
    np.testing.assert_allclose(guides["FULL"], tonemap(passes["Combined"][:, :, :3]), atol=1e-6)
    np.testing.assert_allclose(guides["LDE"], tonemap(passes["DiffDir"] * passes["DiffCol"]), atol=1e-6)
    np.testing.assert_allclose(guides["LSE"], tonemap(passes["GlossDir"] * passes["GlossCol"]), atol=1e-6)
    np.testing.assert_allclose(guides["L.*DDE"], tonemap(passes["DiffInd"] * passes["DiffCol"]), atol=1e-6)


def test_combined_alpha_is_ignored():
    passes = random_passes(2)
    a = dict(stylit_guides(passes))["FULL"]
    passes["Combined"][:, :, 3] = 0.0
    np.testing.assert_array_equal(dict(stylit_guides(passes))["FULL"], a)


def test_tonemap_values():
    x = np.array([0.0, 1.0, 3.0, 1e9], dtype=np.float32)
    expected = linear_to_srgb(np.array([0.0, 0.5, 0.75, 1.0]))
    np.testing.assert_allclose(tonemap(x), expected, atol=1e-5)
    np.testing.assert_array_equal(tonemap(np.array([-1.0, np.nan])), [0.0, 0.0])
    ramp = tonemap(np.linspace(0.0, 50.0, 2001))
    assert np.all(np.diff(ramp) > 0)  # strictly increasing: highlights stay distinct


def test_per_pixel_so_exemplar_and_target_are_normalized_alike():
    """No image-dependent normalization: a pixel's guide values depend only on
    its own pass values, so equal lighting gives equal guides in the exemplar
    and in any target, whatever else the images hold."""
    passes = random_passes(3, shape=(10, 12))
    whole = stylit_guides(passes)
    crop = stylit_guides({name: p[2:7, 3:9] for name, p in passes.items()})
    brighter = dict(passes, Combined=passes["Combined"] * np.float32(4.0))
    brighter["Combined"][2:7, 3:9] = passes["Combined"][2:7, 3:9]
    for (name, full), (_, part), (_, other) in zip(whole, crop, stylit_guides(brighter)):
        np.testing.assert_array_equal(full[2:7, 3:9], part, err_msg=name)
        np.testing.assert_array_equal(other[2:7, 3:9], part, err_msg=name)


def test_missing_pass_and_size_mismatch():
    passes = random_passes()
    del passes["GlossCol"]
    with pytest.raises(ValueError, match="GlossCol"):
        stylit_guides(passes)
    passes = random_passes()
    passes["DiffInd"] = passes["DiffInd"][:5]
    with pytest.raises(ValueError, match="differ in size"):
        stylit_guides(passes)
    passes = random_passes()
    passes["DiffDir"] = passes["DiffDir"][:, :, 0]
    with pytest.raises(ValueError, match="DiffDir"):
        stylit_guides(passes)


def test_read_stylit_passes_from_multilayer_exr(tmp_path):
    import tempera
    from tempera.passes import channel_names

    passes = random_passes(4)
    names, channels = [], []
    for name in REQUIRED_PASSES:
        names += channel_names(name, "Layer")
        channels.append(passes[name])
    path = tmp_path / "frame.exr"
    tempera.write_image(str(path), np.concatenate(channels, axis=2), names)
    read = read_stylit_passes(path, "Layer")
    assert sorted(read) == sorted(REQUIRED_PASSES)
    for name in REQUIRED_PASSES:
        np.testing.assert_array_equal(read[name], passes[name])
