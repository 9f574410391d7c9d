"""Exemplars the project makes itself (numpy only), so that the fluid demos
and tests need no outside footage (docs/media_exemplars.md):

* `smoke_still` / `smoke_loop`: an RGBA smoke or fire element for
  LazyFluids (thesis ch. 5): multi-octave value noise, domain-warped and
  shaped into a rising plume, a soft alpha and a colour ramp (smoke
  grey-blue and lit from above, fire a warm emissive ramp). The loop's noise
  lives on a torus: periodic in time and, vertically, over one rise of the
  plume per loop, so the frame after the last is exactly the first.
* `ink_simulation` / `ink_video`: a drop of ink spreading on wet paper for
  Fluidymation (Platkevic et al. 2021): the wet front grows at `speed` px
  per frame (with a wavy, paper-dependent outline), and the pigment is
  advected outwards by the spreading water and diffuses inside the wet
  area (no flux into the dry paper). The pictures add darker edges
  (pigment carried to the rim), granulation (pigment settling into the
  paper's valleys, more the longer it has been wet) and the paper's
  texture; the masks are pigment > INK_THRESHOLD.

Every value is display-encoded (sRGB, as painted or filmed pictures are) in
[0, 1]; images are rows top-down, x right, y down. Everything random comes
from numpy.random.default_rng(seed): one seed, one result.
"""
from __future__ import annotations

import math

import numpy as np

KINDS = ("smoke", "fire")
INK_THRESHOLD = 0.5  # the masks: pigment concentration above this
PAPER = np.array([0.955, 0.94, 0.9])
INK_ABSORPTION = np.array([2.3, 1.7, 0.55])  # Beer-Lambert per channel: an indigo ink
HORIZONTAL_SQUEEZE = {"smoke": 1.0, "fire": 2.5}
MAX_SIDE = 4096
MIN_SIDE = 16

# Smoke's colour ramp from thick (in shadow) to thin (lit) smoke, and fire's
# from its coolest visible to its hottest: (position, r, g, b). Smoke is a
# sooty one, charcoal in its core and warm light at its lit rims, so that it
# reads against any sky (a pale grey ramp vanished into a pale sky).
SMOKE_RAMP = np.array([[0.0, 0.08, 0.08, 0.10], [0.45, 0.30, 0.29, 0.30], [0.8, 0.70, 0.66, 0.60],
                       [1.0, 0.95, 0.90, 0.80]])
FIRE_RAMP = np.array([[0.0, 0.28, 0.03, 0.01], [0.3, 0.80, 0.16, 0.02], [0.6, 1.0, 0.52, 0.08],
                      [0.85, 1.0, 0.82, 0.40], [1.0, 1.0, 0.97, 0.86]])


# --------------------------------------------------------------------------- checks

def _check_size(width, height):
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"{name} must be a whole number of pixels, got {value!r}")
        if not MIN_SIDE <= value <= MAX_SIDE:
            raise ValueError(f"{name} must be {MIN_SIDE}-{MAX_SIDE} px, got {value}")


def _check_frames(frames):
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 1:
        raise ValueError(f"frames must be a whole number >= 1, got {frames!r}")


def _check_kind(kind):
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")


# --------------------------------------------------------------------------- noise

def _fade(t):
    return t * t * t * (t * (t * 6 - 15) + 10)


def _lattice_noise(lattice, x, y, t):
    """Value noise of a (Gt, Gy, Gx) lattice of random values at lattice
    coordinates (x, y, t), periodic in all three: quintic interpolation."""
    gt, gy, gx = lattice.shape
    x0, y0, t0 = np.floor(x), np.floor(y), np.floor(t)
    fx, fy, ft = _fade(x - x0), _fade(y - y0), _fade(t - t0)
    ix, iy, it = (x0.astype(np.int64) % gx), (y0.astype(np.int64) % gy), (int(t0) % gt)
    jx, jy, jt = (ix + 1) % gx, (iy + 1) % gy, (it + 1) % gt
    out = 0.0
    for tt, wt in ((it, 1 - ft), (jt, ft)):
        plane = lattice[tt]
        top = plane[iy, ix] * (1 - fx) + plane[iy, jx] * fx
        bottom = plane[jy, ix] * (1 - fx) + plane[jy, jx] * fx
        out = out + wt * (top * (1 - fy) + bottom * fy)
    return out


