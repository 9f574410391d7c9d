"""Contact sheets: many same-kind images laid out on one grid (native/src/app/contact_sheet.cpp)."""
import numpy as np

from .. import _native


def _as_hwc(image, index):
    array = np.asarray(image, dtype=np.float32)
    if array.ndim == 2:
        array = array[:, :, None]
    if array.ndim != 3 or array.shape[0] == 0 or array.shape[1] == 0 or array.shape[2] == 0:
        raise ValueError(
            f"contact_sheet: image {index} must be a non-empty (H, W) or (H, W, C) array, "
            f"got shape {np.shape(image)}"
        )
    return array


def contact_sheet(images, columns=None, gap=4, margin=0, background=0.0):
    """Lay `images` out row by row on one float32 (H, W, C) array.

    images      sequence of (H, W) or (H, W, C) arrays. All must have the same
                channel count C, except that single-channel images are repeated
                to C channels. Sizes may differ: every cell is as large as the
                largest image, and each image is centred in its cell.
    columns     images per row; default ceil(sqrt(n)), i.e. a near-square grid.
    gap         pixels between neighbouring cells.
    margin      pixels around the whole grid.
    background  value (or per-channel sequence of C values) of gaps, margins
                and unused cells.
    """
    arrays = [_as_hwc(image, i) for i, image in enumerate(images)]
    if columns is None:
        columns = 0  # native: ceil(sqrt(n))
    elif columns < 1:
        raise ValueError(f"contact_sheet: columns must be >= 1, got {columns}")
    try:
        values = np.asarray(background, dtype=np.float32).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"contact_sheet: background must be a number or a sequence of numbers, got {background!r}") from None
    return _native.contact_sheet(arrays, int(columns), int(gap), int(margin), values.tolist())
