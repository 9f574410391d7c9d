"""tempera.trace_lpe / check_lpe: the native light-path-expression tracer from Python."""
import math

import numpy as np
import pytest

import tempera
from tempera.tracer.lpe import LIGHT_PATH_EXPRESSIONS, lpe_matches

from conftest import assert_releases_gil


def plane_scene(width=16, height=12, irradiance=2.0, albedo=0.5):
    """A large Lambert floor at z=0 under a sun straight above, seen from z=5."""
    s = 100.0
    camera = np.eye(4, dtype=np.float32)
    camera[2, 3] = 5.0
    return {
        "vertices": np.array([[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, s, 0]], np.float32),
        "triangles": np.array([[0, 1, 2], [0, 2, 3]], np.int32),
        "triangle_materials": np.zeros(2, np.int32),
        "materials": [{"base_color": [albedo] * 3, "specular": 0.0, "roughness": 1.0}],
        "lights": [{"type": "sun", "direction": [0.0, 0.0, 1.0], "irradiance": [irradiance] * 3}],
        "world": {"radiance": [0.0, 0.0, 0.0]},
        "camera": {"type": "perspective", "camera_to_world": camera, "width": width, "height": height,
                   "tan_half_fov_x": 0.4, "tan_half_fov_y": 0.3},
    }


def test_sun_on_lambert_plane():
    images, alpha = tempera.trace_lpe(plane_scene(), ["LDE", "LSE", "L.*E"], samples=16)
    assert len(images) == 3
    for image in images:
        assert image.shape == (12, 16, 3) and image.dtype == np.float32
    assert alpha.shape == (12, 16) and alpha.dtype == np.float32
    np.testing.assert_allclose(alpha, 1.0)
    expected = 0.5 / math.pi * 2.0
    np.testing.assert_allclose(images[0].mean(), expected, rtol=1e-3)
    assert images[1].max() < 1e-3 * expected
    np.testing.assert_allclose(images[2], images[0], rtol=1e-5)


def test_the_tracers_options_are_one_table():
    """Issue 41, step 6: tempera.TraceOptions' table gives trace_lpe's keywords,
    their defaults, ranges and help; a typo is a ValueError, not a default."""
    table = {row["name"]: row for row in tempera.TraceOptions.table()}
    assert (table["samples"]["default"], table["max_bounces"]["default"], table["seed"]["default"]) == (64, 8, 0)
    assert table["pixel_filter"]["choices"] == ["box", "gaussian", "blackman_harris"]
    assert all(row["help"] for row in table.values())
    for options, message in (({"bounces": 2}, "unknown option 'bounces'"),
                             ({"samples": 0}, r"samples must be in \[1, 1048576\], got 0"),
                             ({"max_bounces": -1}, "max bounces must be in"),
                             ({"pixel_filter": "mitchell"}, "unknown pixel filter 'mitchell'"),
                             ({"filter_width": 0}, "filter width must be above 0")):
        with pytest.raises(ValueError, match=message):
            tempera.trace_lpe(plane_scene(), ["LDE"], **options)
    defaults = {name: row["default"] for name, row in table.items()}
    (given,), _ = tempera.trace_lpe(plane_scene(), ["LDE"], **dict(defaults, samples=2))
    (default,), _ = tempera.trace_lpe(plane_scene(), ["LDE"], samples=2)
    np.testing.assert_array_equal(given, default)


def test_same_result_for_any_thread_count():
    one, _ = tempera.trace_lpe(plane_scene(), ["L.*E"], samples=4, seed=3, threads=1)
    two, _ = tempera.trace_lpe(plane_scene(), ["L.*E"], samples=4, seed=3, threads=2)
    np.testing.assert_array_equal(one[0], two[0])


def test_check_lpe_names_the_position():
    for expression in LIGHT_PATH_EXPRESSIONS.values():
        tempera.check_lpe(expression)
    with pytest.raises(ValueError, match=r"position 4: expected '\)'"):
        tempera.check_lpe("L(DE")
    with pytest.raises(ValueError, match="position 1"):
        tempera.trace_lpe(plane_scene(), ["LDE", "LX"], samples=1)
    assert lpe_matches("LD{1,2}E", "LDDE") and not lpe_matches("LD{1,2}E", "LDDDE")


