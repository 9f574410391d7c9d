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
