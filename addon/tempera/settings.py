"""Limits and defaults of Tempera's user settings (no bpy: shared by the
Blender UI, the tests and scripts that drive the engine without Blender)."""

DEFAULT_OUTPUT_DIR = "//tempera/"  # "//" = relative to the .blend file

PATCH_SIZE_DEFAULT = 5
PATCH_SIZE_MIN = 3
PATCH_SIZE_MAX = 15


def odd_patch_size(size):
    """The patch size actually used for `size`: patches need a centre pixel, so
    even sizes are rounded up to the next odd one, within [MIN, MAX]."""
    size = int(size)
    if size % 2 == 0:
        size += 1
    return max(PATCH_SIZE_MIN, min(PATCH_SIZE_MAX, size))


# Stylization defaults shared by the panel, scripts and the CLI's documentation.
# StyLit's light-path guides (names as in the guide cache) and their weights:
# LDE counts double because a painting's stroke density follows the direct
# diffuse shading; L.*DDE counts half, at guide sample counts it is the
# noisiest guide; LD{1,2}E is off by default (it needs a second render).
DEFAULT_GUIDE_WEIGHTS = {"FULL": 1.0, "LDE": 2.0, "LSE": 1.0, "LDDE": 0.5, "LD12E": 0.0}
# Pull towards the previous stylized frame advected along the motion (Fišer
# 2017, EbSynth); 0 stylizes every frame on its own. See docs/user_guide.md.
DEFAULT_TEMPORAL_WEIGHT = 0.5
QUALITY_PRESETS = ("preview", "final")
OUTPUT_FORMATS = ("png", "exr")
