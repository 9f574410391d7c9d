"""The fluid velocity guide: the screen motion of smoke, liquids and particles, with no bpy.

Cycles' Vector pass is zero on volumes (smoke, fire) and about zero on
liquid meshes, so the velocity_* guides cannot move fluids. This guide comes
from the simulation instead: every sample (a voxel centre of a gas domain, a
vertex of a liquid mesh, a particle) is projected through the camera at x and
at x + v (v its world displacement over one frame); the screen displacements
are splatted bilinearly, weighted by the sample's density, and divided by the
splatted weight. Pixels inside the alpha that no sample reached are filled by
diffusion from their neighbours; pixels outside the alpha are 0.

Conventions are those of the cache's velocity_forward: pixels per frame, x
right, y down, rows top-down, p moves to p + F in the next frame.

The splat averages every sample along a pixel's ray by density, not by what
is in front (no opacity): for thin media, as smoke is, that is what is seen.

The Blender side (reading the grids, meshes and particles, the camera) is
tempera.blender.fluid_velocity; the time units of each source are here, so
that they are tested without Blender (docs/guide_cache.md, fluid_velocity).
"""
import numpy as np

# Mantaflow's time unit, as Blender sets it up (intern/mantaflow, fluid
# script): a frame lasts frame_length = 0.1 * (25 / fps) * time_scale time
# units, and initial velocities in m/s are scaled by 1 / 2.5, i.e. one second
# of simulated time is 2.5 time units. Grid velocities are in cells per time
# unit. Measured on Blender 3.4 (docs/guide_cache.md): a flow of +2 m/s in a
# domain of 4 m and 32 cells gives 6.5 cells per time unit (2 * 8 / 2.5 = 6.4).
MANTAFLOW_TIME_UNITS_PER_SECOND = 2.5

# Blender's particle step: a frame advances particles by velocity * 0.04 *
# timestep factor (psys_get_timestep: 1/25 of a second per frame, whatever fps).
PARTICLE_SECONDS_PER_FRAME = 0.04

DEFAULT_ALPHA_THRESHOLD = 1e-3  # alpha above which a pixel shows fluid and gets a velocity
FILL_ITERATIONS = 24  # Jacobi sweeps of the diffusion fill on each level of the pyramid


def _array(name, value, shape_tail, dtype=np.float64):
    a = np.asarray(value, dtype)
    if a.ndim != len(shape_tail) + 1 or a.shape[1:] != shape_tail:
        want = "(N, " + ", ".join(map(str, shape_tail)) + ")" if shape_tail else "(N,)"
        raise ValueError(f"{name} must have shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} holds NaN or infinite values")
    return a


def _paired(first_name, first, second_name, second):
    """Two (N, 3) arrays of the same samples, checked."""
    a, b = _array(first_name, first, (3,)), _array(second_name, second, (3,))
    if a.shape != b.shape:
        raise ValueError(f"{second_name} {b.shape} and {first_name} {a.shape} differ in count")
    return a, b


def _positive(name, value):
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be positive, got {value!r}")
    return float(value)


def _size(size):
    try:
        width, height = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height), got {size!r}") from None
    if width < 1 or height < 1:
        raise ValueError(f"size must be positive, got {width} x {height}")
    return width, height


def _clip_matrix(world_to_clip):
    m = np.asarray(world_to_clip, np.float64)
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise ValueError(f"world_to_clip must be a finite 4x4 matrix, got shape {m.shape}")
    return m


def project(points, world_to_clip, size):
    """Pixel positions (N, 2) of world points (N, 3) through a 4x4 world to
    clip matrix (OpenGL clip space: x, y in [-1, 1] on screen, y up), x right
    and y down, pixel i covering [i, i + 1]; and (N,) True where the point is
    in front of the camera (clip w > 0)."""
    width, height = _size(size)
    m = _clip_matrix(world_to_clip)
    p = _array("points", points, (3,))
    clip = p @ m[:3, :3].T + m[:3, 3]
    w = p @ m[3, :3] + m[3, 3]
    front = w > 1e-12
    safe_w = np.where(front, w, 1.0)
    x = (clip[:, 0] / safe_w + 1.0) * 0.5 * width
    y = (1.0 - clip[:, 1] / safe_w) * 0.5 * height
    return np.stack([x, y], axis=1), front


