"""tempera.tracer.scene_units: Blender's light and camera settings in the tracer's units.
The camera against Blender's own projection is checked in blender_tests/test_lpe.py."""
import math

import numpy as np
import pytest

from tempera.tracer import scene_units as su


def test_light_conversions():
    np.testing.assert_allclose(su.point_intensity(100.0, (1, 0.5, 0)), np.array([1, 0.5, 0]) * 100 / (4 * math.pi))
    np.testing.assert_allclose(su.sun_irradiance(3.0, (1, 1, 0.5, 1)), [3, 3, 1.5])
    u, v, area = su.area_size("RECTANGLE", 2.0, 0.5)
    assert (u, v, area) == (2.0, 0.5, 1.0)
    u, v, area = su.area_size("DISK", 2.0, 0.5)  # a disk ignores size_y
    assert (u, v) == (2.0, 2.0) and area == pytest.approx(math.pi)
    assert su.area_size("ELLIPSE", 2.0, 1.0)[2] == pytest.approx(math.pi / 2)
    np.testing.assert_allclose(su.area_radiance(100.0, (1, 1, 1), 0.25), [100.0] * 3)
    np.testing.assert_allclose(su.area_radiance(100.0, (1, 1, 1), 0.25, emits_power=True), [400 / math.pi] * 3)
    with pytest.raises(ValueError, match="positive area"):
        su.area_radiance(1.0, (1, 1, 1), 0.0)
    with pytest.raises(ValueError, match="shape"):
        su.area_size("TRIANGLE", 1, 1)


@pytest.mark.parametrize("fit,width,height,expected", [
    ("AUTO", 200, 100, "HORIZONTAL"), ("AUTO", 100, 200, "VERTICAL"), ("AUTO", 100, 100, "HORIZONTAL"),
    ("VERTICAL", 200, 100, "VERTICAL"), ("HORIZONTAL", 100, 200, "HORIZONTAL")])
def test_sensor_fit(fit, width, height, expected):
    assert su.resolve_sensor_fit(fit, width, height) == expected


def test_perspective_intrinsics():
    # 50 mm lens on a 36 mm sensor fitted to the width: tan(fov_x / 2) = 18 / 50.
    cam = su.camera_intrinsics("PERSP", 200, 100, lens=50, sensor_width=36)
    assert cam["tan_half_fov_x"] == pytest.approx(0.36) and cam["tan_half_fov_y"] == pytest.approx(0.18)
    # AUTO on a portrait image fits the height, with sensor_width all the same.
    cam = su.camera_intrinsics("PERSP", 100, 200, lens=50, sensor_width=36, sensor_height=10)
    assert cam["tan_half_fov_y"] == pytest.approx(0.36) and cam["tan_half_fov_x"] == pytest.approx(0.18)
    # VERTICAL uses sensor_height, on the height.
    cam = su.camera_intrinsics("PERSP", 200, 100, lens=50, sensor_width=36, sensor_height=24,
                               sensor_fit="VERTICAL")
    assert cam["tan_half_fov_y"] == pytest.approx(0.24) and cam["tan_half_fov_x"] == pytest.approx(0.48)


def test_shift_is_rescaled_to_the_larger_side():
    # HORIZONTAL on a portrait image: Blender's shift unit is the width, the
    # tracer's the height (twice as large), so the tracer's shift is half.
    cam = su.camera_intrinsics("PERSP", 100, 200, lens=50, sensor_width=36, sensor_fit="HORIZONTAL",
                               shift_x=0.2, shift_y=-0.1)
    assert cam["shift_x"] == pytest.approx(0.1) and cam["shift_y"] == pytest.approx(-0.05)
    # The image centre moves by shift x (sensor / lens) at unit depth.
    origin, direction = su.camera_ray(cam, 49.5, 99.5)
    np.testing.assert_allclose(direction[:2], [0.2 * 36 / 50, -0.1 * 36 / 50], atol=1e-12)
    cam = su.camera_intrinsics("ORTHO", 300, 100, ortho_scale=6.0, shift_x=0.5)
    assert cam["ortho_width"] == pytest.approx(6.0) and cam["ortho_height"] == pytest.approx(2.0)
    origin, direction = su.camera_ray(cam, 149.5, 49.5)
    np.testing.assert_allclose(origin, [3.0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(direction, [0, 0, -1])


def test_camera_refusals():
    with pytest.raises(ValueError, match="not supported"):
        su.camera_intrinsics("PANO", 10, 10)
    with pytest.raises(ValueError, match="positive"):
        su.camera_intrinsics("PERSP", 0, 10)
    with pytest.raises(ValueError, match="sensor fit"):
        su.camera_intrinsics("PERSP", 10, 10, sensor_fit="DIAGONAL")


def test_srgb_to_linear():
    np.testing.assert_allclose(su.srgb_to_linear([0.0, 0.04045, 0.5, 1.0]),
                               [0.0, 0.04045 / 12.92, 0.21404, 1.0], rtol=1e-4)
