#!/usr/bin/env python3
"""Packs the Blender 4.2+ extension zip: manifest, the extension's
__init__.py, the bundled exemplar kit and the self-contained wheels, one per
CPython that Blender bundles.

    tools/make_extension.py --wheel dist/tempera_native-X-cp311-*.whl \
        --wheel dist/tempera_native-X-cp313-*.whl \
        --kit build/kit/sphere_on_table --out dist/tempera-X-linux-x64.zip

Layout (what Blender's "Install from Disk" expects of an extension):

    blender_manifest.toml   addon/tempera/blender_manifest.toml plus wheels = [...]
    __init__.py             addon/extension/__init__.py (registers tempera from the wheel)
    kit/<variant>/...       style.png, render.png, guides/ (as in the legacy zip)
    wheels/tempera_native-X-cp311-cp311-manylinux_*.whl   Blender 4.2-5.0 (CPython 3.11)
    wheels/tempera_native-X-cp313-cp313-manylinux_*.whl   Blender 5.1+ (CPython 3.13)

Blender installs only the wheel whose tag matches its own Python (and since
5.1 refuses an extension none of whose wheels matches). Refuses (exit 1,
naming the problem) a manifest or wheel whose version is not the
CMakeLists.txt project version, a wheel that is not a repaired cp311 or
cp313 x86-64 Linux wheel, two wheels for one CPython, and an incomplete kit.
"""
import argparse
import re
import sys
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "addon" / "tempera" / "blender_manifest.toml"
SHIM = ROOT / "addon" / "extension" / "__init__.py"
sys.path.insert(0, str(Path(__file__).resolve().parent))

from make_addon_zip import kit_files  # noqa: E402


def cmake_version():
    match = re.search(r"^project\(tempera VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text(), re.MULTILINE)
    if not match:
        sys.exit("make_extension: no 'project(tempera VERSION x.y.z' in CMakeLists.txt")
    return match.group(1)


# The CPythons of the Blenders the extension serves: 3.11 (4.2-5.0) and 3.13 (5.1+).
PYTHON_TAGS = ("cp311", "cp313")


def manifest_text(wheel_names, version):
    """The source manifest with `wheels = [...]` added after `platforms`."""
    text = MANIFEST.read_text()
    data = tomllib.loads(text)
    if data.get("version") != version:
        sys.exit(f"make_extension: {MANIFEST} has version {data.get('version')!r}, "
                 f"CMakeLists.txt {version!r}")
    if "wheels" in data:
        sys.exit(f"make_extension: {MANIFEST} must not list wheels; the packer adds them")
    lines = text.splitlines(keepends=True)
    at = next((i for i, line in enumerate(lines) if line.startswith("platforms")), None)
    if at is None:
        sys.exit(f"make_extension: {MANIFEST} has no platforms line")
    paths = [f"./wheels/{name}" for name in wheel_names]
    lines.insert(at + 1, "wheels = [" + ", ".join(f'"{path}"' for path in paths) + "]\n")
    out = "".join(lines)
    assert tomllib.loads(out)["wheels"] == paths
    return out


def check_wheel(wheel, version):
    """The wheel's CPython tag (cp311, cp313); exits naming the problem."""
    tags = "|".join(PYTHON_TAGS)
    match = re.fullmatch(rf"tempera_native-([0-9.]+)-({tags})-\2-manylinux_\d+_\d+_x86_64\.whl", wheel.name)
    if not match:
        sys.exit(f"make_extension: {wheel.name} is not a repaired {' or '.join(PYTHON_TAGS)} manylinux x86-64 "
                 "tempera_native wheel (run 'make wheel')")
    if match.group(1) != version:
        sys.exit(f"make_extension: {wheel.name} is version {match.group(1)}, CMakeLists.txt {version}")
    return match.group(2)


def check_wheels(wheels, version):
    seen = {}
    for wheel in wheels:
        if not wheel.is_file():
            sys.exit(f"make_extension: wheel not found: {wheel} (run 'make wheel')")
        tag = check_wheel(wheel, version)
        if tag in seen:
            sys.exit(f"make_extension: two {tag} wheels: {seen[tag].name} and {wheel.name}")
        seen[tag] = wheel


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--wheel", action="append", required=True, help="a repaired wheel; once per CPython")
    parser.add_argument("--kit", action="append", default=[], metavar="DIR")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    version = cmake_version()
    wheels = [Path(w) for w in args.wheel]
    check_wheels(wheels, version)
    manifest = manifest_text([w.name for w in wheels], version)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".zip.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("blender_manifest.toml", manifest)
        zf.write(SHIM, "__init__.py")
        for wheel in wheels:  # already compressed; storing them again saves time
            zf.write(wheel, f"wheels/{wheel.name}", compress_type=zipfile.ZIP_STORED)
        for kit in map(Path, args.kit):
            for path in kit_files(kit):
                zf.write(path, Path("kit") / kit.name / path.relative_to(kit))
    tmp.replace(out)
    print(f"extension zip: {out} ({out.stat().st_size // (1024 * 1024)} MiB)")


if __name__ == "__main__":
    main()
