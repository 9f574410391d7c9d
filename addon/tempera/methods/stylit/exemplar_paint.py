"""A procedural "hand-drawn" style exemplar (StyLit's A'), made from the
exemplar's own render so that the demo needs no outside data (no bpy).

StyLit has an artist paint over a print of the "sphere on a table" render.
`paint_hatching` stands in for the artist: coloured-pencil / crayon hatching
on off-white paper whose stroke density follows the illumination:

* the shading (render / albedo) is mapped to a darkness in [0, 1];
* four stroke layers, each starting at a darkness threshold, are laid on
  top of each other: a light layer in the material's own colour (sparse
  where lit, so the paper shows), a darker one in nearly the same
  direction, then two cross-hatching layers of dark ink across it, so deep
  shadows, including the shadow cast on the table, are densely
  cross-hatched; highlights (shading far above white) stay bare paper;
* strokes are slightly curved segments 10-22 px long with tapered, uneven
  pressure; their direction follows the form (along the isophotes where the
  shading changes, e.g. around the sphere), a per-material base direction
  elsewhere, plus a slow wobble and per-stroke jitter; they mostly stay
  inside the material they start in, and a few longer strokes outline the
  objects;
* the ink sits on the paper's tooth (a grain texture), overlapping strokes
  darken multiplicatively like wax crayon, and each stroke's colour is
  jittered slightly.

Everything random comes from numpy.random.default_rng(seed): one seed, one image.
"""
import numpy as np

from ...engine.color import linear_to_srgb, srgb_to_linear

PAPER = (0.965, 0.945, 0.895)
LUMA = np.array([0.2126, 0.7152, 0.0722])
DARK_INK = np.array([0.16, 0.12, 0.15])  # dark sepia-violet, the deepest shadows


# One row per stroke layer: darkness where it starts, density there (as a
# fraction of full density), darkness over which it ramps up to full density,
# direction offset (radians) from the base field, how dark its colour is
# (1 = material colour, 0 = DARK_INK), spacing between strokes at full
# density (px), opacity.
_LAYERS = (
    # start  floor  ramp  angle  tint  spacing  opacity
    (0.00, 0.40, 0.60, 0.00, 1.00, 3.0, 0.70),
    (0.30, 0.10, 0.25, 0.20, 0.55, 3.0, 0.75),
    (0.50, 0.05, 0.20, 1.25, 0.30, 3.2, 0.80),
    (0.68, 0.05, 0.18, -0.75, 0.00, 3.4, 0.85),
)


# --------------------------------------------------------------------------- numpy helpers

def _box_blur(a, radius, axis):
    """Box filter of width 2*radius+1 along axis, edges clamped."""
    if radius <= 0:
        return a
    pad = [(0, 0)] * a.ndim
    pad[axis] = (radius + 1, radius)
    c = np.cumsum(np.pad(a, pad, mode="edge"), axis=axis)
    n = a.shape[axis]
    upper = np.take(c, np.arange(2 * radius + 1, 2 * radius + 1 + n), axis=axis)
    lower = np.take(c, np.arange(0, n), axis=axis)
    return (upper - lower) / (2 * radius + 1)


def _blur(a, radius, passes=3):
    """Approximately Gaussian blur (repeated box filter) over the first two axes."""
    a = np.asarray(a, dtype=np.float64)
    radius = int(round(radius))
    for _ in range(passes):
        a = _box_blur(_box_blur(a, radius, 0), radius, 1)
    return a


def _smooth_noise(rng, height, width, cell):
    """Value noise with features about `cell` pixels apart, in [-1, 1]."""
    gh, gw = height // cell + 3, width // cell + 3
    grid = rng.uniform(-1.0, 1.0, (gh, gw))
    y = np.arange(height) / cell + 1.0
    x = np.arange(width) / cell + 1.0
    y0, x0 = np.floor(y).astype(int), np.floor(x).astype(int)
    fy, fx = y - y0, x - x0
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)  # smoothstep
    top = grid[y0][:, x0] * (1 - fx) + grid[y0][:, x0 + 1] * fx
    bottom = grid[y0 + 1][:, x0] * (1 - fx) + grid[y0 + 1][:, x0 + 1] * fx
    noise = top * (1 - fy)[:, None] + bottom * fy[:, None]
    return noise / max(np.abs(noise).max(), 1e-9)


