"""`tempera.trace_lpe`: light-path-expression guides by path tracing.

StyLit matches light-path classes (thesis §8.3.2) that Cycles cannot isolate,
e.g. caustics ``LS*DE`` or the second diffuse bounce alone. This renders any
number of expressions in one pass with the native Embree tracer. The scene is
a typed ``tempera._native.Scene`` (its classes mirror ``tempera/tracer/scene.hpp``
field by field), or a plain dict of arrays turned into one by
``scene_from_dict`` (see ``docs/lpe_guides.md``, "Scene format"); the Blender
exporter builds the dict.
"""
from __future__ import annotations

from typing import Callable, Optional, Sequence

import numpy as np

from .. import _native

# The guides of the StyLit paper (thesis fig. 8.4), by name (native guide table).
LIGHT_PATH_EXPRESSIONS = {g["name"]: g["expression"] for g in _native.light_path_guides()}


class _Reader:
    """One dict of the scene format, read strictly: a missing required key or
    an unknown key is a ValueError naming it (an exporter typo must never
    silently change a render)."""

    def __init__(self, value, what):
        if not isinstance(value, dict):
            raise ValueError(f"{what} must be a dict")
        self.value, self.what, self.used = value, what, set()

    def has(self, key):
        return key in self.value

    def required(self, key):
        if key not in self.value:
            raise ValueError(f"{self.what}: missing key '{key}'")
        self.used.add(key)
        return self.value[key]

    def get(self, key, default=None):
        return self.required(key) if key in self.value else default

    def number(self, key, default=None):
        value = self.required(key) if default is None else self.get(key, default)
        try:
            return float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{self.what} '{key}' must be a number") from None

    def integer(self, key, default=None):
        value = self.required(key) if default is None else self.get(key, default)
        try:
            return int(value)
        except (TypeError, ValueError):
            raise ValueError(f"{self.what} '{key}' must be an integer") from None

    def text(self, key, choices, default=None):
        value = self.required(key) if default is None else self.get(key, default)
        if value not in choices:
            raise ValueError(f"{self.what}: {key} must be one of {', '.join(repr(c) for c in choices)}, "
                             f"got {value!r}")
        return value

    def finish(self):
        unknown = [k for k in self.value if k not in self.used]
        if unknown:
            raise ValueError(f"{self.what}: unknown keys " + ", ".join(f"'{k}'" for k in unknown))


def _enum(enum_type, name):
    return getattr(enum_type, name)


def _texture_ref(value, what):
    r = _Reader(value, what)
    t = _native.TextureRef()
    t.image = r.integer("image")
    if t.image < 0:
        raise ValueError(f"{what}: image must be >= 0")
    if r.has("uv"):
        uv = np.asarray(r.required("uv"), np.float32)
        if uv.shape != (2, 3):
            raise ValueError(f"{what} 'uv' must have shape (2, 3), got {uv.shape}")
        t.uv = [float(x) for x in uv.ravel()]
    t.channel = r.integer("channel", 4)
    r.finish()
    return t


def _factor(value, what):
    r = _Reader(value, what)
    f = _native.Factor()
    f.kind = _enum(_native.Factor.Kind, r.text("kind", ("constant", "texture", "fresnel", "layer_fresnel",
                                                         "layer_facing")))
    f.value = r.number("value", 1.0)
    if r.has("texture") or f.kind == _native.Factor.Kind.texture:
        f.texture = _texture_ref(r.required("texture"), f"{what} texture")
    f.invert = bool(r.get("invert", False))
    r.finish()
    return f


CLOSURE_TYPES = ("principled", "diffuse", "glossy", "glass", "refraction", "translucent", "transparent", "emission")


def _closure(value, what):
    r = _Reader(value, what)
    c = _native.Closure()
    c.type = _enum(_native.Closure.Type, r.text("type", CLOSURE_TYPES))
    for key in ("weight", "color", "subsurface_color", "specular_tint", "coat_tint"):
        if r.has(key):
            setattr(c, key, r.required(key))
    for key in ("roughness", "ior", "metallic", "specular", "transmission", "subsurface", "clearcoat",
                "clearcoat_roughness", "specular_ior_level", "coat_ior"):
        if r.has(key):
            setattr(c, key, r.number(key))
    c.multiscatter = bool(r.get("multiscatter", False))
    for key in ("color_texture", "roughness_texture"):
        if r.has(key):
            setattr(c, key, _texture_ref(r.required(key), f"{what} {key}"))
    if r.has("distribution"):
        c.distribution = _enum(_native.Closure.Distribution, r.text("distribution", ("ggx", "beckmann", "sharp")))
    factors = r.get("factors", [])
    if not isinstance(factors, (list, tuple)):
        raise ValueError(f"{what} 'factors' must be a list")
    c.factors = [_factor(f, f"{what} factor {i}") for i, f in enumerate(factors)]
    r.finish()
    return c


