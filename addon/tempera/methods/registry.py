"""The method registry (native/include/tempera/methods/registry.hpp) for the
Python side: the panel's Method list, the `tempera` console script's
dispatch and the farm planner read it, so a method is named once."""
from __future__ import annotations

import importlib

from .. import _native

METHODS = tuple(_native.methods())  # dicts: name, title, summary, paper, unit, docs, python_command


def names() -> list:
    return [m["name"] for m in METHODS]


def find(name: str) -> dict:
    """The entry of `name`; ValueError naming every method (the CLI's message)."""
    return _native.find_method(str(name))


def panel_items() -> tuple:
    """The panel's Method EnumProperty items: (NAME, title, summary) in the registry's order."""
    return tuple((m["name"].upper(), m["title"], m["summary"]) for m in METHODS)


def python_command(name: str):
    """The function that runs `tempera stylize --method NAME ...` for a method
    written in Python (rigid), or None for a method of the native command."""
    entry = next((m for m in METHODS if m["name"] == name), None)
    if entry is None or not entry["python_command"]:
        return None
    module, function = entry["python_command"].split(":")
    return getattr(importlib.import_module(module), function)
