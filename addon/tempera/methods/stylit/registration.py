"""Registration of a photo or scan of a painted template (no bpy, numpy only):
StyLit's "we align a photo or scan of the painting with the original
rendered image using the alignment marks" (thesis §8.3.1).

    style = register_painting(photo, kit)   # kit: read_kit_json("kit/kit.json")

1. find_marks: the four corner marks of tempera.methods.stylit.painting_template are found
   as dark blobs (adaptive threshold: darker than 0.55 x the local mean, so
   uneven lighting does not matter) that are compact (moment test) and hold
   exactly one centred white hole. The key mark is the one whose hole is by
   far the largest; the others follow it clockwise, as on the page, so any
   rotation of the photo (a homography keeps the turning sense) is undone.
2. estimate_homography: normalized DLT from the four photo mark centres to
   the template's.
3. The picture rectangle is resampled at the guide resolution (s x s
   bilinear samples averaged per pixel, s ~ photo pixels per guide pixel, so
   the photo's grain and noise are filtered, not aliased).
4. flatten: the blank paper between the picture and the marks gives the
   lighting: a smooth (quadratic) fit per channel, which the picture is
   divided by, so the paper comes out white and uneven lighting goes.
"""
import numpy as np

from .painting_template import picture_grid, sample_bilinear

LUMA = np.array([0.2126, 0.7152, 0.0722])
DETECT_SIZE = 1600  # marks are found on a copy at most this large (pixels, longer side)


# --------------------------------------------------------------------------- homography

def estimate_homography(src, dst):
    """3x3 H with dst ~ H @ [src, 1] (least squares for more than 4 points),
    by the DLT with Hartley's normalization (centroid at 0, mean distance sqrt 2)."""
    src, dst = np.asarray(src, dtype=np.float64), np.asarray(dst, dtype=np.float64)
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] != 2 or len(src) < 4:
        raise ValueError(f"estimate_homography: need two (N >= 4, 2) point arrays, got {src.shape} and {dst.shape}")

    def normalizer(p):
        centre = p.mean(axis=0)
        scale = np.sqrt(2.0) / max(np.linalg.norm(p - centre, axis=1).mean(), 1e-12)
        return np.array([[scale, 0, -scale * centre[0]], [0, scale, -scale * centre[1]], [0, 0, 1]])

    ts, td = normalizer(src), normalizer(dst)
    s, d = apply_homography(ts, src), apply_homography(td, dst)
    rows = []
    for (x, y), (u, v) in zip(s, d):
        rows.append([-x, -y, -1, 0, 0, 0, u * x, u * y, u])
        rows.append([0, 0, 0, -x, -y, -1, v * x, v * y, v])
    h = np.linalg.svd(np.array(rows))[2][-1].reshape(3, 3)  # null vector: the smallest singular value's
    h = np.linalg.inv(td) @ h @ ts
    return h / h[2, 2]


def apply_homography(h, points):
    """Points (..., 2) mapped through the 3x3 homography h."""
    p = np.asarray(points, dtype=np.float64)
    q = p @ h[:2, :2].T + h[:2, 2]
    w = p @ h[2, :2] + h[2, 2]
    return q / w[..., None]


# --------------------------------------------------------------------------- mark detection

def _box_mean(a, radius):
    """Mean over a (2 radius + 1)^2 window, edges clamped (summed-area table)."""
    p = np.pad(a, radius + 1, mode="edge")
    c = p.cumsum(0).cumsum(1)
    k = 2 * radius + 1
    h, w = a.shape
    s = c[k:k + h, k:k + w] - c[:h, k:k + w] - c[k:k + h, :w] + c[:h, :w]
    return s / (k * k)


def label_components(mask):
    """4-connected components of a boolean image: int labels, -1 outside the
    mask, each component labelled by its smallest flat pixel index. Numpy
    only: union by hooking larger roots onto smaller ones, then pointer
    jumping, repeated over the edges still joining two roots."""
    h, w = mask.shape
    parent = np.arange(h * w)
    index = parent.reshape(h, w)
    horizontal, vertical = mask[:, :-1] & mask[:, 1:], mask[:-1] & mask[1:]
    a_h, a_v = index[:, :-1][horizontal], index[:-1][vertical]
    a, b = np.concatenate([a_h, a_v]), np.concatenate([a_h + 1, a_v + w])  # neighbour pairs inside the mask
    while a.size:
        ra, rb = parent[a], parent[b]
        differ = ra != rb
        a, b, ra, rb = a[differ], b[differ], ra[differ], rb[differ]  # joined edges stay joined
        if not a.size:
            break
        np.minimum.at(parent, np.maximum(ra, rb), np.minimum(ra, rb))
        while True:  # compress every path to its root
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    labels = parent.reshape(h, w)
    return np.where(mask, labels, -1)