def screen_displacement(points, velocities, world_to_clip, size):
    """(positions (N, 2), displacements (N, 2), valid (N,)) of samples at
    world points moving by world `velocities` (N, 3) in one frame: the pixel
    position at x and its change to x + v. Valid where both ends are in front
    of the camera."""
    p, v = _paired("points", points, "velocities", velocities)
    start, front0 = project(p, world_to_clip, size)
    end, front1 = project(p + v, world_to_clip, size)
    return start, end - start, front0 & front1


def splat(positions, values, weights, size):
    """Bilinear splat: (sum of weight * value (H, W, C), sum of weight (H, W))
    of samples at pixel positions (N, 2) (pixel centres at i + 0.5)."""
    width, height = _size(size)
    pos = _array("positions", positions, (2,))
    vals = np.asarray(values, np.float64)
    vals = vals[:, None] if vals.ndim == 1 else vals
    w = np.asarray(weights, np.float64)
    if len(vals) != len(pos) or w.shape != (len(pos),):
        raise ValueError(f"{len(pos)} positions need as many values and weights, got {len(vals)} and {w.shape}")
    gx, gy = pos[:, 0] - 0.5, pos[:, 1] - 0.5
    x0, y0 = np.floor(gx).astype(np.int64), np.floor(gy).astype(np.int64)
    fx, fy = gx - x0, gy - y0
    value_sum = np.zeros((height * width, vals.shape[1]))
    weight_sum = np.zeros(height * width)
    for dx, dy, share in ((0, 0, (1 - fx) * (1 - fy)), (1, 0, fx * (1 - fy)),
                          (0, 1, (1 - fx) * fy), (1, 1, fx * fy)):
        x, y = x0 + dx, y0 + dy
        inside = (x >= 0) & (x < width) & (y >= 0) & (y < height)
        index = (y * width + x)[inside]
        sw = (w * share)[inside]
        weight_sum += np.bincount(index, sw, minlength=height * width)
        for c in range(vals.shape[1]):
            value_sum[:, c] += np.bincount(index, sw * vals[inside, c], minlength=height * width)
    return value_sum.reshape(height, width, -1), weight_sum.reshape(height, width)


def _relax(out, holes, inside, iterations):
    """Jacobi sweeps in place: each hole becomes the mean of its 4-neighbours
    in `inside` (`out` is 0 outside it, so those add nothing)."""
    h, w = inside.shape
    region = np.pad(inside.astype(out.dtype), 1)
    count = region[:-2, 1:-1] + region[2:, 1:-1] + region[1:-1, :-2] + region[1:-1, 2:]
    update = (holes & (count > 0))[:, :, None]
    inverse = (1.0 / np.maximum(count, 1.0))[:, :, None]
    padded = np.zeros((h + 2, w + 2, out.shape[2]), out.dtype)
    for _ in range(iterations):
        padded[1:-1, 1:-1] = out
        total = padded[:-2, 1:-1] + padded[2:, 1:-1]
        total += padded[1:-1, :-2]
        total += padded[1:-1, 2:]
        total *= inverse
        np.copyto(out, total, where=update)