def _material(value, index):
    what = f"scene material {index}"
    r = _Reader(value, what)
    m = _native.Material()
    if r.has("closures"):
        closures = r.required("closures")
        if not isinstance(closures, (list, tuple)):
            raise ValueError(f"{what} 'closures' must be a list")
        m.closures = [_closure(c, f"{what} closure {i}") for i, c in enumerate(closures)]
        if r.has("base_color"):
            m.base_color = r.required("base_color")
    else:
        m.base_color = r.required("base_color")
    for key in ("metallic", "specular", "roughness", "transmission", "ior"):
        if r.has(key):
            setattr(m, key, r.number(key))
    if r.has("emission"):
        m.emission = r.required("emission")
    if r.has("base_color_texture"):
        m.base_color_texture = np.ascontiguousarray(r.required("base_color_texture"), np.float32)
    r.finish()
    return m


def _light(value, index):
    what = f"scene light {index}"
    r = _Reader(value, what)
    kind = r.text("type", ("point", "spot", "sun", "area"))
    light = _native.Light()
    light.type = _enum(_native.Light.Type, kind)
    if kind in ("point", "spot"):
        light.position, light.intensity = r.required("position"), r.required("intensity")
        light.radius = r.number("radius", 0.0)
        if kind == "spot":
            light.direction = r.required("direction")
            light.spot_half_angle = r.number("spot_half_angle")
            light.spot_blend = r.number("spot_blend", 0.0)
            light.spot_axis_cosine = bool(r.get("spot_axis_cosine", True))
        light.soft_shape = _enum(_native.Light.SoftShape, r.text("soft_shape", ("disk", "sphere"), "disk"))
    elif kind == "sun":
        light.direction, light.irradiance = r.required("direction"), r.required("irradiance")
        light.angle = r.number("angle", 0.0)
    else:
        for key in ("center", "axis_u", "axis_v", "normal", "radiance"):
            setattr(light, key, r.required(key))
        light.size_u, light.size_v = r.number("size_u"), r.number("size_v")
        light.shape = _enum(_native.Light.Shape, r.text("shape", ("rect", "disk"), "rect"))
    light.visibility = r.integer("visibility", 255)
    light.cast_shadow = bool(r.get("cast_shadow", True))
    light.max_bounces = r.integer("max_bounces", 1024)
    light.multiple_importance = bool(r.get("multiple_importance", True))
    r.finish()
    return light


def _camera(value):
    r = _Reader(value, "scene camera")
    c = _native.Camera()
    kind = r.text("type", ("perspective", "orthographic"))
    c.type = _enum(_native.Camera.Type, kind)
    c.camera_to_world = np.asarray(r.required("camera_to_world"), np.float32)
    c.width, c.height = r.integer("width"), r.integer("height")
    perspective = kind == "perspective"
    # Only the projection's own sizes are required; the other's may be present.
    for key in ("tan_half_fov_x", "tan_half_fov_y"):
        setattr(c, key, r.number(key) if perspective else r.number(key, 1.0))
    for key in ("ortho_width", "ortho_height"):
        setattr(c, key, r.number(key, 1.0) if perspective else r.number(key))
    for key, default in (("shift_x", 0.0), ("shift_y", 0.0), ("clip_start", 0.1), ("clip_end", 1000.0)):
        setattr(c, key, r.number(key, default))
    r.finish()
    return c


