#!/usr/bin/env python3
"""Stages the third-party libraries the wheel links, instead of Debian's:
PyPI's OpenImageIO and a static Embree.

    tools/wheel_deps.py [--root DIR] [--jobs N]

prints, on its last line, {"openimageio": DIR1, "embree": DIR2} as JSON
(default root ~/.cache/tempera/wheel-deps). A finished folder (its .staged
file names the release) is used as it is. `make build` and the legacy add-on
zip keep Debian's packages.

OpenImageIO

Why: Debian's libOpenImageIO links FFmpeg, GDAL, OpenVDB, poppler, DCMTK and
more, so a wheel repaired against it vendors 247 libraries (135 MiB). PyPI's
`OpenImageIO` wheel carries two libraries, libOpenImageIO and
libOpenImageIO_Util, with its image formats (OpenEXR, TIFF, PNG, JPEG, HDR,
...) linked in statically and only libz and the C/C++ runtimes outside; it is
built for manylinux_2_28. That wheel has no C++ headers, so they come from
the sdist of the same release, configured the way OpenImageIO's CMake would
(oiioversion.h), with Debian's fmt where OpenImageIO would copy its own
(header-only fmt, as the release uses; fmt's versioned inline namespace keeps
the two apart).

DIR1 holds include/ (OpenImageIO/*.h), lib/ (the two libraries and their
unversioned names for the linker), LICENSE.md and THIRD-PARTY.md; the wheel
build points CMake's OIIO_INCLUDE_DIR / OIIO_LIBRARY / OIIO_UTIL_LIBRARY at
it (tools/build_wheel.py).

Embree
Debian's Embree 3.13.5 source (the release Debian's libembree3 is built
from, fetched from Debian's archive and checked against its SHA-256), built
as a static library with only what the tracer uses: triangles, filter
functions, single rays, the SSE2, AVX and AVX2 kernels (Embree 3.13.5 builds
its 8-wide primitives only with AVX on), Embree's own tasking
(no TBB). Linked into the module with its symbols hidden
(TEMPERA_EMBREE_DIR in native/CMakeLists.txt), because blender.org's
Blender (4.2+) loads its own Embree 4, whose C API has the same names
(rtcNewDevice, ...): with Blender's libraries in the global scope, as the
Blender executable has them, a shared libembree3 beside it was bound to
Embree 4's functions, and the tracer failed ("Embree failed to create a
device") or traced black. DIR2 is an install prefix
(lib/cmake/embree-3.13.5/embree-config.cmake, include/embree3/, LICENSE.txt).
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import urllib.request
import zipfile
from pathlib import Path

OIIO_RELEASE = "3.2.2.0"  # PyPI's OpenImageIO; its libraries' ABI namespace is OpenImageIO::v3_1 / v3_2
FMT_HEADERS = Path("/usr/include/fmt")  # Debian's libfmt-dev (tools/install_deps.sh); OpenImageIO needs >= 9
EMBREE_RELEASE = "3.13.5"
EMBREE_SOURCE = "http://deb.debian.org/debian/pool/main/e/embree/embree_3.13.5+dfsg.orig.tar.xz"
EMBREE_SHA256 = "1b7c5b6144230ad81b92ece884a2017fbbb433bf5416a6fca9257e0109501c63"
# Everything the tracer (native/src/tracer/embree_scene.cpp) does not use is off.
EMBREE_OPTIONS = {
    "EMBREE_STATIC_LIB": "ON", "EMBREE_TASKING_SYSTEM": "INTERNAL", "EMBREE_ISPC_SUPPORT": "OFF",
    "EMBREE_TUTORIALS": "OFF", "EMBREE_ISA_SSE2": "ON", "EMBREE_ISA_SSE42": "OFF", "EMBREE_ISA_AVX": "ON",
    "EMBREE_ISA_AVX2": "ON", "EMBREE_ISA_AVX512": "OFF", "EMBREE_GEOMETRY_TRIANGLE": "ON",
    "EMBREE_GEOMETRY_QUAD": "OFF", "EMBREE_GEOMETRY_CURVE": "OFF", "EMBREE_GEOMETRY_SUBDIVISION": "OFF",
    "EMBREE_GEOMETRY_USER": "OFF", "EMBREE_GEOMETRY_INSTANCE": "OFF", "EMBREE_GEOMETRY_GRID": "OFF",
    "EMBREE_GEOMETRY_POINT": "OFF", "EMBREE_RAY_PACKETS": "OFF", "EMBREE_RAY_MASK": "OFF",
    "EMBREE_FILTER_FUNCTION": "ON", "CMAKE_POSITION_INDEPENDENT_CODE": "ON", "CMAKE_BUILD_TYPE": "Release",
}


def default_root():
    return Path(os.environ.get("TEMPERA_VENVS", Path.home() / ".cache" / "tempera")) / "wheel-deps"


def staged(dest, release, stage):
    """`dest` made by stage(partial_folder) unless it is already there for `release`."""
    stamp = dest / ".staged"
    if stamp.is_file() and stamp.read_text().strip() == release:
        return dest
    shutil.rmtree(dest, ignore_errors=True)
    partial = dest.with_name(dest.name + ".partial")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    stage(partial)
    (partial / ".staged").write_text(release + "\n")
    partial.rename(dest)
    return dest


def run(cmd):
    """Runs `cmd`, its output on stderr: stdout carries only the staged folders (build_wheel.py reads it)."""
    print("+ " + " ".join(map(str, cmd)), file=sys.stderr, flush=True)
    subprocess.run([str(c) for c in cmd], check=True, stdout=sys.stderr)


def pip_download(tmp, *args):
    run([sys.executable, "-m", "pip", "download", "--no-deps", "--disable-pip-version-check", "-q",
         "-d", tmp, f"OpenImageIO=={OIIO_RELEASE}", *args])


def stage_libraries(wheel, lib):
    """The two shared libraries out of PyPI's wheel, plus the linker's names."""
    lib.mkdir(parents=True)
    with zipfile.ZipFile(wheel) as zf:
        for name in zf.namelist():
            base = Path(name).name
            if re.fullmatch(r"libOpenImageIO(_Util)?\.so\.[0-9.]+", base):
                (lib / base).write_bytes(zf.read(name))
                (lib / base).chmod(0o755)
    for stem in ("libOpenImageIO", "libOpenImageIO_Util"):
        (real,) = lib.glob(f"{stem}.so.*")
        (lib / f"{stem}.so").symlink_to(real.name)


def configure_version_header(template, major, minor, patch, tweak):
    """oiioversion.h from its .in, as OpenImageIO's CMakeLists.txt fills it for a release."""
    values = {
        "PROJECT_VERSION_MAJOR": major, "PROJECT_VERSION_MINOR": minor, "PROJECT_VERSION_PATCH": patch,
        "PROJECT_VERSION_TWEAK": tweak, "PROJECT_VERSION_RELEASE_TYPE": "",
        "OIIO_USE_COMPILED_FMT_VALUE": "0", "PROJ_NAMESPACE": "OpenImageIO",
        "PROJ_VERSION_NAMESPACE": f"v{major}_{minor}", "Imath_VERSION_MAJOR": "3", "Imath_VERSION_MINOR": "1",
        "CMAKE_CXX_STANDARD": "17",
    }
    # The PyPI libraries need no libtbb: built without TBB.
    switches = {"OIIO_TBB": "0"}
    unknown = (set(re.findall(r"@([A-Za-z_]+)@", template)) - values.keys()) | (
        set(re.findall(r"^#cmakedefine01 (\w+)", template, re.M)) - switches.keys())
    if unknown:
        sys.exit(f"wheel_deps: oiioversion.h.in has placeholders this script does not fill: {sorted(unknown)}")
    text = re.sub(r"@([A-Za-z_]+)@", lambda m: values[m.group(1)], template)
    return re.sub(r"^#cmakedefine01 (\w+)", lambda m: f"#define {m.group(1)} {switches[m.group(1)]}", text, flags=re.M)