def _moment_ratio(ys, xs):
    """area / sqrt(det covariance): 12 for any affine image of a filled square
    (12.6 for a disk), much larger for rings, lines and ragged blobs."""
    cov = np.cov(np.stack([xs, ys]).astype(np.float64)) if xs.size > 2 else np.eye(2)
    return xs.size / np.sqrt(max(np.linalg.det(cov), 1e-12))


def _examine(blob):
    """(hole area / filled area, filled area, centre y, centre x) of a mark-like
    blob (bool crop), or None: the blob with its holes filled must be compact
    and square-ish, with one hole near its centre."""
    padded = np.pad(blob, 1)
    outside = label_components(~padded)
    holes = (outside >= 0) & (outside != outside[0, 0])
    hole_labels, hole_areas = np.unique(outside[holes], return_counts=True)
    filled = padded | holes
    significant = hole_areas >= max(3, 0.01 * filled.sum())
    if significant.sum() != 1:
        return None
    fy, fx = np.nonzero(filled)
    if not 10.0 <= _moment_ratio(fy, fx) <= 14.5:
        return None
    hy, hx = np.nonzero(outside == hole_labels[significant][0])
    cy, cx = fy.mean(), fx.mean()
    if np.hypot(hy.mean() - cy, hx.mean() - cx) > 0.15 * np.sqrt(fy.size):
        return None
    return hy.size / fy.size, fy.size, cy - 1, cx - 1  # -1: the padding


def find_marks(photo):
    """The four mark centres in `photo` ((H, W[, C]) in [0, 1]) as (4, 2) photo
    pixel coordinates [x, y] in MARK_ORDER (key first, then clockwise).
    Raises ValueError with advice when they cannot be found."""
    image = np.asarray(photo, dtype=np.float64)
    gray = image[:, :, :3] @ LUMA if image.ndim == 3 and image.shape[2] >= 3 else image.reshape(image.shape[:2])
    # Detect on a reduced copy (box-averaged): marks are large, and the
    # centroid of many pixels is precise to well under a reduced pixel.
    f = max(1, int(np.ceil(max(gray.shape) / DETECT_SIZE)))
    h, w = gray.shape[0] // f, gray.shape[1] // f
    small = gray[: h * f, : w * f].reshape(h, f, w, f).mean(axis=(1, 3))
    dark = small < 0.55 * _box_mean(small, max(7, min(h, w) // 16))
    labels = label_components(dark)
    areas = np.unique(labels[dark], return_counts=True)[1]  # per component, in label order
    min_area, max_area = 40, 0.02 * h * w
    candidates = []
    yy, xx = np.nonzero(dark)
    order = np.argsort(labels[dark], kind="stable")  # pixels grouped by component
    starts = np.concatenate([[0], np.cumsum(areas)])
    for k in np.nonzero((areas >= min_area) & (areas <= max_area))[0]:
        py, px = yy[order[starts[k]:starts[k + 1]]], xx[order[starts[k]:starts[k + 1]]]
        y0, x0 = py.min(), px.min()
        bh, bw = py.max() - y0 + 1, px.max() - x0 + 1
        if max(bh, bw) > 3 * min(bh, bw) or areas[k] < 0.3 * bh * bw:
            continue
        blob = np.zeros((bh, bw), dtype=bool)
        blob[py - y0, px - x0] = True
        found = _examine(blob)
        if found:
            ratio, area, cy, cx = found
            candidates.append((ratio, area, (cx + x0 + 0.5) * f, (cy + y0 + 0.5) * f))
    if len(candidates) < 4:
        raise ValueError(f"found {len(candidates)} of 4 alignment marks; make sure all four corner marks "
                         "are visible in the photo, not covered by paint or glare, and not tiny")
    if len(candidates) > 4:  # stray look-alikes: keep the four of the most alike size
        candidates.sort(key=lambda c: c[1])
        spread = [candidates[i + 3][1] / candidates[i][1] for i in range(len(candidates) - 3)]
        i = int(np.argmin(spread))
        candidates = candidates[i:i + 4]
    ratios = sorted(c[0] for c in candidates)
    if ratios[3] < 1.8 * ratios[2]:
        raise ValueError("cannot tell which alignment mark is the top-left one (the mark with the large "
                         "square hole); make sure its hole is not painted over")
    key = max(range(4), key=lambda i: candidates[i][0])
    points = np.array([c[2:] for c in candidates])
    centre = points.mean(axis=0)
    angle = np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0])  # y down: increasing = clockwise
    clockwise = np.argsort((angle - angle[key]) % (2 * np.pi))
    return points[clockwise]


# --------------------------------------------------------------------------- registration

