"""The `tempera` package outside Blender: import, versions, metadata."""
import shutil
import subprocess
import sys
import tomllib

import pytest

import tempera
from conftest import ROOT, cmake_project_version


def run_python(code, **kwargs):
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, **kwargs)


def test_import_does_not_need_bpy():
    result = run_python("import sys, tempera; print('bpy' in sys.modules, tempera.__version__)")
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["False", tempera.__version__]


def test_blender_subpackage_is_the_only_bpy_user():
    for path in (ROOT / "addon" / "tempera").glob("*.py"):
        assert "import bpy" not in path.read_text(), f"{path.name} imports bpy outside tempera.blender"
    with pytest.raises(ImportError, match="bpy"):
        import tempera.blender  # noqa: F401


def test_version_matches_cmake_project_version():
    assert tempera.__version__ == cmake_project_version()
    assert tempera._native.__version__ == tempera.__version__


def test_bl_info():
    info = tempera.bl_info
    assert info["name"] == "Tempera"
    assert info["category"] == "Render"
    assert info["location"] == "Properties > Output > Tempera"
    assert info["blender"] == (3, 4, 0)
    assert info["version"] == tuple(int(p) for p in tempera.__version__.split("."))


def test_extension_manifest():
    manifest = tomllib.loads((ROOT / "addon" / "tempera" / "blender_manifest.toml").read_text())
    assert manifest["schema_version"] == "1.0.0"
    assert manifest["id"] == "tempera"
    assert manifest["version"] == tempera.__version__
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert manifest["platforms"] == ["linux-x64"]
    for key in ("name", "tagline", "maintainer"):
        assert manifest[key]
    assert len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith(".")


def test_public_api():
    for name in tempera.__all__:
        assert hasattr(tempera, name), name
    assert issubclass(tempera.Cancelled, RuntimeError)


def test_missing_native_module_says_how_to_build_it(tmp_path):
    package = tmp_path / "tempera"
    shutil.copytree(ROOT / "addon" / "tempera", package, ignore=shutil.ignore_patterns("_native*", "__pycache__"))
    result = run_python("import tempera", cwd=tmp_path, env={"PYTHONPATH": str(tmp_path)})
    assert result.returncode != 0
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError:"), result.stderr
    assert "make build" in last and "tempera._native" in last


def test_setup_py_version_comes_from_cmake():
    result = subprocess.run([sys.executable, "setup.py", "--version"], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == cmake_project_version()