def stage_headers(sdist, dest):
    """src/include/OpenImageIO of the sdist, configured, plus fmt under detail/fmt; the licences."""
    include = dest / "include" / "OpenImageIO"
    with tarfile.open(sdist) as tf:
        root = tf.getnames()[0].split("/")[0]
        prefix = f"{root}/src/include/OpenImageIO/"
        for member in tf.getmembers():
            if member.isfile() and member.name.startswith(prefix):
                target = include / member.name[len(prefix):]
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(tf.extractfile(member).read())
        for doc in ("LICENSE.md", "THIRD-PARTY.md"):
            (dest / doc).write_bytes(tf.extractfile(f"{root}/{doc}").read())
    template = include / "oiioversion.h.in"
    major, minor, patch, tweak = OIIO_RELEASE.split(".")
    (include / "oiioversion.h").write_text(configure_version_header(template.read_text(), major, minor, patch, tweak))
    template.unlink()
    if not (FMT_HEADERS / "format.h").is_file():
        sys.exit(f"wheel_deps: no fmt headers in {FMT_HEADERS} (apt-get install libfmt-dev)")
    shutil.copytree(FMT_HEADERS, include / "detail" / "fmt")


def stage_openimageio(dest):
    with tempfile.TemporaryDirectory(prefix="tempera-wheel-deps-") as tmp:
        tmp = Path(tmp)
        # Any CPython's wheel: the libraries in it do not depend on Python.
        pip_download(tmp, "--only-binary", ":all:", "--python-version", "3.11",
                     "--platform", "manylinux_2_28_x86_64")
        pip_download(tmp, "--no-binary", ":all:")
        (wheel,) = tmp.glob("*.whl")
        (sdist,) = tmp.glob("*.tar.gz")
        stage_libraries(wheel, dest / "lib")
        stage_headers(sdist, dest)


