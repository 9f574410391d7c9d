import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cmake_project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"^project\(tempera VERSION ([0-9.]+)", text, re.MULTILINE)
    assert match, "no project(tempera VERSION x.y.z) in CMakeLists.txt"
    return match.group(1)


@pytest.fixture(scope="session")
def cli_path():
    """The `tempera` CLI binary: $TEMPERA_CLI (set by tools/run_tests.py), else build/bin/tempera."""
    path = Path(os.environ.get("TEMPERA_CLI") or ROOT / "build" / "bin" / "tempera")
    assert path.is_file(), f"tempera CLI not found at {path}; run 'make build'"
    return path