def _coarser(values, known, inside):
    """One pyramid level down (2 x 2 blocks, odd sizes padded): the mean of
    the known values of each block, known where any was, inside where any was."""
    h, w = known.shape
    pad = ((0, h % 2), (0, w % 2))
    values = np.pad(values, pad + ((0, 0),))
    known, inside = np.pad(known, pad), np.pad(inside, pad)
    H, W = known.shape[0] // 2, known.shape[1] // 2
    k = known.reshape(H, 2, W, 2).astype(np.float64)
    total = (values * known[:, :, None]).reshape(H, 2, W, 2, -1).sum(axis=(1, 3))
    count = k.sum(axis=(1, 3))
    coarse = total / np.maximum(count, 1.0)[:, :, None]
    return coarse, count > 0, inside.reshape(H, 2, W, 2).any(axis=(1, 3))


def diffuse_fill(values, known, inside, iterations=FILL_ITERATIONS):
    """Fills the pixels of `inside` (H, W bool) that are not `known` with the
    harmonic interpolation of the known ones (Laplace's equation, held at the
    known pixels, no flux across the border of `inside`), coarse to fine: each
    level starts from the level below and relaxes with Jacobi sweeps. Pixels
    outside `inside` are 0; a region of `inside` with no known pixel gets what
    diffuses in through the coarse levels, or 0."""
    values = np.asarray(values, np.float32)  # float32 halves the sweeps' memory traffic
    values = values[:, :, None] if values.ndim == 2 else values
    known, inside = np.asarray(known, bool) & np.asarray(inside, bool), np.asarray(inside, bool)
    if values.shape[:2] != known.shape or known.shape != inside.shape:
        raise ValueError(f"values {values.shape[:2]}, known {known.shape} and inside {inside.shape} differ in size")
    out = np.where(known[:, :, None], values, np.float32(0))
    holes = inside & ~known
    if not holes.any() or not known.any():
        return out
    rows, cols = np.flatnonzero(inside.any(axis=1)), np.flatnonzero(inside.any(axis=0))
    box = np.s_[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]  # the work is inside's bounding box only
    out[box] = _fill(out[box], known[box], inside[box], iterations)
    return out


def _fill(out, known, inside, iterations):
    holes = inside & ~known
    h, w = known.shape
    if min(h, w) > 2:
        coarse, coarse_known, coarse_inside = _coarser(out, known, inside)
        start = diffuse_fill(coarse, coarse_known, coarse_inside, iterations)
        up = np.repeat(np.repeat(start, 2, axis=0), 2, axis=1)[:h, :w]
        out = np.where(holes[:, :, None], up, out)
    _relax(out, holes, inside, iterations)
    return out