def test_missing_and_unknown_keys_are_named():
    scene = plane_scene()
    del scene["camera"]["width"]
    with pytest.raises(ValueError, match="scene camera: missing key 'width'"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)
    scene = plane_scene()
    scene["materials"][0]["colour"] = 1
    with pytest.raises(ValueError, match="unknown keys 'colour'"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)


def test_bad_arrays_raise_value_error():
    scene = plane_scene()
    scene["vertices"][1, 2] = np.nan
    with pytest.raises(ValueError, match="vertex 1 is not finite"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)
    scene = plane_scene()
    scene["vertices"] = scene["vertices"][:, :2]
    with pytest.raises(ValueError, match=r"'vertices' must have shape \(4, 3\)"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)
    scene = plane_scene()
    scene["triangles"] = np.array([[0, 1, 2], [0, 2, 7]], np.int32)
    with pytest.raises(ValueError, match="triangle 1 uses vertex 7 but there are only 4 vertices"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)
    scene = plane_scene()
    scene["camera"]["width"] = 0
    with pytest.raises(ValueError, match="empty"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)


def test_releases_gil():
    scene = plane_scene(width=160, height=120)
    assert_releases_gil(lambda: tempera.trace_lpe(scene, ["LDE"], samples=64, threads=1))


def test_progress_can_cancel():
    fractions = []

    def progress(fraction):
        fractions.append(fraction)
        return len(fractions) < 3

    with pytest.raises(tempera.Cancelled):
        tempera.trace_lpe(plane_scene(), ["LDE"], samples=1, threads=1, progress=progress)
    assert len(fractions) == 3
    done = []
    tempera.trace_lpe(plane_scene(), ["LDE"], samples=1, progress=done.append)
    assert done[-1] == 1.0


def test_closures_mix_as_cycles_mix_shader():
    """A material of closures (the exporter's format): a Mix Shader at 0.25
    of two Diffuse BSDFs is their weighted albedo; no glossy lobe at all."""
    scene = plane_scene()
    scene["materials"] = [{"closures": [
        {"type": "diffuse", "color": [0.8, 0.8, 0.8], "factors": [{"kind": "constant", "value": 0.25,
                                                                    "invert": True}]},
        {"type": "diffuse", "color": [0.2, 0.2, 0.2], "factors": [{"kind": "constant", "value": 0.25}]},
    ]}]
    (lde, lse), _ = tempera.trace_lpe(scene, ["LDE", "LSE"], samples=16)
    expected = (0.75 * 0.8 + 0.25 * 0.2) / math.pi * 2.0
    np.testing.assert_allclose(lde.mean(), expected, rtol=1e-3)
    assert lse.max() == 0


def test_closure_keys_are_checked():
    scene = plane_scene()
    scene["materials"] = [{"closures": [{"type": "diffuse", "colour": [1, 0, 0]}]}]
    with pytest.raises(ValueError, match="scene material 0 closure 0: unknown keys 'colour'"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)
    scene["materials"] = [{"closures": [{"type": "velvet"}]}]
    with pytest.raises(ValueError, match="type must be one of"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)


def test_typed_scene_is_the_dict_scene():
    """scene_from_dict gives the bound classes, field by field; tracing either is the same."""
    from tempera import _native
    from tempera.tracer.lpe import scene_from_dict

    typed = scene_from_dict(plane_scene())
    assert isinstance(typed, _native.Scene) and typed.camera.width == 16
    assert typed.lights[0].type == _native.Light.Type.sun and typed.lights[0].irradiance == (2.0, 2.0, 2.0)
    np.testing.assert_array_equal(typed.triangles, [[0, 1, 2], [0, 2, 3]])
    a, _ = tempera.trace_lpe(typed, ["LDE"], samples=4)
    b, _ = tempera.trace_lpe(plane_scene(), ["LDE"], samples=4)
    np.testing.assert_array_equal(a[0], b[0])
    light = _native.Light()
    with pytest.raises(ValueError, match="must have 3 values"):
        light.position = (1.0, 2.0)


