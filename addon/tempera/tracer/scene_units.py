"""Blender's light and camera settings in the physical units of Tempera's
light-path tracer (tempera.tracer.lpe), with numpy only (no bpy): the Blender side,
tempera.blender.scene_export, reads the settings and calls these.

The light conversions reproduce Cycles 3.4 and 4.x, measured with Cycles
renders of a diffuse floor (docs/lpe_guides.md, "Validation"):

* point and spot lights of power P watts have a radiant intensity of
  P / (4 pi) W/sr (spots in the centre of their cone); a radius r makes them
  a disk of radius r facing the shaded point, of radiance I / (pi r^2);
* a sun of strength S gives an irradiance of S W/m^2 on a surface facing it;
* an area light of power P and area A has a radiance of P / (4 A) W/m^2/sr
  on its front side in Cycles 3.x: it emits pi P / 4 watts, not P; Cycles 4.0
  made it P / (pi A), a Lambertian emitter of P watts (`emits_power`);
* emission shaders and the world background: radiance = colour x strength.
"""
from __future__ import annotations

import math

import numpy as np

SENSOR_FITS = ("AUTO", "HORIZONTAL", "VERTICAL")


def point_intensity(power, color):
    """Radiant intensity (W/sr, RGB) of a point or spot light of `power` watts."""
    return np.asarray(color, np.float64)[:3] * (power / (4.0 * math.pi))


def sun_irradiance(strength, color):
    """Irradiance (W/m^2, RGB) on a surface facing a sun of `strength`."""
    return np.asarray(color, np.float64)[:3] * strength


def area_size(shape, size, size_y):
    """Full extents (u, v) and area of an area light: Blender's SQUARE and
    DISK use `size` for both sides, RECTANGLE and ELLIPSE `size` x `size_y`;
    disks and ellipses take the area of the ellipse."""
    if shape not in ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE"):
        raise ValueError(f"unknown area light shape {shape!r}")
    u, v = (size, size) if shape in ("SQUARE", "DISK") else (size, size_y)
    area = u * v * (math.pi / 4.0 if shape in ("DISK", "ELLIPSE") else 1.0)
    return u, v, area


def area_radiance(power, color, area, emits_power=False):
    """Radiance (W/m^2/sr, RGB) of an area light of `power` watts and `area`
    m^2: Cycles 3.x's P / (4 A), or with `emits_power` Cycles 4.0's P / (pi A)."""
    if area <= 0:
        raise ValueError(f"an area light needs a positive area, got {area}")
    return np.asarray(color, np.float64)[:3] * (power / ((math.pi if emits_power else 4.0) * area))


def resolve_sensor_fit(fit, width, height):
    """The axis Blender fits the sensor (or the orthographic scale) to:
    'HORIZONTAL' or 'VERTICAL'. AUTO takes the larger side (width on ties)."""
    if fit not in SENSOR_FITS:
        raise ValueError(f"unknown sensor fit {fit!r}; expected one of {SENSOR_FITS}")
    if fit == "AUTO":
        return "HORIZONTAL" if width >= height else "VERTICAL"
    return fit


def camera_intrinsics(kind, width, height, *, lens=50.0, sensor_width=36.0, sensor_height=24.0,
                      sensor_fit="AUTO", ortho_scale=1.0, shift_x=0.0, shift_y=0.0):
    """The tracer's camera fields (tempera scene format) for a Blender camera
    rendering `width` x `height` pixels with square pixels.

    Blender fits the sensor (or ortho_scale) to one image axis: that axis
    spans sensor / lens at unit depth (ortho: ortho_scale), the other follows
    from the aspect ratio. AUTO fits the larger side but still uses
    sensor_width; HORIZONTAL / VERTICAL use sensor_width / sensor_height.
    Shift is in units of the fitted side, while the tracer measures it in
    units of the larger side, hence the rescaling of the shift below.
    """
    if width <= 0 or height <= 0:
        raise ValueError(f"image size must be positive, got {width} x {height}")
    fit = resolve_sensor_fit(sensor_fit, width, height)
    fitted_pixels = width if fit == "HORIZONTAL" else height
    larger_pixels = max(width, height)
    if kind == "PERSP":
        sensor = sensor_height if sensor_fit == "VERTICAL" else sensor_width
        span = sensor / lens  # of the fitted side, at unit depth
    elif kind == "ORTHO":
        span = ortho_scale
    else:
        raise ValueError(f"camera type {kind!r} is not supported (perspective and orthographic are)")
    per_pixel = span / fitted_pixels
    x_span, y_span = width * per_pixel, height * per_pixel
    # Shift offsets the image by shift * span; the tracer offsets it by
    # shift' * (span of the larger side).
    scale = span / (larger_pixels * per_pixel)
    out = {"type": "perspective" if kind == "PERSP" else "orthographic", "width": int(width),
           "height": int(height), "shift_x": float(shift_x * scale), "shift_y": float(shift_y * scale)}
    if kind == "PERSP":
        out.update(tan_half_fov_x=x_span / 2.0, tan_half_fov_y=y_span / 2.0)
    else:
        out.update(ortho_width=x_span, ortho_height=y_span)
    return out


def camera_ray(camera, x, y):
    """Camera-space origin and (unnormalised) direction of the ray through
    pixel centre (x + 0.5, y + 0.5), rows top-down, as the tracer defines it
    (native/include/tempera/tracer/scene.hpp). Used to check intrinsics against
    Blender's own projection."""
    ndc_x = 2.0 * (x + 0.5) / camera["width"] - 1.0
    ndc_y = 1.0 - 2.0 * (y + 0.5) / camera["height"]
    if camera["type"] == "perspective":
        t = max(camera["tan_half_fov_x"], camera["tan_half_fov_y"])
        direction = np.array([ndc_x * camera["tan_half_fov_x"] + 2 * camera["shift_x"] * t,
                              ndc_y * camera["tan_half_fov_y"] + 2 * camera["shift_y"] * t, -1.0])
        return np.zeros(3), direction
    s = max(camera["ortho_width"], camera["ortho_height"])
    origin = np.array([ndc_x * camera["ortho_width"] / 2 + camera["shift_x"] * s,
                       ndc_y * camera["ortho_height"] / 2 + camera["shift_y"] * s, 0.0])
    return origin, np.array([0.0, 0.0, -1.0])


def srgb_to_linear(values):
    """sRGB-encoded values in [0, 1] to linear (the IEC 61966-2-1 curve)."""
    v = np.asarray(values, np.float32)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4).astype(np.float32)
