"""tempera.app.fluid_velocity: projection, splat, diffusion fill and the units of each fluid source."""
import numpy as np
import pytest

from tempera.app import fluid_velocity as fv
from tempera.app import guide_cache

W, H = 64, 48


def perspective(focal=2.0, near=0.1, far=100.0, aspect=W / H):
    """OpenGL world to clip matrix of a camera at the origin looking down -z
    (x right, y up): ndc x = focal * x / -z / aspect, ndc y = focal * y / -z."""
    return np.array([[focal / aspect, 0, 0, 0],
                     [0, focal, 0, 0],
                     [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
                     [0, 0, -1, 0]])


def orthographic(half_width=2.0, aspect=W / H):
    return np.array([[1 / half_width, 0, 0, 0],
                     [0, aspect / half_width, 0, 0],
                     [0, 0, -0.01, 0],
                     [0, 0, 0, 1]])


def cloud(depth_range, count=4000, seed=1):
    """Points filling a box in front of the camera (z from -depth_range[0] to -depth_range[1])."""
    rng = np.random.default_rng(seed)
    points = rng.uniform([-0.6, -0.4, 0], [0.6, 0.4, 1], (count, 3))
    points[:, 2] = -(depth_range[0] + points[:, 2] * (depth_range[1] - depth_range[0]))
    return points


def test_uniform_velocity_in_perspective_gives_the_analytic_screen_displacement():
    points = cloud((3.0, 3.0))  # one depth: the displacement is the same everywhere
    velocity = np.array([0.05, -0.03, 0.0])  # per frame, world (y up)
    alpha = np.ones((H, W))
    field = fv.fluid_velocity(points, np.tile(velocity, (len(points), 1)), np.ones(len(points)),
                              perspective(), (W, H), alpha)
    focal, z = 2.0, 3.0
    expected = np.array([velocity[0] * focal / z / (W / H) * W / 2, -velocity[1] * focal / z * H / 2])  # y down
    covered = np.abs(field).sum(axis=2) > 0
    np.testing.assert_allclose(field[covered], np.broadcast_to(expected, field[covered].shape), rtol=1e-4)
    assert covered.sum() == W * H  # the fill reached every pixel inside the alpha


def test_orthographic_displacement_does_not_depend_on_depth():
    points = cloud((1.0, 8.0))
    velocity = np.array([0.1, 0.05, 0.0])
    field = fv.fluid_velocity(points, np.tile(velocity, (len(points), 1)), np.ones(len(points)),
                              orthographic(), (W, H), np.ones((H, W)))
    expected = [0.1 / 2.0 * W / 2, -0.05 * (W / H) / 2.0 * H / 2]
    np.testing.assert_allclose(field.reshape(-1, 2), np.broadcast_to(expected, (W * H, 2)), rtol=1e-4)


def test_density_weights_the_mean_of_a_pixel():
    """Two samples on one pixel centre: the mean is weighted by their densities."""
    m = orthographic()
    centre = np.array([[0.0, 0.0, -2.0], [0.0, 0.0, -3.0]])
    v = np.array([[0.2, 0.0, 0.0], [0.0, 0.0, 0.0]])
    start, disp, valid = fv.screen_displacement(centre, v, m, (W, H))
    assert valid.all()
    total, weight = fv.splat(start, disp, [3.0, 1.0], (W, H))
    x, y = np.floor(start[0]).astype(int)
    pixel = total[y, x] / weight[y, x]
    np.testing.assert_allclose(pixel[0], 0.75 * disp[0, 0], rtol=1e-6)


def test_bilinear_splat_keeps_the_total_weight():
    rng = np.random.default_rng(0)
    positions = rng.uniform([1, 1], [W - 1, H - 1], (500, 2))
    weights = rng.uniform(0.1, 2, 500)
    _total, weight = fv.splat(positions, np.zeros((500, 2)), weights, (W, H))
    assert weight.sum() == pytest.approx(weights.sum(), rel=1e-9)


def test_forward_convention_matches_the_motion_of_a_point():
    """p moves to p + F: the projection of x + v is where the splat's pixel value points."""
    m = perspective()
    x = np.array([[0.1, 0.2, -4.0]])
    v = np.array([[0.3, -0.1, 0.5]])
    start, disp, _ = fv.screen_displacement(x, v, m, (W, H))
    end, _ = fv.project(x + v, m, (W, H))
    np.testing.assert_allclose(start + disp, end)
    assert disp[0, 0] > 0 and disp[0, 1] > 0  # right and (y down) down for +x, -y world motion


def test_hole_fill_stays_inside_the_alpha():
    """Known values on the left of a disc, a hole on its right: the hole is
    filled with values between the known ones, nothing outside the disc."""
    yy, xx = np.mgrid[:H, :W]
    disc = (xx - 32) ** 2 + (yy - 24) ** 2 < 18 ** 2
    values = np.zeros((H, W, 2))
    values[:, :, 0] = 2.0 + 0.05 * yy  # varies, so the fill has to interpolate
    values[:, :, 1] = -1.0
    known = disc & (xx < 28)
    filled = fv.diffuse_fill(values, known, disc)
    holes = disc & ~known
    assert np.all(filled[~disc] == 0)
    np.testing.assert_allclose(filled[known], values[known])
    assert filled[holes, 0].min() >= values[known, 0].min() - 1e-6
    assert filled[holes, 0].max() <= values[known, 0].max() + 1e-6
    np.testing.assert_allclose(filled[holes, 1], -1.0, atol=1e-3)
    # a constant on the border stays the constant (harmonic), to a small residual
    const = fv.diffuse_fill(np.full((H, W, 2), 3.0), known, disc)
    np.testing.assert_allclose(const[holes], 3.0, atol=1e-3)


def test_outside_the_alpha_is_zero():
    points = cloud((3.0, 3.0))
    alpha = np.zeros((H, W))
    alpha[10:30, 10:40] = 0.5
    field = fv.fluid_velocity(points, np.tile([0.1, 0, 0], (len(points), 1)), np.ones(len(points)),
                              perspective(), (W, H), alpha)
    assert np.all(field[alpha == 0] == 0)
    assert np.all(field[alpha > 0, 0] > 0)


def test_gas_domain_voxels_and_mantaflow_units():
    """A uniform grid velocity g (cells per Mantaflow time unit) is g * cell *
    2.5 * time_scale / fps world units per frame; voxel centres fill the
    transformed bounds, x fastest."""
    res = (4, 3, 2)
    g = np.array([1.0, 0.5, 0.0])
    velocity = np.tile(g, int(np.prod(res)))
    density = np.arange(np.prod(res), dtype=float)
    matrix = np.diag([2.0, 1.0, 1.0, 1.0])
    matrix[:3, 3] = [10, 0, 0]
    grid = fv.DomainGrid(res, [-1, -1, -1], [1, 1, 1], matrix, fps=24, time_scale=0.5)
    points, per_frame, weights = fv.gas_domain_samples(velocity, density, grid)
    cell = np.array([2 / 4, 2 / 3, 2 / 2])
    np.testing.assert_allclose(points[0], [10 + 2 * (-1 + cell[0] / 2), -1 + cell[1] / 2, -1 + cell[2] / 2])
    np.testing.assert_allclose(points[1] - points[0], [2 * cell[0], 0, 0])  # x fastest
    np.testing.assert_allclose(points[4] - points[0], [0, cell[1], 0])
    expected = g * cell * 2.5 * 0.5 / 24 * [2, 1, 1]
    np.testing.assert_allclose(per_frame, np.broadcast_to(expected, per_frame.shape))
    np.testing.assert_allclose(weights, density)
    # the +2 m/s flow measured on Blender 3.4 (6.4 cells per unit in a 4 m, 32 cell domain) is 2/24 m per frame
    one_cell = fv.DomainGrid((1, 1, 1), [0, 0, 0], [4 / 32] * 3, np.eye(4), fps=24)
    _, v, _ = fv.gas_domain_samples([6.4, 0, 0], [1], one_cell)
    assert v[0, 0] == pytest.approx(2 / 24)


def test_a_noise_density_grid_is_averaged_onto_the_velocity_grid():
    """With Mantaflow's noise on, density_grid is noise_scale times finer per
    axis (Quick Smoke's fire); each voxel weighs the mean of its s^3 cells."""
    res, s = (3, 2, 2), 2
    grid = fv.DomainGrid(res, [0, 0, 0], [1, 1, 1], np.eye(4), fps=24)
    coarse = np.arange(12, dtype=float).reshape(2, 2, 3)  # z, y, x
    fine = coarse.repeat(s, 0).repeat(s, 1).repeat(s, 2)
    fine[0, 0, 0] += 8.0  # one noise cell of voxel 0: its mean rises by 1
    _, _, weights = fv.gas_domain_samples(np.zeros(3 * 12), fine.reshape(-1), grid, density_scale=s)
    np.testing.assert_allclose(weights, coarse.reshape(-1) + np.eye(12)[0])
    with pytest.raises(ValueError, match="density scale 2 needs 96 density values, got 12"):
        fv.gas_domain_samples(np.zeros(3 * 12), coarse.reshape(-1), grid, density_scale=s)


def test_liquid_vertices_take_the_interpolated_grid_velocity():
    """A grid velocity linear in x is interpolated exactly between voxel
    centres and clamped beyond them; a +3 m/s liquid (9.5 cells per unit
    in a 4 m, 32 cell domain, Blender 3.4) moves 0.124 m per frame."""
    res = (4, 2, 2)
    grid = fv.DomainGrid(res, [0, 0, 0], [4, 2, 2], np.eye(4), fps=24)
    centres = grid.voxel_centres()
    field = np.zeros((len(centres), 3))
    field[:, 0] = centres[:, 0]  # vx = x cells per unit
    points, v, w = fv.liquid_grid_samples([[1.25, 0.7, 1.1], [0.1, 1, 1], [3.9, 1, 1]], field.reshape(-1), grid)
    frame = 2.5 / 24
    np.testing.assert_allclose(v[:, 0], np.array([1.25, 0.5, 3.5]) * frame)
    np.testing.assert_allclose(v[:, 1:], 0)
    assert list(w) == [1, 1, 1]
    liquid = fv.DomainGrid((32, 16, 16), [-2, -1, -1], [2, 1, 1], np.eye(4), fps=24)
    _, v, _ = fv.liquid_grid_samples([[0, 0, 0]], np.tile([9.5, 0, 0], 32 * 16 * 16), liquid)
    assert v[0, 0] == pytest.approx(0.124, rel=0.01)


def test_liquid_mesh_and_particle_units():
    matrix = np.eye(4)
    matrix[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # 90 degrees about z
    points, v, w = fv.mesh_samples([[1, 0, 0]], [[3.2, 0, 0]], matrix, domain_size=2.0, fps=24)
    np.testing.assert_allclose(points, [[0, 1, 0]], atol=1e-12)
    # Blender 3.4's liquid front at 3.2 in a 2 m domain moved 0.067 m per frame (24 fps)
    np.testing.assert_allclose(v, [[0, 3.2 * 2 * (2.5 / 24) ** 2, 0]], atol=1e-12)
    assert v[0, 1] == pytest.approx(0.067, rel=0.05)
    _, v2, _ = fv.mesh_samples([[1, 0, 0]], [[1.6, 0, 0]], np.eye(4), domain_size=4.0, fps=24)
    assert v2[0, 0] == pytest.approx(v[0, 1])  # the 4 m domain's front moved as fast
    assert list(w) == [1.0]
    loc, pv, _ = fv.particle_samples([[0, 0, 5]], [[0, 0, 3]], timestep=0.04)
    np.testing.assert_allclose(pv, [[0, 0, 0.12]])  # Blender 3.4 moved it 0.12 per frame
    merged = fv.merge_samples((points, v, w), (loc, pv, np.ones(1)))
    assert merged[0].shape == (2, 3) and merged[2].shape == (2,)


@pytest.mark.parametrize("call, message", [
    (lambda: fv.fluid_velocity(np.zeros((3, 2)), np.zeros((3, 3)), np.ones(3), np.eye(4), (W, H),
                               np.ones((H, W))), "points must have shape"),
    (lambda: fv.fluid_velocity(np.zeros((3, 3)), np.zeros((2, 3)), np.ones(3), np.eye(4), (W, H),
                               np.ones((H, W))), "differ in count"),
    (lambda: fv.fluid_velocity(np.zeros((3, 3)), np.zeros((3, 3)), -np.ones(3), np.eye(4), (W, H),
                               np.ones((H, W))), "weights"),
    (lambda: fv.fluid_velocity(np.zeros((3, 3)), np.zeros((3, 3)), np.ones(3), np.eye(3), (W, H),
                               np.ones((H, W))), "4x4"),
    (lambda: fv.fluid_velocity(np.zeros((3, 3)), np.zeros((3, 3)), np.ones(3), np.eye(4), (0, H),
                               np.ones((H, W))), "size must be positive"),
    (lambda: fv.fluid_velocity(np.zeros((3, 3)), np.zeros((3, 3)), np.ones(3), np.eye(4), (W, H),
                               np.ones((W, H))), "alpha must be"),
    (lambda: fv.fluid_velocity(np.full((3, 3), np.nan), np.zeros((3, 3)), np.ones(3), np.eye(4), (W, H),
                               np.ones((H, W))), "NaN"),
    (lambda: fv.gas_domain_samples(np.zeros(5), np.zeros(2), fv.DomainGrid((2, 1, 1), [0] * 3, [1] * 3,
                                                                           np.eye(4), 24)), "grid needs"),
    (lambda: fv.DomainGrid((2, 1, 1), [0] * 3, [1] * 3, np.eye(4), 0), "fps"),
    (lambda: fv.DomainGrid((2, 0, 1), [0] * 3, [1] * 3, np.eye(4), 24), "resolution"),
    (lambda: fv.DomainGrid((2, 1, 1), [0] * 3, [1, 0, 1], np.eye(4), 24), "bounds"),
    (lambda: fv.particle_samples(np.zeros((2, 3)), np.zeros((2, 3)), timestep=0), "timestep"),
    (lambda: fv.mesh_samples(np.zeros((2, 3)), np.zeros((2, 3)), np.eye(4), 0.0, 24), "domain_size"),
])
def test_bad_input_names_the_problem(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_no_samples_give_zeros_and_the_guide_is_in_the_cache_table():
    field = fv.fluid_velocity(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), perspective(), (W, H),
                              np.ones((H, W)))
    assert field.shape == (H, W, 2) and field.dtype == np.float32 and not field.any()
    disc = np.ones((H, W), bool)
    assert not fv.diffuse_fill(np.full((H, W, 2), 3.0), np.zeros((H, W), bool), disc).any()  # nothing known
    assert guide_cache.channel_names("fluid_velocity") == ["fluid_velocity.X", "fluid_velocity.Y"]
