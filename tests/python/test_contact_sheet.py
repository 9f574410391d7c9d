import numpy as np
import pytest

from tempera import contact_sheet


def frames(n, h=4, w=6, c=3):
    return [np.full((h, w, c), i + 1, dtype=np.float32) for i in range(n)]


def test_grid_layout_and_gaps():
    sheet = contact_sheet(frames(4), columns=2, gap=3, background=-1)
    assert sheet.shape == (2 * 4 + 3, 2 * 6 + 3, 3) and sheet.dtype == np.float32
    assert (sheet[0:4, 0:6] == 1).all()
    assert (sheet[0:4, 9:15] == 2).all()
    assert (sheet[7:11, 0:6] == 3).all()
    assert (sheet[7:11, 9:15] == 4).all()
    assert (sheet[4:7, :] == -1).all()  # horizontal gap
    assert (sheet[:, 6:9] == -1).all()  # vertical gap


def test_default_columns_make_a_near_square_grid():
    sheet = contact_sheet(frames(5), gap=1, background=0)
    # ceil(sqrt(5)) = 3 columns, 2 rows; the sixth cell stays background.
    assert sheet.shape == (2 * 4 + 1, 3 * 6 + 2, 3)
    assert (sheet[5:9, 14:20] == 0).all()
    assert (sheet[5:9, 7:13] == 5).all()


def test_margin_and_per_channel_background():
    sheet = contact_sheet(frames(1), gap=5, margin=2, background=(0.1, 0.2, 0.3))
    assert sheet.shape == (4 + 4, 6 + 4, 3)
    np.testing.assert_allclose(sheet[0, 0], [0.1, 0.2, 0.3])
    assert (sheet[2:6, 2:8] == 1).all()


def test_fewer_images_than_columns():
    assert contact_sheet(frames(2), columns=10, gap=0).shape == (4, 12, 3)


def test_grey_images_are_broadcast_and_small_ones_centred():
    rgb = np.full((4, 6, 3), 0.5, dtype=np.float32)
    grey = np.full((2, 2), 0.9, dtype=np.float32)
    sheet = contact_sheet([rgb, grey], columns=2, gap=0, background=0)
    assert sheet.shape == (4, 12, 3)
    assert (sheet[1:3, 8:10] == 0.9).all()  # centred in the 4x6 cell at x=6
    assert (sheet[0, 6:12] == 0).all()


@pytest.mark.parametrize(
    "images, kwargs, message",
    [
        ([], {}, "no images"),
        (frames(2), {"columns": 0}, "columns"),
        (frames(2), {"gap": -1}, "gap"),
        ([np.zeros((2, 2, 3)), np.zeros((2, 2, 4))], {}, "channel counts"),
        ([np.zeros((2, 2, 2, 2))], {}, "image 0"),
        ([np.zeros((0, 2, 3))], {}, "image 0"),
        (frames(1), {"background": (1, 2)}, "background"),
    ],
)
def test_invalid_input(images, kwargs, message):
    with pytest.raises(ValueError, match=message):
        contact_sheet(images, **kwargs)
