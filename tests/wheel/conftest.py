"""Fixtures of the wheel level: the repaired wheel (TEMPERA_TEST_WHEEL, set by
tools/run_tests.py) pip-installed into a fresh folder, as a user installs it.
Runs under a Python with pip, numpy and dask (~/.cache/tempera/venv-tools),
never with addon/ on sys.path."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))  # synthetic_cache (imports tempera lazily, from the wheel)


def cmake_project_version():
    return re.search(r"^project\(tempera VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text(), re.M).group(1)


@pytest.fixture(scope="session")
def wheel():
    path = os.environ.get("TEMPERA_TEST_WHEEL")
    if not path or not Path(path).is_file():
        pytest.fail(f"TEMPERA_TEST_WHEEL is not a wheel file ({path!r}); run 'make wheel'")
    return Path(path)


@pytest.fixture(scope="session")
def installed(wheel, tmp_path_factory):
    """Folder the wheel was pip-installed into (--target), put first on this
    process's sys.path and on PYTHONPATH for subprocesses and Dask workers."""
    target = tmp_path_factory.mktemp("site")
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--disable-pip-version-check",
                    "--target", str(target), str(wheel)], check=True)
    assert not any(str(ROOT / "addon") == p for p in sys.path)
    sys.path.insert(0, str(target))
    os.environ["PYTHONPATH"] = str(target)
    os.environ.pop("TEMPERA_CLI", None)  # the wheel's own CLI, not build/bin/tempera
    return target
