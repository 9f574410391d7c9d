#!/usr/bin/env python3
"""Writes the engine's option table (native/include/tempera/engine/synthesis_options.hpp,
as bound to Python) into docs/engine.md between its OPTIONS markers, so the
docs never restate it by hand. tests/python/test_docs.py checks it is current.

    PYTHONPATH=addon /usr/bin/python3 tools/option_docs.py
"""
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BEGIN, END = "<!-- OPTIONS BEGIN (tools/option_docs.py) -->", "<!-- OPTIONS END -->"


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


def render(text):
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{option_rows()}\n{END}{tail}"


if __name__ == "__main__":
    path = ROOT / "docs" / "engine.md"
    path.write_text(render(path.read_text()))
    print("updated", path, file=sys.stderr)