def _int_array(value, what: str) -> np.ndarray:
    a = np.asarray(value)
    if a.size and a.dtype.kind not in "iu":
        raise ValueError(f"scene '{what}' must be an integer array, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.int64)


def scene_from_dict(scene: dict):
    """The typed tempera._native.Scene of a scene dict (docs/lpe_guides.md,
    "Scene format"); a missing or unknown key raises ValueError naming it."""
    if isinstance(scene, _native.Scene):
        return scene
    r = _Reader(scene, "scene")
    s = _native.Scene()
    s.vertices = np.ascontiguousarray(r.required("vertices"), np.float32)
    s.triangles = _int_array(r.required("triangles"), "triangles")
    count = len(s.triangles)
    materials_of = _int_array(r.required("triangle_materials"), "triangle_materials")
    if materials_of.shape != (count,):
        raise ValueError(f"scene 'triangle_materials' must have shape ({count},)")
    s.triangle_materials = materials_of
    for key in ("normals", "uvs"):
        if r.has(key):
            value = np.ascontiguousarray(r.required(key), np.float32)
            if len(value) != count:
                raise ValueError(f"scene '{key}' must have {count} rows (one per triangle), got {len(value)}")
            setattr(s, key, value)
    if r.has("triangle_visibility"):
        visibility = _int_array(r.required("triangle_visibility"), "triangle_visibility")
        if visibility.shape != (count,):
            raise ValueError(f"scene 'triangle_visibility' must have shape ({count},)")
        s.triangle_visibility = visibility
    materials = r.required("materials")
    if not isinstance(materials, (list, tuple)):
        raise ValueError("scene 'materials' must be a list of dicts")
    s.materials = [_material(m, i) for i, m in enumerate(materials)]
    lights = r.get("lights", [])
    if not isinstance(lights, (list, tuple)):
        raise ValueError("scene 'lights' must be a list of dicts")
    s.lights = [_light(l, i) for i, l in enumerate(lights)]
    textures = r.get("textures", [])
    if not isinstance(textures, (list, tuple)):
        raise ValueError("scene 'textures' must be a list of arrays")
    s.textures = [np.ascontiguousarray(t, np.float32) for t in textures]
    if r.has("world"):
        w = _Reader(r.required("world"), "scene world")
        s.world_radiance = w.required("radiance")
        s.world_map = w.integer("map", -1)
        s.world_visibility = w.integer("visibility", 31)
        if w.has("rotation"):
            rotation = np.asarray(w.required("rotation"), np.float32)
            if rotation.shape != (3, 3):
                raise ValueError(f"scene world 'rotation' must have shape (3, 3), got {rotation.shape}")
            s.world_rotation = [float(x) for x in rotation.ravel()]
        w.finish()
    s.camera = _camera(r.required("camera"))
    if r.has("closure_model"):  # which Cycles' microfacets: {"height_correlated_shadowing": bool, ...}
        c = _Reader(r.required("closure_model"), "scene closure_model")
        for key in ("height_correlated_shadowing", "microfacet_glass_fresnel", "principled_v2",
                    "energy_preserving_oren_nayar"):
            setattr(s.closure_model, key, bool(c.get(key, False)))
        c.finish()
    r.finish()
    return s


def check_lpe(expression: str) -> None:
    """Raise ValueError naming the 0-based position if ``expression`` is malformed."""
    _native.check_lpe(str(expression))


def lpe_matches(expression: str, events: str) -> bool:
    """Whether the light-to-eye event string (e.g. ``"LDDE"``) matches ``expression``."""
    return _native.lpe_matches(str(expression), str(events))


TraceOptions = _native.TraceOptions  # the tracer's options (samples, seed, Cycles' bounce limits, ...)


def trace_lpe(scene: dict, expressions: Sequence[str], *,
              progress: Optional[Callable[[float], Optional[bool]]] = None, **options):
    """Render one linear radiance image per light path expression.

    ``expressions`` are written light-to-eye: ``L`` emitter (lights, emissive
    surfaces, world), ``D`` diffuse, ``S`` (or ``G``) glossy/specular
    reflection, ``T`` transmission, ``E`` eye; operators ``. * + ? {m} {m,}
    {m,n} [..] [^..] | ( )``.

    ``options`` are the fields of tempera.TraceOptions, whose ``table()``
    gives each one's default, range and help (the one table,
    native/include/tempera/tracer/embree_tracer.hpp): ``samples`` (64),
    ``seed`` (0; the result depends only on it, not on ``threads``),
    ``max_bounces`` (8, indirect bounces as Cycles counts them) and Cycles'
    per-kind limits (``diffuse_bounces`` ...; transparent surfaces count
    separately), ``caustics_reflective``/``caustics_refractive`` (False drops
    glossy/refractive lobes after a diffuse bounce), ``filter_glossy``
    (Cycles' Filter Glossy, 0: off), ``pixel_filter`` (``"box"``,
    ``"gaussian"``, ``"blackman_harris"``) and ``filter_width`` (pixels):
    Cycles' Film > Pixel Filter (default: the pixel itself). An unknown
    option or a value out of range is a ValueError naming it.
    ``progress(fraction)`` returning False cancels (raises ``tempera.Cancelled``).

    Returns ``(images, alpha)``: a list of float32 (H, W, 3) arrays in the
    order of ``expressions`` and the float32 (H, W) fraction of camera rays
    that hit geometry.
    """
    if isinstance(expressions, str):
        raise ValueError("expressions must be a list of strings, not one string")
    expressions = [str(e) for e in expressions]

    def report(fraction: float) -> bool:
        return True if progress is None else progress(fraction) is not False

    return _native.trace_lpe(scene_from_dict(scene), expressions, TraceOptions(**options), report)
