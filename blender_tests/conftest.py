"""Shared helpers for tests that run inside Blender (see run.py)."""
import os

import addon_utils
import bpy
import pytest

# The module name Blender knows the add-on by (run.py sets it): 'tempera' for
# the legacy add-on, 'bl_ext.user_default.tempera' for the extension, whose
# code is the package `tempera` from its wheel.
ADDON = os.environ.get("TEMPERA_TEST_ADDON_MODULE", "tempera")
INSTALL = os.environ.get("TEMPERA_TEST_INSTALL", "legacy")
PACKAGE = "tempera"


def _raise(exc):
    raise exc


def enable():
    """Enable the add-on; any error in register() fails the test."""
    module = addon_utils.enable(ADDON, default_set=True, handle_error=_raise)
    assert module is not None, "addon_utils.enable returned None"
    return module


def disable():
    addon_utils.disable(ADDON, default_set=True, handle_error=_raise)


def is_enabled():
    return addon_utils.check(ADDON) == (True, True) and ADDON in bpy.context.preferences.addons


_REGISTERABLE = (bpy.types.Panel, bpy.types.Operator, bpy.types.Menu, bpy.types.UIList,
                 bpy.types.PropertyGroup, bpy.types.AddonPreferences)


def _subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


def registered_tempera_classes():
    """Names of all Tempera classes Blender has registered. Panels, operators
    and menus show up in bpy.types; property groups and preferences do not,
    so these are found through the Python class hierarchy."""
    names = {n for n in dir(bpy.types) if n.lower().startswith("tempera")}
    for base in _REGISTERABLE:
        names.update(c.__name__ for c in _subclasses(base)
                     if c.__module__.split(".")[0] == PACKAGE and c.is_registered)
    return sorted(names)


@pytest.fixture(autouse=True)
def addon_enabled_around_each_test():
    """Each test starts, and leaves the next one, with the add-on enabled."""
    if not is_enabled():
        enable()
    yield
    if not is_enabled():
        enable()