def _widen(a):
    """Spreads splatted lines to about two pixels' width."""
    return 0.5 * a + 0.5 * _blur(a, 1, passes=1)


def _splat(height, width, xs, ys, weights, values):
    """Bilinear splat of point samples: returns (sum of weights, sum of
    weight * value per channel) on the pixel grid."""
    x0, y0 = np.floor(xs).astype(np.int64), np.floor(ys).astype(np.int64)
    fx, fy = xs - x0, ys - y0
    acc = np.zeros(height * width)
    col = np.zeros((values.shape[1], height * width))
    for dx, dy, w in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)), (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        px, py = x0 + dx, y0 + dy
        inside = (px >= 0) & (px < width) & (py >= 0) & (py < height)
        index = (py * width + px)[inside]
        ww = (w * weights)[inside]
        acc += np.bincount(index, ww, minlength=height * width)
        for c in range(values.shape[1]):
            col[c] += np.bincount(index, ww * values[inside, c], minlength=height * width)
    return acc.reshape(height, width), col.reshape(-1, height, width).transpose(1, 2, 0)


# --------------------------------------------------------------------------- painting

def _as_rgb(array, what):
    a = np.nan_to_num(np.asarray(array, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    if a.ndim == 2:
        a = np.repeat(a[:, :, None], 3, axis=2)
    if a.ndim != 3 or a.shape[2] < 1 or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"paint_hatching: {what} must be an (H, W) or (H, W, C) array, got shape {np.shape(array)}")
    if a.shape[2] < 3:
        a = np.repeat(a[:, :, :1], 3, axis=2)
    return np.maximum(a[:, :, :3], 0.0)


def _shading(render, albedo=None, mask=None):
    """(shading, mask): the render's luminance divided by the albedo's (so a
    red sphere and a beige table that are lit alike get alike shading), or
    the luminance alone without albedo; the mask (float in [0, 1]) defaults
    to where the albedo is non-zero (not the background), or everywhere."""
    render = _as_rgb(render, "render")
    luminance = render @ LUMA
    if albedo is not None:
        albedo = _as_rgb(albedo, "albedo")
        if albedo.shape != render.shape:
            raise ValueError(f"paint_hatching: albedo shape {albedo.shape} differs from render shape {render.shape}")
        albedo_luminance = albedo @ LUMA
        shading = luminance / np.maximum(albedo_luminance, 1e-3)
        if mask is None:
            mask = albedo_luminance > 1e-3
    else:
        shading = luminance
    if mask is None:
        mask = np.ones(shading.shape)
    mask = np.asarray(mask, dtype=np.float64)
    if mask.ndim == 3:
        mask = mask[:, :, 0]
    if mask.shape != shading.shape:
        raise ValueError(f"paint_hatching: mask shape {mask.shape} differs from image shape {shading.shape}")
    return _blur(shading, 1, passes=1), np.clip(mask, 0.0, 1.0)  # the blur tames render noise


def darkness_map(render, albedo=None, mask=None, *, white=1.2, gamma=0.7):
    """How much ink each pixel gets, in [0, 1] (0 = fully lit or not drawn).

    `white` is the shading (see _shading) that counts as fully lit, `gamma`
    < 1 spreads the shadows apart. Outside `mask` (by default: where the
    albedo is zero, i.e. the background) the darkness is 0.
    """
    shading, mask = _shading(render, albedo, mask)
    tone = np.clip(shading / white, 0.0, 1.0) ** gamma
    return np.clip((1.0 - tone) * mask, 0.0, 1.0)


def _regions(albedo, mask):
    """Integer label per pixel: one per material (quantized albedo), or
    drawn / not drawn without albedo."""
    if albedo is None:
        return (mask > 0.5).astype(np.int64)
    q = np.round(np.clip(albedo, 0.0, 1.0) * 8.0).astype(np.int64)
    return q[:, :, 0] * 81 + q[:, :, 1] * 9 + q[:, :, 2]


def _direction_field(rng, dark, albedo, mask):
    """Hatching angle per pixel (radians, x right, y down)."""
    height, width = dark.shape
    base = np.full(dark.shape, np.radians(-55.0))  # lower left to upper right
    if albedo is not None:
        # Another base direction per material, as an artist turns the pencil
        # from one object to the next.
        labels, index = np.unique(_regions(albedo, mask), return_inverse=True)
        base = base + rng.uniform(-0.6, 0.6, labels.size)[index.reshape(dark.shape)]
    # Form-following: along the isophotes where the shading changes.
    smooth = _blur(dark, 5)
    gy, gx = np.gradient(smooth)
    strength = np.clip(np.hypot(gx, gy) / 0.02, 0.0, 1.0) * 0.85
    iso = np.arctan2(gx, -gy)  # perpendicular to the gradient
    # Blend as doubled angles (a stroke has no head or tail), smooth, halve.
    c = (1 - strength) * np.cos(2 * base) + strength * np.cos(2 * iso)
    s = (1 - strength) * np.sin(2 * base) + strength * np.sin(2 * iso)
    c, s = _blur(c, 4), _blur(s, 4)
    angle = 0.5 * np.arctan2(s, c)
    return angle + 0.2 * _smooth_noise(rng, height, width, 32)


def paint_hatching(render, albedo=None, *, mask=None, seed=0, linear=True, white=1.2, gamma=0.7, highlight=1.8,
                   stroke_length=(10.0, 22.0), density=1.0, outline=1.0, paper=PAPER):
    """A hatched drawing of `render`: float32 (H, W, 3) in [0, 1], display-referred (sRGB).

    render         (H, W[, C]) render of the exemplar; linear (Blender's Combined) unless linear=False.
    albedo         optional (H, W, 3) diffuse colour (Blender's DiffCol, linear): gives the
                   shading (render / albedo), the pencil colours and the background mask.
    mask           optional (H, W) in [0, 1]: where to draw; elsewhere bare paper.
    seed           all randomness; the same seed and inputs give the same image.
    white, gamma   shading -> darkness mapping, see darkness_map.
    highlight      shading above highlight * white stays bare paper.
    stroke_length  (min, max) stroke length in pixels.
    density        scales the number of hatching strokes.
    outline        scales the number of outline strokes (0: none).
    """
    rgb = _as_rgb(render, "render")
    if albedo is not None:
        albedo = _as_rgb(albedo, "albedo")
    height, width = rgb.shape[:2]
    rng = np.random.default_rng(seed)
    lo, hi = float(stroke_length[0]), float(stroke_length[1])
    if not 0 < lo <= hi:
        raise ValueError(f"paint_hatching: stroke_length must be 0 < min <= max, got {stroke_length}")

    if not linear:  # display-referred input: undo the encoding for the shading
        rgb = srgb_to_linear(rgb).astype(np.float64)
        if albedo is not None:
            albedo = srgb_to_linear(albedo).astype(np.float64)
    shading, mask = _shading(rgb, albedo, mask)
    dark = np.clip((1.0 - np.clip(shading / white, 0.0, 1.0) ** gamma) * mask, 0.0, 1.0)
    # Bare paper: outside the mask and in highlights (much brighter than
    # `white`, i.e. specular reflections of the light).
    drawable = (mask > 0.5) & (shading < highlight * white)

    # Pencil colours: the material's colour at full saturation.
    colour_source = linear_to_srgb(albedo if albedo is not None else rgb).astype(np.float64)
    colour_source = _blur(colour_source, 1, passes=1)
    # Hue kept, saturation raised (a beige table gets an ochre pencil), never
    # quite white or fully saturated.
    local = colour_source / np.maximum(colour_source.max(axis=2, keepdims=True), 1e-3)
    local = 0.06 + 0.84 * local ** 3

    # Paper: off-white with a slow mottle and a fine tooth (grain in [0, 1]).
    grain = _blur(rng.random((height, width)), 1, passes=1)
    grain = np.argsort(np.argsort(grain, axis=None)).reshape(height, width) / (height * width - 1)
    mottle = _smooth_noise(rng, height, width, 40)
    image = np.asarray(paper, dtype=np.float64)[None, None, :] * (1 + 0.02 * mottle - 0.035 * (1 - grain))[:, :, None]
    tooth = np.clip(1.3 * grain + 0.25, 0.35, 1.0)  # crayon skips the paper's valleys

    angle_field = _direction_field(rng, dark, albedo, mask)
    regions = _regions(albedo, mask)
    canvas = _Canvas(image, tooth, regions, mask > 0.5, hi)

    for start, floor, ramp, angle_offset, tint, spacing, opacity in _LAYERS:
        # Candidate stroke centres, kept with a probability that grows with darkness.
        mean_length = 0.5 * (lo + hi)
        count = int(density * 1.6 * height * width / (spacing * mean_length))
        cx = rng.uniform(-2, width + 1, count)
        cy = rng.uniform(-2, height + 1, count)
        ix = np.clip(cx.astype(int), 0, width - 1)
        iy = np.clip(cy.astype(int), 0, height - 1)
        d = dark[iy, ix]
        probability = np.where((d >= start) & drawable[iy, ix], np.clip(floor + (d - start) / ramp, 0.0, 1.0), 0.0)
        keep = rng.random(count) < probability / 1.6
        cx, cy, ix, iy, d = cx[keep], cy[keep], ix[keep], iy[keep], d[keep]
        n = cx.size
        # Colour: the local pencil colour darkened towards DARK_INK.
        value = tint * (1.0 - 0.25 * np.clip(d - start, 0.0, 1.0))
        colour = value[:, None] * local[iy, ix] + (1.0 - value[:, None]) * DARK_INK[None, :]
        theta = angle_field[iy, ix] + angle_offset + rng.normal(0.0, 0.08, n)
        canvas.strokes(rng, cx, cy, theta, rng.uniform(lo, hi, n), colour, opacity, stay_inside=True)

    # Outlines: a few strokes along the edges between materials and around
    # the drawn area, in a darkened local colour.
    edges, edge_angle = _outline(albedo, mask)
    ey, ex = np.nonzero(edges)
    keep = rng.random(ey.size) < outline / (0.5 * (lo + hi))
    ey, ex = ey[keep], ex[keep]
    n = ey.size
    colour = 0.45 * local[ey, ex] + 0.55 * DARK_INK[None, :]
    theta = edge_angle[ey, ex] + rng.normal(0.0, 0.06, n)
    canvas.strokes(rng, ex + rng.uniform(0, 1, n), ey + rng.uniform(0, 1, n), theta,
                   rng.uniform(lo, hi, n) * 1.2, colour, 0.55, stay_inside=False)
    return np.clip(canvas.image, 0.0, 1.0).astype(np.float32)


def _outline(albedo, mask):
    """(edge pixels, angle along the edge) of the material / mask boundaries."""
    signal = mask * 2.0
    if albedo is not None:
        signal = signal + linear_to_srgb(albedo).astype(np.float64) @ np.array([1.0, 2.0, 0.5])
    smooth = _blur(signal, 1, passes=2)
    gy, gx = np.gradient(smooth)
    magnitude = np.hypot(gx, gy)
    # Edge = local maximum of the gradient across the edge, above a threshold.
    edges = magnitude > 0.12
    edges &= magnitude >= np.maximum(np.roll(magnitude, 1, 0), np.roll(magnitude, -1, 0)) * (np.abs(gy) >= np.abs(gx)) \
        + np.maximum(np.roll(magnitude, 1, 1), np.roll(magnitude, -1, 1)) * (np.abs(gy) < np.abs(gx))
    edges[:2], edges[-2:], edges[:, :2], edges[:, -2:] = False, False, False, False
    return edges, np.arctan2(gx, -gy)


class _Canvas:
    """Paper being drawn on: strokes are splatted per batch and laid over it."""

    def __init__(self, image, tooth, regions, inside, max_length):
        self.image, self.tooth, self.regions, self.inside = image, tooth, regions, inside
        # Ink may spread a pixel past the mask (line width), no further.
        self.reach = _blur(inside.astype(np.float64), 1, passes=1) > 0.0
        self.samples = int(np.ceil(max_length * 1.2 / 0.5)) + 1
        self.u = np.linspace(-0.5, 0.5, self.samples)

    def strokes(self, rng, cx, cy, theta, length, colour, opacity, stay_inside):
        """One batch of strokes centred on (cx, cy), at angles theta, with
        per-stroke colours (n, 3); overlapping strokes darken like wax crayon."""
        n = np.size(cx)
        if n == 0:
            return
        height, width = self.regions.shape
        u, samples = self.u, self.samples
        bend = rng.normal(0.0, 0.07, n) * length
        pressure = rng.uniform(0.55, 1.0, n)
        dx, dy = np.cos(theta), np.sin(theta)
        along = u[None, :] * length[:, None]
        across = bend[:, None] * (1.0 - (2.0 * u[None, :]) ** 2)
        xs = cx[:, None] + along * dx[:, None] - across * dy[:, None]
        ys = cy[:, None] + along * dy[:, None] + across * dx[:, None]
        # Pressure: quick attack, slow fade towards the end, a little wobble.
        profile = np.sin(np.pi * (u + 0.5)) ** 0.4 * (1.0 - 0.35 * (u + 0.5))
        wobble = 1.0 + 0.15 * np.sin(rng.uniform(0, 2 * np.pi, n)[:, None] + u[None, :] * rng.uniform(4, 9, n)[:, None])
        step = length / (samples - 1)
        weights = (pressure * step)[:, None] * profile[None, :] * wobble
        # No ink on the background (outside the mask): there the guides are
        # all alike, and any mark could be copied anywhere into a target's
        # background. With stay_inside, strokes mostly stay inside the
        # region (material) they start in: into a neighbouring one only a
        # faint overshoot remains.
        sx = np.clip(np.round(xs).astype(np.int64), 0, width - 1)
        sy = np.clip(np.round(ys).astype(np.int64), 0, height - 1)
        keep = self.inside[sy, sx].astype(np.float64)
        if stay_inside:
            ix = np.clip(np.asarray(cx).astype(np.int64), 0, width - 1)
            iy = np.clip(np.asarray(cy).astype(np.int64), 0, height - 1)
            keep *= np.where(self.regions[sy, sx] == self.regions[iy, ix][:, None], 1.0, 0.12)
        weights = weights * keep
        # A little colour variation from stroke to stroke.
        colour = colour * (1.0 + rng.normal(0.0, 0.05, (n, 3))) * rng.uniform(0.92, 1.06, n)[:, None]
        colour = np.clip(colour, 0.0, 1.0)

        acc, col = _splat(height, width, xs.ravel(), ys.ravel(), weights.ravel(), np.repeat(colour, samples, axis=0))
        acc, col = _widen(acc), _widen(col)  # strokes about two pixels wide
        ink = col / np.maximum(acc, 1e-9)[:, :, None]
        alpha = opacity * (1.0 - np.exp(-4.0 * acc)) * self.tooth * self.reach
        self.image = self.image * (1.0 - alpha[:, :, None] * (1.0 - ink))
