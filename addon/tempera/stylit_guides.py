"""StyLit's light-path guides (Fišer et al. 2016, thesis eq. 8.2) from
Blender render passes, with no bpy.

    {A, B} = (FULL, LDE, LSE, L.*DDE, LD{1,2}E)

computed from Cycles' passes as

    FULL    Combined RGB                  (the whole global illumination render)
    LDE     DiffDir * DiffCol             (direct diffuse)
    LSE     GlossDir * GlossCol           (direct specular)
    L.*DDE  DiffInd * DiffCol             (diffuse interreflection: the light
                                           reaching a diffuse surface after at
                                           least one earlier bounce)

LD{1,2}E (the first two diffuse bounces) is left out: Cycles' passes split
direct from indirect light but do not count bounces, so it would need a
second render with the diffuse bounce limit set to 1 (its Combined minus
glossy). The synthesis does not expect any particular set of guides.

Every guide goes through the same tone curve, `tonemap` (Reinhard x/(1+x),
then the sRGB encoding), for the exemplar and the target alike: values land
in [0, 1), bright highlights stay distinct instead of clipping, dark values
(shadows, interreflections) are spread out as the eye sees them, and the
guide weights mean the same for every guide and every render.
"""
import numpy as np

from .color import linear_to_srgb

GUIDE_NAMES = ("FULL", "LDE", "LSE", "L.*DDE")
# Blender passes the guides are computed from (names as in tempera.passes.PASSES).
REQUIRED_PASSES = ("Combined", "DiffDir", "DiffCol", "GlossDir", "GlossCol", "DiffInd")


def tonemap(linear):
    """Linear radiance (>= 0) -> guide values in [0, 1): x/(1+x), sRGB-encoded.
    NaN and negative values (noise in subtracted passes) become 0."""
    x = np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0, posinf=1e6, neginf=0.0)
    x = np.maximum(x, 0.0)
    return linear_to_srgb(x / (1.0 + x))


def _rgb(passes, name):
    try:
        array = np.asarray(passes[name], dtype=np.float32)
    except KeyError:
        raise ValueError(f"stylit_guides: pass {name!r} missing (have {sorted(passes)}; need {', '.join(REQUIRED_PASSES)})") from None
    if array.ndim != 3 or array.shape[2] < 3:
        raise ValueError(f"stylit_guides: pass {name!r} must be (H, W, >=3), got shape {array.shape}")
    return array[:, :, :3]


def stylit_guides(passes):
    """The StyLit guides of one render.

    passes  dict pass name -> float (H, W, C) linear array, C >= 3 (extra
            channels such as Combined's alpha are ignored), holding at least
            REQUIRED_PASSES.

    Returns [(name, (H, W, 3) float32 array in [0, 1)), ...] in GUIDE_NAMES order.
    """
    rgb = {name: _rgb(passes, name) for name in REQUIRED_PASSES}
    shapes = {a.shape for a in rgb.values()}
    if len(shapes) != 1:
        raise ValueError(f"stylit_guides: passes differ in size: {sorted(shapes)}")
    linear = {
        "FULL": rgb["Combined"],
        "LDE": rgb["DiffDir"] * rgb["DiffCol"],
        "LSE": rgb["GlossDir"] * rgb["GlossCol"],
        "L.*DDE": rgb["DiffInd"] * rgb["DiffCol"],
    }
    return [(name, tonemap(linear[name])) for name in GUIDE_NAMES]


def read_stylit_passes(path, view_layer="ViewLayer"):
    """REQUIRED_PASSES of a Blender multilayer EXR, as the dict stylit_guides takes."""
    from .passes import read_pass

    return {name: read_pass(path, name, view_layer) for name in REQUIRED_PASSES}
