"""The repaired wheel pip-installed: `import tempera`, the `tempera` command,
metadata, and no dependency on the system's OpenImageIO, Embree or TBB."""
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from conftest import cmake_project_version

VENDORED = re.compile(r"lib(OpenImageIO|OpenImageIO_Util|embree3|tbb|OpenEXR|OpenEXRCore|Imath|Iex|IlmThread)\b")


def test_wheel_name_tag_and_metadata(wheel):
    version = cmake_project_version()
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"  # the wheel for this Python: cp311, cp313
    assert re.fullmatch(rf"tempera_native-{re.escape(version)}-{tag}-{tag}-manylinux_2_\d+_x86_64\.whl", wheel.name)
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
        entry_points = zf.read(f"tempera_native-{version}.dist-info/entry_points.txt").decode()
        metadata = zf.read(f"tempera_native-{version}.dist-info/METADATA").decode()
    assert re.search(r"^tempera = tempera\.__main__:main$", entry_points, re.M)
    assert re.search(r"^Requires-Dist: numpy", metadata, re.M)
    assert "tempera/__init__.py" in names and "tempera_native/bin/tempera" in names
    assert not [n for n in names if n.startswith("tempera/_native")], "a stray source-tree module in the wheel"
    assert not [n for n in names if n.startswith("tempera/kit/")]


# manylinux_2_28 (Rocky/Alma Linux 8, the VFX Reference Platform 2021-2023, blender.org's own
# builds): glibc 2.28 and GCC 8's libstdc++ (auditwheel's policy for the tag).
NEWEST = {"GLIBC": (2, 28), "GLIBCXX": (3, 4, 25), "CXXABI": (1, 3, 11), "GCC": (7, 0, 0)}


def test_wheel_installs_on_glibc_2_28(wheel, tmp_path):
    """The tag says manylinux_2_28 or older, and no binary inside asks for more: pip on Rocky 8
    takes the wheel only for the tag, and the loader runs it only for the symbols."""
    platforms = re.findall(r"manylinux_(\d+)_(\d+)_x86_64", wheel.name.rsplit("-", 1)[1])
    assert platforms and min((int(a), int(b)) for a, b in platforms) <= NEWEST["GLIBC"], wheel.name
    with zipfile.ZipFile(wheel) as zf:
        elves = [zf.extract(n, tmp_path) for n in zf.namelist()
                 if n.endswith("/bin/tempera") or ".so" in Path(n).name]
    assert len(elves) >= 4  # the module, the CLI, OpenImageIO's two libraries
    for elf in elves:
        symbols = subprocess.run(["objdump", "-T", elf], capture_output=True, text=True, check=True).stdout
        for name, version in re.findall(r"\b(GLIBC|GLIBCXX|CXXABI|GCC)_([0-9.]+)\b", symbols):
            assert tuple(map(int, version.split("."))) <= NEWEST[name], f"{Path(elf).name} needs {name}_{version}"


def test_import_tempera_uses_the_wheels_engine(installed):
    import tempera

    assert Path(tempera.__file__).parent == installed / "tempera"
    assert Path(tempera._native.__file__).parent == installed / "tempera_native"
    assert tempera.__version__ == tempera._native.__version__ == cmake_project_version()
    yy, xx = np.mgrid[0:24, 0:32].astype(np.float32)
    style = np.dstack([xx / 32, yy / 24, 0.5 + 0.4 * np.sin(xx / 3) * np.cos(yy / 4)]).astype(np.float32)
    image, _ = tempera.synthesize(style, [(style, style, 1.0)])
    assert image.shape == style.shape
    assert np.corrcoef(image.ravel(), style.ravel())[0, 1] > 0.9  # identity guide: the style back


def test_console_script_runs_the_native_cli(installed):
    script = installed / "bin" / "tempera"
    result = subprocess.run([str(script), "--version"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["tempera", cmake_project_version()]
    help_text = subprocess.run([str(script), "synth", "--help"], capture_output=True, text=True)
    assert help_text.returncode == 0 and "--style" in help_text.stdout
    bad = subprocess.run([str(script), "synth", "--sparkle"], capture_output=True, text=True)
    assert bad.returncode == 2


def _ldd(path):
    out = subprocess.run(["ldd", str(path)], capture_output=True, text=True, check=True).stdout
    return [line.split() for line in out.splitlines() if "=>" in line]


def test_ldd_shows_no_system_oiio_embree_or_tbb(installed):
    libs = installed / "tempera_native.libs"
    (module,) = installed.glob("tempera_native/_native*.so")
    # Embree is linked in statically (tools/wheel_deps.py): no libembree or libtbb is needed at all.
    for binary in (module, installed / "tempera_native" / "bin" / "tempera"):
        entries = _ldd(binary)
        assert not [e for e in entries if "not found" in " ".join(e)], entries
        vendored = [e for e in entries if VENDORED.match(e[0])]
        assert {VENDORED.match(e[0]).group(1) for e in vendored} >= {"OpenImageIO", "OpenImageIO_Util"}, entries
        for name, _, resolved, *_ in vendored:
            # renamed (libOpenImageIO-1a2b3c4d.so.3.2.2), and loaded from the wheel's folder
            assert re.match(r"lib[A-Za-z0-9_.-]+-[0-9a-f]{8}\.so", name), name
            assert Path(resolved).resolve().parent == libs.resolve(), (name, resolved)
        system = [e for e in entries if re.search(r"/usr/lib.*/lib(OpenImageIO|embree|tbb)", e[2])]
        assert not system, system
        assert not [e for e in entries if re.match(r"lib(embree|tbb)", e[0])], entries


def test_the_wheel_vendors_openimageio_only(wheel):
    """The lean wheel (issue 40): PyPI's OpenImageIO carries its image formats
    inside its two libraries (Debian's brought 247: GDAL, OpenVDB, FFmpeg, ...),
    and Embree is linked into the module."""
    with zipfile.ZipFile(wheel) as zf:
        libs = sorted(Path(n).name for n in zf.namelist()
                      if n.startswith("tempera_native.libs/") and not n.endswith("/"))
    stems = sorted(re.match(r"(lib[A-Za-z0-9_]+?)-[0-9a-f]{8}\.so", lib).group(1) for lib in libs)
    assert stems == ["libOpenImageIO", "libOpenImageIO_Util"], libs


@pytest.mark.parametrize("extension, tolerance", [("png", 0.5 / 255), ("tif", 0.5 / 255), ("jpg", 0.02),
                                                  ("exr", 0.0)])
def test_the_wheels_engine_writes_and_reads_the_documented_formats(installed, tmp_path, extension, tolerance):
    """PNG, TIFF, JPEG (8 bits: paintings, stylized frames) and EXR (float: guide caches) through the
    wheel's own OpenImageIO."""
    import tempera

    yy, xx = np.mgrid[0:40, 0:56].astype(np.float32)
    image = np.dstack([xx / 56, yy / 40, 0.5 + 0.25 * np.sin(xx / 5)]).astype(np.float32)
    path = tmp_path / f"image.{extension}"
    tempera.write_image(str(path), image)
    back = tempera.read_image(str(path))
    assert back.shape == image.shape
    assert np.abs(back - image).mean() <= tolerance + 1e-7, extension
