"""Contact sheets: many same-kind images laid out on one grid (pure numpy)."""
import math

import numpy as np


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
    if not arrays:
        raise ValueError("contact_sheet: no images given")
    if gap < 0 or margin < 0:
        raise ValueError(f"contact_sheet: gap and margin must be >= 0, got gap={gap}, margin={margin}")
    if columns is None:
        columns = math.ceil(math.sqrt(len(arrays)))
    if columns < 1:
        raise ValueError(f"contact_sheet: columns must be >= 1, got {columns}")
    columns = min(columns, len(arrays))
    rows = math.ceil(len(arrays) / columns)

    channel_counts = {a.shape[2] for a in arrays}
    channels = max(channel_counts)
    if channel_counts - {1, channels}:
        raise ValueError(f"contact_sheet: images have different channel counts {sorted(channel_counts)}")

    cell_h = max(a.shape[0] for a in arrays)
    cell_w = max(a.shape[1] for a in arrays)
    height = 2 * margin + rows * cell_h + (rows - 1) * gap
    width = 2 * margin + columns * cell_w + (columns - 1) * gap
    sheet = np.empty((height, width, channels), dtype=np.float32)
    try:
        sheet[...] = np.asarray(background, dtype=np.float32)
    except ValueError:
        raise ValueError(
            f"contact_sheet: background must be one value or {channels} values, got {background!r}"
        ) from None

    for i, array in enumerate(arrays):
        row, col = divmod(i, columns)
        y = margin + row * (cell_h + gap) + (cell_h - array.shape[0]) // 2
        x = margin + col * (cell_w + gap) + (cell_w - array.shape[1]) // 2
        sheet[y : y + array.shape[0], x : x + array.shape[1], :] = array  # broadcasts 1 -> C
    return sheet