class _Fbm:
    """Multi-octave value noise over an image, periodic in time (one loop =
    phase 0 to 1) and vertically with `period` px, drifting up by one period
    per loop: a texture advected upward on a torus in time."""

    def __init__(self, rng, width, period, cell, octaves, time_cells=3):
        self.cell, self.period, self.octaves = float(cell), float(period), octaves
        self.lattices = []
        for k in range(octaves):
            c = self.cell / 2 ** k
            self.lattices.append(rng.random((time_cells, int(round(period / c)), int(math.ceil(width / c)) + 2)))

    def __call__(self, x, y, phase):
        """Noise in [0, 1] at pixel coordinates (x, y) and loop phase in [0, 1)."""
        total, norm = 0.0, 0.0
        for k, lattice in enumerate(self.lattices):
            c, amplitude = self.cell / 2 ** k, 0.5 ** k
            y_drift = y + self.period * phase
            total = total + amplitude * _lattice_noise(lattice, x / c, y_drift / c, phase * lattice.shape[0])
            norm += amplitude
        return total / norm


def _smoothstep(lo, hi, x):
    t = np.clip((x - lo) / (hi - lo), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def _ramp(stops, t):
    return np.stack([np.interp(t, stops[:, 0], stops[:, c]) for c in (1, 2, 3)], axis=-1)


# --------------------------------------------------------------------------- smoke and fire

class _Plume:
    """The noise fields of one smoke/fire element (one seed); `frame(phase)`
    gives its RGBA picture at a loop phase."""

    def __init__(self, width, height, seed, kind):
        _check_size(width, height)
        _check_kind(kind)
        rng = np.random.default_rng(seed)
        self.width, self.height, self.kind = width, height, kind
        base = max(8.0, min(width, height) / 4)
        # A whole number of cells of every octave of all three noises (the coarsest: 2 * base).
        period = math.ceil(height / (2 * base)) * 2 * base
        self.detail = _Fbm(rng, width, period, base, octaves=5)
        self.warp = _Fbm(rng, width, period, base * 2, octaves=2)
        self.sway = _Fbm(rng, width, period, base * 2, octaves=1)
        self.x0 = width * (0.5 + 0.06 * (rng.random() - 0.5))
        self.y, self.x = np.mgrid[0:height, 0:width].astype(np.float64)

    def frame(self, phase):
        w, h = self.width, self.height
        up = 1.0 - self.y / h  # 0 at the source (bottom), 1 at the top
        sway = (self.sway(self.x * 0 + self.x0, self.y, phase) - 0.5) * 2
        centre = self.x0 + w * 0.14 * up ** 1.5 * sway
        warp = 0.9 * self.detail.cell * (self.warp(self.x, self.y, phase) - 0.5)
        # Fire's noise is squeezed sideways: tall thin tongues.
        detail = self.detail(HORIZONTAL_SQUEEZE[self.kind] * (self.x + warp), self.y - warp, phase)
        if self.kind == "smoke":
            return self._smoke(up, centre, detail)
        return self._fire(up, centre, detail)

    def _smoke(self, up, centre, detail):
        # A wide, dense plume: most of its pixels are interior ones, the
        # ones LazyFluids fills the target's inside with.
        width = self.width * (0.08 + 0.2 * up)
        envelope = np.exp(-((self.x - centre) / width) ** 2) * _smoothstep(0.0, 0.06, up) * (1 - up) ** 0.8
        density = envelope * _smoothstep(0.25, 0.7, detail) * 3.0
        alpha = 1 - np.exp(-1.8 * density)
        # Thick smoke shades itself; the noise lights its billows' tops.
        lit = np.clip(1.0 - 0.45 * density + 1.4 * (detail - 0.5), 0.0, 1.0)
        return _rgba(_ramp(SMOKE_RAMP, lit), alpha)

    def _fire(self, up, centre, detail):
        width = self.width * np.maximum(0.03, 0.2 - 0.14 * up)
        envelope = np.exp(-((self.x - centre) / width) ** 2) * _smoothstep(0.0, 0.15, up) * _smoothstep(0.95, 0.35, up)
        # The noise carves the flame into tongues, more the higher up.
        heat = np.clip(1.4 * envelope - (1 - detail) ** 1.5 * (0.3 + 2.2 * up), 0.0, 1.0)
        alpha = _smoothstep(0.04, 0.8, heat)
        return _rgba(_ramp(FIRE_RAMP, heat), alpha)


def _rgba(rgb, alpha):
    return np.ascontiguousarray(np.concatenate([rgb, alpha[..., None]], axis=-1), dtype=np.float32)


def smoke_still(width, height, seed, kind="smoke"):
    """One RGBA (H, W, 4) float32 smoke or fire element (straight alpha): a
    plume rising from the bottom centre; alpha soft, in [0, 1]."""
    return _Plume(width, height, seed, kind).frame(0.0)


def smoke_loop(width, height, frames, seed, kind="smoke"):
    """`frames` RGBA frames of the element that loop seamlessly: the frame
    after the last would be the first. The plume rises one image height
    (rounded up to the noise's coarsest cell) per loop while it evolves;
    frame 0 is `smoke_still` of the same seed."""
    _check_frames(frames)
    plume = _Plume(width, height, seed, kind)
    return [plume.frame(i / frames) for i in range(frames)]


# --------------------------------------------------------------------------- ink

def _bilinear(image, x, y):
    """`image` sampled at float pixel coordinates, clamped at the edges."""
    h, w = image.shape
    x = np.clip(x, 0, w - 1)
    y = np.clip(y, 0, h - 1)
    x0 = np.minimum(np.floor(x).astype(np.int64), w - 2)
    y0 = np.minimum(np.floor(y).astype(np.int64), h - 2)
    fx, fy = x - x0, y - y0
    top = image[y0, x0] * (1 - fx) + image[y0, x0 + 1] * fx
    bottom = image[y0 + 1, x0] * (1 - fx) + image[y0 + 1, x0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def _neighbour_sum(a):
    """Sum of the 4 neighbours, with zero outside the image."""
    p = np.pad(a, 1)
    return p[:-2, 1:-1] + p[2:, 1:-1] + p[1:-1, :-2] + p[1:-1, 2:]


class _InkDrop:
    """One drop of ink on wet paper: the wet front's shape and the pigment's
    advection-diffusion inside it."""

    DIFFUSION = 0.15  # px^2 per substep, below the explicit limit of 0.25
    WOBBLE = 0.07  # relative amplitude of the front's angular waviness
    HARMONICS = np.arange(2, 17)

    def __init__(self, width, height, speed, seed):
        rng = np.random.default_rng(seed)
        self.speed = speed
        side = min(width, height)
        self.r0 = max(2.0, 0.04 * side)
        self.cx = width * (0.5 + 0.08 * (rng.random() - 0.5))
        self.cy = height * (0.5 + 0.08 * (rng.random() - 0.5))
        y, x = np.mgrid[0:height, 0:width].astype(np.float64)
        self.dx, self.dy = x - self.cx, y - self.cy
        self.r = np.hypot(self.dx, self.dy)
        self.theta = np.arctan2(self.dy, self.dx)
        self.amplitude = self.WOBBLE * rng.standard_normal(len(self.HARMONICS)) / self.HARMONICS * 2
        self.phase = rng.random(len(self.HARMONICS)) * 2 * np.pi
        self.drift = (rng.random(len(self.HARMONICS)) - 0.5) * 0.08  # the outline's slow change per frame
        cell = max(4.0, side / 16)
        self.paper = _Fbm(rng, width, math.ceil(height / cell) * cell, cell, octaves=4)(x, y, 0.0)
        self.grain = _Fbm(rng, width, math.ceil(height / 4) * 4, 4.0, octaves=2)(x, y, 0.0)
        self.pigment = np.clip(0.8 + 0.5 * (self.paper - 0.5), 0.7, 1.0) * (self.front(0.0) > -0.5)

    def wobble(self, t):
        angles = self.HARMONICS[:, None, None] * self.theta + (self.phase + self.drift * t)[:, None, None]
        return np.tensordot(self.amplitude, np.cos(angles), axes=1)

    def radius(self, t):
        return self.r0 + self.speed * t

    def front(self, t):
        """Signed distance inside the wet front (px, > 0 wet) at time t (frames)."""
        outline = self.radius(t) * (1 + self.wobble(t)) + 6.0 * (self.paper - 0.5)  # paper soaks unevenly
        return outline - self.r

    def step(self, t, dt):
        """Advances the pigment from t to t + dt: semi-Lagrangian advection
        along the spreading water, whose radial speed grows from 0 at the
        drop's centre to the front's at the front, then diffusion between
        wet pixels only."""
        wet_before = np.clip(self.front(t) + 0.5, 0.0, 1.0)
        wet = np.clip(self.front(t + dt) + 0.5, 0.0, 1.0)
        back = 1 - self.speed * dt / self.radius(t + dt)  # radial scaling of the backtrace
        x, y = self.cx + self.dx * back, self.cy + self.dy * back
        carried = _bilinear(self.pigment * wet_before, x, y)
        weight = _bilinear(wet_before, x, y)
        # Normalized by the wet share, so newly wet paper takes the pigment behind the front.
        c = np.where(weight > 1e-6, carried / np.maximum(weight, 1e-6), 0.0) * (wet > 0)
        flux = _neighbour_sum(c * wet) - c * _neighbour_sum(wet)
        self.pigment = (c + self.DIFFUSION * flux * wet) * (wet > 0)
        return wet

    def picture(self, t, wet):
        """The paper with the ink at time t: Beer-Lambert of an optical
        density from the pigment, a darker rim, granulation and paper."""
        # Rim and granulation are strong enough to survive patch synthesis's
        # averaging (weaker ones came out of Fluidymation as a flat blot).
        inside = np.maximum(self.front(t), 0.0)
        rim = np.exp(-inside / 3.5)
        age = np.maximum(t - (self.r - self.r0) / self.speed, 0.0)  # frames since the front passed
        granulation = 1 + (1 - np.exp(-age / 6)) * 1.3 * (0.5 - self.grain)
        density = self.pigment * wet * (0.45 + 1.5 * rim) * granulation * (0.7 + 0.6 * self.paper)
        paper = PAPER * (1 - 0.05 * (self.grain - 0.5))[..., None]
        rgb = paper * np.exp(-density[..., None] * INK_ABSORPTION)
        return np.ascontiguousarray(np.clip(rgb, 0, 1), dtype=np.float32)


def _check_speed(speed, width, height):
    try:
        speed = float(speed)
    except (TypeError, ValueError):
        raise ValueError(f"speed must be a number of px per frame, got {speed!r}") from None
    limit = min(width, height) / 8
    if not (math.isfinite(speed) and 0 < speed <= limit):
        raise ValueError(f"speed must be > 0 and <= {limit:g} px per frame (an eighth of the shorter side), "
                         f"got {speed}")
    return speed


def ink_simulation(width, height, frames, speed, seed):
    """The ink drop's `frames` (rgb, pigment) pairs: rgb (H, W, 3) float32
    over paper, pigment (H, W) float32 concentration in [0, 1] (0 on dry
    paper). The wet front's mean radius grows by `speed` px per frame from
    the drop's; it leaves the picture once the radius passes half the
    shorter side."""
    _check_size(width, height)
    _check_frames(frames)
    speed = _check_speed(speed, width, height)
    drop = _InkDrop(width, height, speed, seed)
    substeps = max(1, math.ceil(speed / 0.75))  # the backtrace moves < 1 px per substep
    wet = np.clip(drop.front(0.0) + 0.5, 0.0, 1.0)
    out = []
    for f in range(frames):
        if f:
            for s in range(substeps):
                wet = drop.step(f - 1 + s / substeps, 1 / substeps)
        out.append((drop.picture(float(f), wet), np.clip(drop.pigment, 0, 1).astype(np.float32)))
    return out


def ink_video(width, height, frames, speed, seed):
    """(rgb frames, mask frames) of the ink drop (ink_simulation): rgb
    (H, W, 3) float32 over paper, masks (H, W) float32 of 0/1 where the
    pigment is above INK_THRESHOLD."""
    sim = ink_simulation(width, height, frames, speed, seed)
    return [rgb for rgb, _ in sim], [(pigment > INK_THRESHOLD).astype(np.float32) for _, pigment in sim]


def ink_mask(rgb, paper=None, threshold=0.3):
    """The mask of a painted, filmed or simulated ink frame (H, W, 3) by
    threshold: 1 where the mean optical density against the paper,
    -log(rgb / paper), is above `threshold`. `paper` is the paper's colour;
    by default the frame's 95th percentile per channel (most of a frame is
    bare paper)."""
    rgb = np.asarray(rgb, np.float64)
    if rgb.ndim != 3 or rgb.shape[2] < 3:
        raise ValueError(f"ink_mask: expected an (H, W, 3) picture, got shape {rgb.shape}")
    rgb = rgb[:, :, :3]
    paper = np.percentile(rgb.reshape(-1, 3), 95, axis=0) if paper is None else np.asarray(paper, np.float64)
    density = -np.log(np.clip(rgb, 1e-4, None) / np.maximum(paper, 1e-4)).mean(axis=2)
    return (density > threshold).astype(np.float32)


# --------------------------------------------------------------------------- files

def frame_name(index):
    """File name of frame `index` (0-based) of a written exemplar."""
    return f"frame_{index + 1:04d}.png"


def write_frames(out, frames, masks=None):
    """Writes frames (RGB or RGBA float arrays) as OUT/frame_0001.png ... and
    masks, if given, as OUT/masks/frame_0001.png ... (grey); each file is
    written to a temporary and renamed (tempera.write_image). Returns the
    frame paths."""
    from pathlib import Path

    from .. import write_image

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if masks is not None:
        (out / "masks").mkdir(exist_ok=True)
    paths = []
    for i, frame in enumerate(frames):
        path = out / frame_name(i)
        write_image(str(path), np.ascontiguousarray(frame, np.float32))
        if masks is not None:
            write_image(str(out / "masks" / frame_name(i)), np.ascontiguousarray(masks[i][..., None], np.float32))
        paths.append(path)
    return paths
