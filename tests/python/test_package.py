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
    package = ROOT / "addon" / "tempera"
    for path in package.rglob("*.py"):
        if "blender" not in path.relative_to(package).parts:
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


def test_wheel_version_comes_from_cmake():
    """pyproject.toml takes the wheel's version from CMakeLists.txt with a
    regex (scikit-build-core's regex provider): it must match the project line."""
    import re

    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    provider = pyproject["tool"]["scikit-build"]["metadata"]["version"]
    assert provider["provider"] == "scikit_build_core.metadata.regex" and provider["input"] == "CMakeLists.txt"
    match = re.search(provider["regex"], (ROOT / "CMakeLists.txt").read_text(), re.MULTILINE)
    assert match and match.group("value") == cmake_project_version() == tempera.__version__
    assert pyproject["project"]["dynamic"] == ["version"] and "version" not in pyproject["project"]
    assert pyproject["project"]["name"] == "tempera_native"  # not "tempera": Blender's shared wheel folder
    assert pyproject["project"]["scripts"] == {"tempera": "tempera.__main__:main"}
    assert not (ROOT / "setup.py").exists()


def test_extension_manifest_permissions_and_packer(tmp_path):
    """The packer adds the wheel to the manifest and refuses a wheel of another version."""
    import subprocess as sp

    manifest = tomllib.loads((ROOT / "addon" / "tempera" / "blender_manifest.toml").read_text())
    assert set(manifest["permissions"]) == {"files"} and len(manifest["permissions"]["files"]) <= 64
    assert "wheels" not in manifest
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import make_extension
    finally:
        sys.path.pop(0)
    names = [f"tempera_native-{tempera.__version__}-{tag}-{tag}-manylinux_2_28_x86_64.whl"
             for tag in ("cp311", "cp313")]
    text = make_extension.manifest_text(names, tempera.__version__)
    assert tomllib.loads(text)["wheels"] == [f"./wheels/{name}" for name in names]
    wrong = tmp_path / "tempera_native-9.9.9-cp311-cp311-manylinux_2_28_x86_64.whl"
    wrong.write_bytes(b"")
    result = sp.run([sys.executable, str(ROOT / "tools" / "make_extension.py"), "--wheel", str(wrong),
                     "--out", str(tmp_path / "x.zip")], capture_output=True, text=True)
    assert result.returncode != 0 and "version 9.9.9" in result.stderr
    unrepaired = tmp_path / f"tempera_native-{tempera.__version__}-cp311-cp311-linux_x86_64.whl"
    unrepaired.write_bytes(b"")
    result = sp.run([sys.executable, str(ROOT / "tools" / "make_extension.py"), "--wheel", str(unrepaired),
                     "--out", str(tmp_path / "x.zip")], capture_output=True, text=True)
    assert result.returncode != 0 and "not a repaired cp311 or cp313 manylinux" in result.stderr
    cp312 = tmp_path / f"tempera_native-{tempera.__version__}-cp312-cp312-manylinux_2_28_x86_64.whl"
    cp312.write_bytes(b"")
    result = sp.run([sys.executable, str(ROOT / "tools" / "make_extension.py"), "--wheel", str(cp312),
                     "--out", str(tmp_path / "x.zip")], capture_output=True, text=True)
    assert result.returncode != 0 and "not a repaired cp311 or cp313 manylinux" in result.stderr


def test_extension_packs_one_wheel_per_cpython(tmp_path):
    """Blender 4.2-5.0 run CPython 3.11 and 5.1+ CPython 3.13: the zip carries a wheel for each
    and its manifest lists both (Blender installs the one that matches); two wheels for one
    CPython are refused."""
    import subprocess as sp
    import zipfile

    wheels = []
    for tag in ("cp311", "cp313"):
        wheel = tmp_path / f"tempera_native-{tempera.__version__}-{tag}-{tag}-manylinux_2_28_x86_64.whl"
        wheel.write_bytes(tag.encode())
        wheels.append(wheel)
    args = [sys.executable, str(ROOT / "tools" / "make_extension.py"), "--out", str(tmp_path / "ext.zip")]
    result = sp.run(args + [a for w in wheels for a in ("--wheel", str(w))], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    with zipfile.ZipFile(tmp_path / "ext.zip") as zf:
        manifest = tomllib.loads(zf.read("blender_manifest.toml").decode())
        assert manifest["wheels"] == [f"./wheels/{w.name}" for w in wheels]
        assert [zf.read(f"wheels/{w.name}") for w in wheels] == [b"cp311", b"cp313"]
    twin = tmp_path / "twin" / wheels[1].name
    twin.parent.mkdir()
    twin.write_bytes(b"")
    result = sp.run(args + ["--wheel", str(wheels[1]), "--wheel", str(twin)], capture_output=True, text=True)
    assert result.returncode != 0 and "two cp313 wheels" in result.stderr


def test_legacy_zip_leaves_the_manifest_out(tmp_path):
    """Blender 4.2+ would take a zip with a manifest for an (incomplete) extension."""
    import subprocess as sp
    import zipfile

    out = tmp_path / "legacy.zip"
    sp.run([sys.executable, str(ROOT / "tools" / "make_addon_zip.py"), "--out", str(out)], check=True,
           capture_output=True)
    names = zipfile.ZipFile(out).namelist()
    assert "tempera/__init__.py" in names and any(n.startswith("tempera/_native") for n in names)
    assert not [n for n in names if n.endswith("blender_manifest.toml")]