def _paper_lighting(photo, to_photo, kit):
    """A function page (x, y) -> paper colour in the photo there, fitted
    (quadratic per channel, robust against paint) to the blank band between
    the picture and the marks."""
    marks = np.array(kit["marks"])
    x0, y0, x1, y1 = kit["picture"]
    side = kit["mark_size"]
    step = side / 4
    gx, gy = np.meshgrid(np.arange(marks[:, 0].min(), marks[:, 0].max(), step),
                         np.arange(marks[:, 1].min(), marks[:, 1].max(), step))
    margin = side / 6  # paint may stray a little over the picture's edge
    in_picture = (gx > x0 - margin) & (gx < x1 + margin) & (gy > y0 - margin) & (gy < y1 + margin)
    near_mark = np.zeros(gx.shape, dtype=bool)
    for mx, my in marks:
        near_mark |= np.maximum(np.abs(gx - mx), np.abs(gy - my)) < 0.75 * side
    keep = ~in_picture & ~near_mark
    px, py = gx[keep], gy[keep]
    colour = sample_bilinear(photo, *np.moveaxis(apply_homography(to_photo, np.stack([px, py], -1)), -1, 0))
    scale = max(x1 - x0, y1 - y0)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2

    def basis(x, y):
        u, v = (np.ravel(x) - cx) / scale, (np.ravel(y) - cy) / scale
        return np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], axis=1)

    a = basis(px, py)
    luma = colour @ LUMA
    use = np.ones(len(a), dtype=bool)
    for _ in range(3):  # refit without samples much darker than the fit (stray paint, marks' blur)
        coef = np.linalg.lstsq(a[use], colour[use], rcond=None)[0]
        use = luma >= 0.9 * (a @ coef) @ LUMA
    return lambda x, y: (basis(x, y) @ coef).reshape(*np.shape(x), -1)


def register_painting(photo, kit, *, flatten=True):
    """The painting in `photo` ((H, W, C) in [0, 1]) resampled to the guide
    resolution kit["resolution"]: float32 (height, width, 3).

    kit      the template geometry (painting_template.Template.geometry(), as
             written to kit.json).
    flatten  divide by the paper's fitted colour (even lighting, paper white).
    """
    photo = np.asarray(photo, dtype=np.float64)
    if photo.ndim == 2:
        photo = photo[:, :, None]
    photo = np.repeat(photo[:, :, :1], 3, axis=2) if photo.shape[2] < 3 else photo[:, :, :3]
    found = find_marks(photo)
    to_photo = estimate_homography(np.array(kit["marks"]), found)  # page -> photo
    width, height = kit["resolution"]
    x0, y0, x1, y1 = kit["picture"]
    corners = apply_homography(to_photo, np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64))
    photo_px_per_pixel = max(np.linalg.norm(corners[1] - corners[0]) / width,
                             np.linalg.norm(corners[3] - corners[0]) / height)
    s = int(np.clip(np.ceil(photo_px_per_pixel), 1, 8))
    xs, ys = picture_grid(kit["picture"], width, height, s)
    style = np.empty((height, width, 3))
    band = max(1, 2 ** 20 // (width * s * s))  # rows at a time: bounded memory for large photos
    for top in range(0, height, band):
        rows = slice(top, top + band)
        pxy = apply_homography(to_photo, np.stack([xs[rows], ys[rows]], -1))
        style[rows] = sample_bilinear(photo, pxy[..., 0], pxy[..., 1]).mean(axis=2)
    if flatten:
        paper = _paper_lighting(photo, to_photo, kit)(xs.mean(axis=2), ys.mean(axis=2))
        style = style / np.maximum(paper, 1e-3)
    return np.clip(style, 0.0, 1.0).astype(np.float32)



def simulate_photo(page, page_to_photo, size, *, seed=0, noise=0.01, table=(0.25, 0.2, 0.15)):
    """A synthetic photo of `page` ((H, W, 3) in [0, 1]) for tests and docs:
    the page seen through the homography `page_to_photo` on a dark table, in
    a (width, height) = `size` frame, under light falling off from 1.0 on the
    left to 0.65 on the right with a warm cast, plus Gaussian noise."""
    width, height = size
    ys, xs = np.mgrid[:height, :width] + 0.5
    p = apply_homography(np.linalg.inv(page_to_photo), np.stack([xs, ys], -1))
    inside = (p[..., 0] >= 0) & (p[..., 0] < page.shape[1]) & (p[..., 1] >= 0) & (p[..., 1] < page.shape[0])
    photo = np.where(inside[..., None], sample_bilinear(np.asarray(page, np.float64), p[..., 0], p[..., 1]), table)
    light = 0.95 - 0.3 * xs / width + 0.05 * ys / height
    photo = photo * light[..., None] * [1.0, 0.97, 0.9]
    photo += np.random.default_rng(seed).normal(0.0, noise, photo.shape)
    return np.clip(photo, 0.0, 1.0).astype(np.float32)
