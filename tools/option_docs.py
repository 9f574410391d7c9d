#!/usr/bin/env python3
"""Writes the engine's option table (native/include/tempera/engine/synthesis_options.hpp,
as bound to Python) into docs/engine.md between its OPTIONS markers, and every
method of the registry (native/include/tempera/methods/registry.hpp) with its
options into docs/methods.md between its METHODS markers, so the docs never
restate them by hand. tests/python/test_docs.py checks both are current.

    PYTHONPATH=addon /usr/bin/python3 tools/option_docs.py
"""
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BEGIN, END = "<!-- OPTIONS BEGIN (tools/option_docs.py) -->", "<!-- OPTIONS END -->"
METHODS_BEGIN, METHODS_END = "<!-- METHODS BEGIN (tools/option_docs.py) -->", "<!-- METHODS END -->"
UNITS = {"frame": "independent frames (a farm splits them anywhere)",
         "segment": "segments from key to key (a farm task each)",
         "chained frame": "chained frames (each made from the previous: one farm task)"}


def option_rows():
    import tempera

    lines = ["| option (`--flag`) | default | range | what it does |", "| --- | --- | --- | --- |"]
    for row in tempera.SynthesisOptions.table():
        default = row["default"]
        default = ",".join(map(str, default)) if isinstance(default, list) else str(default)
        if row["choices"]:
            valid = " \\| ".join(row["choices"])
        elif math.isinf(row["min"]) and math.isinf(row["max"]):
            valid = ""
        else:
            valid = f"{row['min']:g} – {row['max']:g}"
        lines.append(f"| `{row['name']}` (`--{row['flag']}`) | {default or 'none'} | {valid} | {row['help']} |")
    return "\n".join(lines)


def default_exemplar_text(kind):
    import tempera

    if not kind:
        return "none: give the artist's own"
    if kind == tempera._native.JOB_MADE_EXEMPLAR:
        return "made by the job"
    if kind == tempera._native.KIT_EXEMPLAR:
        return "the bundled exemplar kit (the Python package's `tempera`)"
    return f"the project's own `{kind}` (`tempera exemplar {kind}`, written into OUT)"


def method_sections():
    """A section per method of the registry, in its order: what the panel's
    tooltip says, its paper, unit, default exemplar, page and options."""
    from tempera.methods import registry

    parts = []
    for m in registry.METHODS:
        default = " (the default method)" if m["name"] == registry.default_name() else ""
        parts.append("\n".join([
            f"## `--method {m['name']}`: {m['title']}{default}", "",
            m["summary"] + ("" if m["summary"].endswith(".") else "."), "",
            f"- paper: {m['paper']}; details: [{Path(m['docs']).name}]({Path(m['docs']).name})",
            f"- unit of work: {UNITS.get(m['unit'], m['unit'])}",
            f"- default exemplar: {default_exemplar_text(m['default_exemplar'])}", "",
            "```", m["options_help"].rstrip("\n"), "```"]))
    return "\n\n".join(parts)


def replace_between(text, begin, end, body):
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{begin}\n{body}\n{end}{tail}"


def render(text):
    return replace_between(text, BEGIN, END, option_rows())


def render_methods(text):
    return replace_between(text, METHODS_BEGIN, METHODS_END, method_sections())


if __name__ == "__main__":
    for name, how in (("engine.md", render), ("methods.md", render_methods)):
        path = ROOT / "docs" / name
        path.write_text(how(path.read_text()))
        print("updated", path, file=sys.stderr)
