"""Limits and defaults of Tempera's user settings (no bpy: shared by the
Blender UI, the tests and scripts that drive the engine without Blender).
The engine's and StyLit's come from the native tables, where they are
defined once (synthesis_options.hpp, stylit.hpp)."""
from .. import _native

DEFAULT_OUTPUT_DIR = "//tempera/"  # "//" = relative to the .blend file

# name -> row of the engine's option table (name, flag, help, default, min, max, choices).
ENGINE_OPTIONS = {row["name"]: row for row in _native.SynthesisOptions.table()}
PATCH_SIZE_DEFAULT = ENGINE_OPTIONS["patch_size"]["default"]
PATCH_SIZE_MIN = int(ENGINE_OPTIONS["patch_size"]["min"])
# The panel stops at 15 (the engine takes up to the table's max, for very
# coarse media, from scripts and the CLI).
PATCH_SIZE_MAX = min(15, int(ENGINE_OPTIONS["patch_size"]["max"]))
SEED_DEFAULT = ENGINE_OPTIONS["seed"]["default"]


def odd_patch_size(size):
    """The patch size actually used for `size`: patches need a centre pixel, so
    even sizes are rounded up to the next odd one, within [MIN, MAX]."""
    size = int(size)
    if size % 2 == 0:
        size += 1
    return max(PATCH_SIZE_MIN, min(PATCH_SIZE_MAX, size))


# StyLit's light-path guides (names as in the guide cache): name, expression,
# default weight, label and help, in matching order.
LIGHT_PATH_GUIDES = tuple(_native.light_path_guides())
DEFAULT_GUIDE_WEIGHTS = {g["name"]: g["weight"] for g in LIGHT_PATH_GUIDES}
# Pull towards the previous stylized frame advected along the motion (Fišer
# 2017, EbSynth); 0 stylizes every frame on its own. The engine and the CLI
# default to 0 (frames independent, so farms can split a shot anywhere); the
# panel starts artists at 0.5, measured on the demo: flicker 0.030 -> 0.011
# with the stroke detail kept (docs/user_guide.md).
# StyLit's option table (stylit.hpp): name -> row (flag, help, default, min, max, choices).
STYLIT_OPTIONS = {row["name"]: row for row in _native.StylitOptions.table()}
DEFAULT_TEMPORAL_WEIGHT = STYLIT_OPTIONS["temporal_weight"]["default"]
PANEL_TEMPORAL_WEIGHT = 0.5
# The panel's Guided Noise checkbox sets noise_guides to this (docs/noisy.md:
# 0.5 and 1 keep the same share of thin strokes; 0.5 was the probe's best).
PANEL_NOISE_GUIDES = 0.5
DEFAULT_QUALITY = STYLIT_OPTIONS["quality"]["default"]
OUTPUT_FORMATS = ("png", "exr")