def fluid_velocity(points, velocities, weights, world_to_clip, size, alpha,
                   alpha_threshold=DEFAULT_ALPHA_THRESHOLD):
    """The fluid_velocity guide (H, W, 2) float32, pixels per frame, x right,
    y down, p moves to p + F in the next frame.

    points (N, 3): world positions of the samples; velocities (N, 3): their
    world displacement over one frame; weights (N,) >= 0: their density;
    world_to_clip: the camera's 4x4 world to clip matrix; size: (width,
    height); alpha (H, W): the render's coverage. Pixels with alpha above
    `alpha_threshold` get the density-weighted mean screen displacement of
    the samples splatted on them, or, where none was, the diffusion of their
    neighbours' (diffuse_fill); the others are 0."""
    width, height = _size(size)
    a = np.asarray(alpha, np.float64)
    if a.shape != (height, width):
        raise ValueError(f"alpha must be (height, width) = ({height}, {width}), got {a.shape}")
    if not np.isfinite(alpha_threshold) or not 0.0 <= alpha_threshold < 1.0:
        raise ValueError(f"alpha_threshold must be in [0, 1), got {alpha_threshold!r}")
    w = np.asarray(weights, np.float64)
    p = _array("points", points, (3,))
    if w.shape != (len(p),):
        raise ValueError(f"weights must have shape ({len(p)},), one per point, got {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError("weights (densities) must be finite and >= 0")
    start, displacement, valid = screen_displacement(p, velocities, world_to_clip, (width, height))
    valid &= w > 0  # most voxels of a gas domain are empty
    total, weight = splat(start[valid], displacement[valid], w[valid], (width, height))
    known = weight > 1e-12 * max(weight.max(initial=0.0), 1e-300)
    mean = total / np.where(known, weight, 1.0)[:, :, None]
    inside = np.isfinite(a) & (a > alpha_threshold)
    return diffuse_fill(mean, known, inside).astype(np.float32)


# --------------------------------------------------------------------------- sources

def _matrix(name, matrix):
    m = np.asarray(matrix, np.float64)
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise ValueError(f"{name} must be a finite 4x4 matrix, got shape {m.shape}")
    return m


class DomainGrid:
    """A Mantaflow domain's grid: resolution (X, Y, Z), its corners in the
    domain object's space, the object's matrix_world, and the length of a
    frame in Mantaflow time units (2.5 * time_scale / fps,
    MANTAFLOW_TIME_UNITS_PER_SECOND)."""

    def __init__(self, resolution, bounds_min, bounds_max, matrix_world, fps, time_scale=1.0):
        self.res = np.asarray(resolution, np.int64)
        if self.res.shape != (3,) or np.any(self.res < 1):
            raise ValueError(f"resolution must be 3 positive whole numbers, got {resolution!r}")
        self.matrix = _matrix("matrix_world", matrix_world)
        self.low, high = np.asarray(bounds_min, np.float64), np.asarray(bounds_max, np.float64)
        if self.low.shape != (3,) or high.shape != (3,) or np.any(high <= self.low):
            raise ValueError(f"bounds must be two 3D corners with min < max, got {bounds_min!r}, {bounds_max!r}")
        self.cell = (high - self.low) / self.res
        self.frame_length = (MANTAFLOW_TIME_UNITS_PER_SECOND * _positive("time_scale", time_scale)
                             / _positive("fps (frames per second)", fps))

    def count(self):
        return int(np.prod(self.res))

    def velocities(self, velocity_grid):
        """The grid's velocities (X * Y * Z, 3), x fastest, as object-space displacements per frame."""
        vel = np.asarray(velocity_grid, np.float64).reshape(-1)
        if vel.size != 3 * self.count():
            raise ValueError(f"a {' x '.join(map(str, self.res))} grid needs {3 * self.count()} velocity values, "
                             f"got {vel.size}")
        return vel.reshape(-1, 3) * self.cell * self.frame_length

    def voxel_centres(self):
        """Object-space voxel centres (X * Y * Z, 3), x fastest."""
        z, y, x = np.meshgrid(*(np.arange(n) for n in self.res[::-1]), indexing="ij")
        return self.low + (np.stack([x, y, z], axis=-1).reshape(-1, 3) + 0.5) * self.cell

    def sample(self, field, local_points):
        """Trilinear interpolation of a per-voxel field (X * Y * Z, C) at
        object-space points (N, 3), clamped to the voxel centres."""
        grid = np.asarray(field).reshape(self.res[2], self.res[1], self.res[0], -1)
        index = np.clip((local_points - self.low) / self.cell - 0.5, 0, self.res - 1)
        i0 = np.minimum(np.floor(index).astype(np.int64), self.res - 1)
        i1, t = np.minimum(i0 + 1, self.res - 1), index - i0
        out = np.zeros((len(local_points), grid.shape[3]))
        for corner in range(8):
            pick = [(corner >> axis) & 1 for axis in range(3)]
            ix, iy, iz = (np.where(pick[a], i1[:, a], i0[:, a]) for a in range(3))
            share = np.prod([np.where(pick[a], t[:, a], 1 - t[:, a]) for a in range(3)], axis=0)
            out += share[:, None] * grid[iz, iy, ix]
        return out

    def to_world(self, local_points, local_velocities):
        m = self.matrix
        return local_points @ m[:3, :3].T + m[:3, 3], local_velocities @ m[:3, :3].T


def gas_domain_samples(velocity_grid, density_grid, grid, density_scale=1):
    """(points, velocities per frame, weights) of a Mantaflow gas domain's
    voxels (DomainGrid `grid`), all in world space. velocity_grid: 3 * X * Y
    * Z floats (x fastest, as Blender's FluidDomainSettings.velocity_grid), in
    cells per Mantaflow time unit; density_grid: X * Y * Z floats, or with
    noise on (Quick Smoke's fire) (s X) * (s Y) * (s Z) at density_scale s =
    the noise upres, averaged over each voxel's s^3 noise cells."""
    dens = _base_density(np.asarray(density_grid, np.float64).reshape(-1), grid, int(density_scale))
    points, velocities = grid.to_world(grid.voxel_centres(), grid.velocities(velocity_grid))
    return points, velocities, np.maximum(np.nan_to_num(dens), 0.0)


def _base_density(dens, grid, scale):
    """The density on the velocity grid from one `scale` times finer per axis."""
    if scale < 1 or dens.size != grid.count() * scale ** 3:
        raise ValueError(f"a {' x '.join(map(str, grid.res))} grid at density scale {scale} needs "
                         f"{grid.count() * max(scale, 1) ** 3} density values, got {dens.size}")
    x, y, z = (int(n) for n in grid.res)
    return dens.reshape(z, scale, y, scale, x, scale).mean(axis=(1, 3, 5)).reshape(-1)


def liquid_grid_samples(vertices, velocity_grid, grid):
    """(points, velocities per frame, weights of 1) of a liquid mesh's
    vertices (N, 3, object space) moving with the domain's velocity grid
    (interpolated at each vertex): what a baked cache gives, whose liquid
    mesh reads back with a velocity attribute of zeros (Blender 3.4 writes no
    mesh velocity files)."""
    v = _array("vertices", vertices, (3,))
    return (*grid.to_world(v, grid.sample(grid.velocities(velocity_grid), v)), np.ones(len(v)))


def mesh_samples(vertices, velocity, matrix_world, domain_size, fps, time_scale=1.0):
    """(points, velocities per frame, weights of 1) of a liquid mesh: its
    vertices (N, 3) and their `velocity` attribute (N, 3), both in the domain
    object's space; domain_size is the longest side of the domain's bounds in
    that space.

    Blender writes the attribute as the Mantaflow velocity (cells per time
    unit) divided by the resolution and by the unscaled frame length
    2.5 / fps, so one frame moves a vertex by velocity * domain_size *
    2.5 * (2.5 * time_scale / fps) / fps. Measured on Blender 3.4
    (docs/guide_cache.md): at 24 fps, domains of 2 and 4 m with the same
    flow gave attributes of 3.2 and 1.6 for fronts that both moved 0.067 m
    per frame (the formula: 0.069)."""
    m = _matrix("matrix_world", matrix_world)
    v, vel = _paired("vertices", vertices, "velocity", velocity)
    unit = MANTAFLOW_TIME_UNITS_PER_SECOND / _positive("fps (frames per second)", fps)  # of an unscaled frame
    per_frame = vel * (_positive("domain_size", domain_size) * unit * unit * _positive("time_scale", time_scale))
    return v @ m[:3, :3].T + m[:3, 3], per_frame @ m[:3, :3].T, np.ones(len(v))


def particle_samples(locations, velocities, timestep=PARTICLE_SECONDS_PER_FRAME):
    """(points, velocities per frame, weights of 1) of live particles: world
    locations and velocities (N, 3); a frame moves a particle by velocity *
    timestep (Blender's 0.04 s times the system's timestep factor)."""
    loc, vel = _paired("locations", locations, "velocities", velocities)
    return loc, vel * _positive("timestep", timestep), np.ones(len(loc))


def merge_samples(*samples):
    """One (points, velocities, weights) of several sources, for one splat."""
    if not samples:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0)
    return tuple(np.concatenate(parts) for parts in zip(*samples))
