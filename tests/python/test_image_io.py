"""Image IO of the native module, through the `tempera` package."""
import os

import numpy as np
import pytest

import tempera

CHANNELS = ["ViewLayer.DiffCol.R", "ViewLayer.DiffCol.G", "ViewLayer.DiffCol.B", "ViewLayer.Depth.Z"]


@pytest.fixture
def image():
    return np.random.default_rng(7).normal(size=(5, 8, 4)).astype(np.float32) * 10


def test_missing_file_raises_file_not_found_naming_it(tmp_path):
    missing = tmp_path / "no_such_frame.exr"
    with pytest.raises(FileNotFoundError, match="no_such_frame.exr"):
        tempera.read_image(str(missing))
    with pytest.raises(FileNotFoundError, match="no_such_frame.exr"):
        tempera.image_info(str(missing))


@pytest.mark.parametrize("name", ["x.png", "x.exr"])
def test_corrupt_file_raises_os_error_naming_it(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(b"this is not an image\x00\xff\x13" * 40)
    for call in (tempera.read_image, tempera.image_info):
        with pytest.raises(OSError) as excinfo:
            call(str(path))
        assert not isinstance(excinfo.value, FileNotFoundError)
        assert str(path) in str(excinfo.value)


def test_folder_is_not_an_image(tmp_path):
    with pytest.raises(OSError, match="folder"):
        tempera.read_image(str(tmp_path))


def test_exr_round_trip_with_named_channels(tmp_path, image):
    path = tmp_path / "guides.exr"
    tempera.write_image(str(path), image, CHANNELS)
    info = tempera.image_info(str(path))
    assert (info["width"], info["height"]) == (8, 5)
    assert sorted(info["channels"]) == sorted(CHANNELS)
    back = tempera.read_image(str(path), CHANNELS)
    assert back.dtype == np.float32 and back.shape == image.shape
    np.testing.assert_array_equal(back, image)  # float EXR is lossless


def test_select_channels_by_name_in_any_order(tmp_path, image):
    path = tmp_path / "guides.exr"
    tempera.write_image(str(path), image, CHANNELS)
    picked = tempera.read_image(str(path), ["ViewLayer.Depth.Z", "ViewLayer.DiffCol.R"])
    np.testing.assert_array_equal(picked, image[:, :, [3, 0]])
    with pytest.raises(ValueError, match="ViewLayer.Normal.X"):
        tempera.read_image(str(path), ["ViewLayer.Normal.X"])


def test_two_dimensional_array_is_one_channel(tmp_path):
    plane = np.arange(12, dtype=np.float32).reshape(3, 4) / 7
    path = tmp_path / "mask.exr"
    tempera.write_image(str(path), plane, ["mask"])
    back = tempera.read_image(str(path))
    assert back.shape == (3, 4, 1)
    np.testing.assert_array_equal(back[:, :, 0], plane)
    np.testing.assert_array_equal(tempera.read_image(str(path), ["mask"])[:, :, 0], plane)


def test_non_float32_input_is_converted(tmp_path):
    path = tmp_path / "f64.exr"
    data = np.linspace(0, 1, 24, dtype=np.float64).reshape(2, 4, 3)
    tempera.write_image(str(path), data)
    np.testing.assert_allclose(tempera.read_image(str(path)), data, rtol=1e-7)


def test_png_is_clamped_to_unit_range(tmp_path):
    path = tmp_path / "clamped.png"
    data = np.array([[[-1.0], [0.5], [2.0], [np.nan]]], dtype=np.float32)
    tempera.write_image(str(path), data)
    back = tempera.read_image(str(path))[0, :, 0]
    np.testing.assert_allclose(back, [0.0, 128 / 255, 1.0, 0.0], atol=1 / 255)


@pytest.mark.parametrize("shape", [(2, 3, 4, 1), (7,), (0, 4, 3)])
def test_bad_array_shape_raises_value_error(tmp_path, shape):
    with pytest.raises(ValueError):
        tempera.write_image(str(tmp_path / "bad.exr"), np.zeros(shape, dtype=np.float32))
    assert os.listdir(tmp_path) == []


def test_channel_name_count_must_match(tmp_path, image):
    with pytest.raises(ValueError, match="channel names"):
        tempera.write_image(str(tmp_path / "x.exr"), image, ["R", "G"])
    assert os.listdir(tmp_path) == []


def test_write_into_missing_folder_fails_and_leaves_nothing(tmp_path, image):
    target = tmp_path / "not_there" / "frame.exr"
    with pytest.raises(OSError, match="not_there"):
        tempera.write_image(str(target), image)
    assert os.listdir(tmp_path) == []


def test_unknown_format_fails_and_leaves_nothing(tmp_path, image):
    with pytest.raises(OSError, match="frame.nosuchformat"):
        tempera.write_image(str(tmp_path / "frame.nosuchformat"), image)
    assert os.listdir(tmp_path) == []


def test_overwrite_replaces_the_file(tmp_path, image):
    path = tmp_path / "frame.exr"
    tempera.write_image(str(path), image)
    tempera.write_image(str(path), image * 2)
    np.testing.assert_array_equal(tempera.read_image(str(path)), image * 2)
    assert os.listdir(tmp_path) == ["frame.exr"]


def test_a_failed_final_rename_names_the_reason(tmp_path):
    """Writing onto a folder fails at the last step, the rename; the message
    says why (it once said 'Success': the cleanup reset the error)."""
    import tempera

    target = tmp_path / "frame.png"
    target.mkdir()
    (target / "keep").write_text("x")  # a non-empty folder cannot be replaced
    with pytest.raises(OSError) as err:
        tempera.write_image(str(target), np.zeros((4, 4, 3), np.float32))
    assert "Success" not in str(err.value) and "frame.png" in str(err.value)
    assert [p.name for p in tmp_path.iterdir()] == ["frame.png"]  # no temporary file left