def test_a_lights_own_path_settings_reach_the_tracer():
    """Cycles' Light > Max Bounces and Multiple Importance, as the exporter
    writes them: read into the typed light, a bad count named."""
    from tempera.tracer.lpe import scene_from_dict

    scene = plane_scene()
    light = scene_from_dict(scene).lights[0]
    assert (light.max_bounces, light.multiple_importance) == (1024, True)  # Cycles' defaults
    scene["lights"][0].update(max_bounces=0, multiple_importance=False)
    light = scene_from_dict(scene).lights[0]
    assert (light.max_bounces, light.multiple_importance) == (0, False)
    (direct,), _ = tempera.trace_lpe(scene, ["LDE"], samples=4)
    assert direct.mean() > 0  # direct light is bounce 0: still lit
    scene["lights"][0]["max_bounces"] = -1
    with pytest.raises(ValueError, match="light 0 max_bounces must be >= 0, got -1"):
        tempera.trace_lpe(scene, ["LDE"], samples=1)


def test_closure_model_reaches_the_tracer():
    """The exporter's closure_model (compat.cycles_closure_model) is read key
    by key: Cycles 4.0's height-correlated shadowing brightens a rough glossy
    floor under a low sun; a misspelt key is named."""
    from tempera.tracer.lpe import scene_from_dict

    scene = plane_scene()
    scene["materials"] = [{"closures": [{"type": "glossy", "color": [1, 1, 1], "roughness": 1.0}]}]
    scene["lights"][0]["direction"] = [0.97, 0.0, 0.243]  # 76 degrees from the normal
    (separable,), _ = tempera.trace_lpe(scene, ["LSE"], samples=16)
    scene["closure_model"] = {"height_correlated_shadowing": True, "microfacet_glass_fresnel": True,
                              "energy_preserving_oren_nayar": True}
    typed = scene_from_dict(scene)
    assert typed.closure_model.height_correlated_shadowing and typed.closure_model.microfacet_glass_fresnel
    assert typed.closure_model.energy_preserving_oren_nayar
    (correlated,), _ = tempera.trace_lpe(scene, ["LSE"], samples=16)
    assert correlated.mean() > 1.008 * separable.mean()  # +1.2 %: the same samples, weighted by G2
    scene["closure_model"] = {"height_correlated": True}
    with pytest.raises(ValueError, match="scene closure_model: unknown keys 'height_correlated'"):
        tempera.trace_lpe(scene, ["LSE"], samples=1)


def test_principled_v2_reaches_the_tracer():
    """closure_model "principled_v2" and Principled v2's closure keys are read:
    a coat over a black base reflects (v1 would trace the coat weight as
    clearcoat of F0 0.04 and weight 0.25, v2 as a full dielectric layer), and
    its tint, read as a colour, darkens the diffuse below it."""
    from tempera.tracer.lpe import scene_from_dict

    scene = plane_scene()
    coat = {"type": "principled", "color": [0.8, 0.8, 0.8], "roughness": 0.5, "ior": 1.5, "clearcoat": 1.0,
            "clearcoat_roughness": 0.1, "coat_ior": 1.5, "coat_tint": [1.0, 0.5, 0.5], "specular_ior_level": 0.5,
            "specular_tint": [1.0, 1.0, 1.0], "multiscatter": True}
    scene["materials"] = [{"closures": [coat]}]
    scene["closure_model"] = {"height_correlated_shadowing": True, "principled_v2": True}
    typed = scene_from_dict(scene)
    assert typed.closure_model.principled_v2
    closure = typed.materials[0].closures[0]
    assert closure.multiscatter and closure.coat_ior == pytest.approx(1.5)
    assert np.allclose(closure.coat_tint, [1.0, 0.5, 0.5])
    (diffuse,), _ = tempera.trace_lpe(scene, ["LDE"], samples=16)
    red, green = diffuse[..., 0].mean(), diffuse[..., 1].mean()
    assert green < 0.6 * red  # the coat's tint absorbs green and blue under it
    scene["closure_model"] = {"height_correlated_shadowing": True}
    (v1,), _ = tempera.trace_lpe(scene, ["LDE"], samples=16)
    assert v1[..., 1].mean() > 0.9 * v1[..., 0].mean()  # v1 has no coat tint