def stage_embree(dest, jobs):
    with tempfile.TemporaryDirectory(prefix="tempera-embree-") as tmp:
        tmp = Path(tmp)
        archive = tmp / Path(EMBREE_SOURCE).name
        print(f"+ download {EMBREE_SOURCE}", file=sys.stderr, flush=True)
        with urllib.request.urlopen(EMBREE_SOURCE, timeout=120) as response:
            archive.write_bytes(response.read())
        digest = hashlib.sha256(archive.read_bytes()).hexdigest()
        if digest != EMBREE_SHA256:
            sys.exit(f"wheel_deps: {archive.name} has SHA-256 {digest}, expected {EMBREE_SHA256}")
        with tarfile.open(archive) as tf:
            tf.extractall(tmp, filter="data")
        (source,) = tmp.glob(f"embree-{EMBREE_RELEASE}*/")
        build = tmp / "build"
        defines = [f"-D{k}={v}" for k, v in EMBREE_OPTIONS.items()]
        run(["cmake", "-S", source, "-B", build, f"-DCMAKE_INSTALL_PREFIX={dest}", *defines])
        run(["cmake", "--build", build, "-j", str(jobs)])
        run(["cmake", "--install", build, "--component", "devel"])  # "lib" wants a readme.pdf the dfsg source lacks
        shutil.copy(source / "LICENSE.txt", dest / "LICENSE.txt")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=Path, default=default_root())
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    root = args.root.resolve()
    oiio = staged(root / f"openimageio-{OIIO_RELEASE}", OIIO_RELEASE, stage_openimageio)
    embree_build = f"{EMBREE_RELEASE} {json.dumps(EMBREE_OPTIONS, sort_keys=True)}"  # changed options: built again
    embree = staged(root / f"embree-{EMBREE_RELEASE}", embree_build, lambda d: stage_embree(d, args.jobs))
    print(json.dumps({"openimageio": str(oiio), "embree": str(embree)}))


if __name__ == "__main__":
    main()
