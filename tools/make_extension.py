#!/usr/bin/env python3
"""Packs the Blender 4.2+ extension zip: manifest, the extension's
__init__.py, the bundled exemplar kit and the self-contained wheel.

    tools/make_extension.py --wheel dist/tempera_native-X-cp311-*.whl \
        --kit build/kit/sphere_on_table --out dist/tempera-X-linux-x64.zip

Layout (what Blender's "Install from Disk" expects of an extension):

    blender_manifest.toml   addon/tempera/blender_manifest.toml plus wheels = [...]
    __init__.py             addon/extension/__init__.py (registers tempera from the wheel)
    kit/<variant>/...       style.png, render.png, guides/ (as in the legacy zip)
    wheels/tempera_native-X-cp311-cp311-manylinux_*.whl

Refuses (exit 1, naming the problem) a manifest or wheel whose version is
not the CMakeLists.txt project version, a wheel that is not a cp311 x86-64
Linux wheel, and an incomplete kit.
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


def manifest_text(wheel_name, version):
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
    lines.insert(at + 1, f'wheels = ["./wheels/{wheel_name}"]\n')
    out = "".join(lines)
    assert tomllib.loads(out)["wheels"] == [f"./wheels/{wheel_name}"]
    return out


def check_wheel(wheel, version):
    match = re.fullmatch(r"tempera_native-([0-9.]+)-cp311-cp311-manylinux_\d+_\d+_x86_64\.whl", wheel.name)
    if not match:
        sys.exit(f"make_extension: {wheel.name} is not a repaired cp311 manylinux x86-64 tempera_native wheel "
                 "(run 'make wheel')")
    if match.group(1) != version:
        sys.exit(f"make_extension: {wheel.name} is version {match.group(1)}, CMakeLists.txt {version}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--wheel", required=True)
    parser.add_argument("--kit", action="append", default=[], metavar="DIR")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    version = cmake_version()
    wheel = Path(args.wheel)
    if not wheel.is_file():
        sys.exit(f"make_extension: wheel not found: {wheel} (run 'make wheel')")
    check_wheel(wheel, version)
    manifest = manifest_text(wheel.name, version)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".zip.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("blender_manifest.toml", manifest)
        zf.write(SHIM, "__init__.py")
        # The wheel is already compressed; storing it again saves time.
        zf.write(wheel, f"wheels/{wheel.name}", compress_type=zipfile.ZIP_STORED)
        for kit in map(Path, args.kit):
            for path in kit_files(kit):
                zf.write(path, Path("kit") / kit.name / path.relative_to(kit))
    tmp.replace(out)
    print(f"extension zip: {out} ({out.stat().st_size // (1024 * 1024)} MiB)")


if __name__ == "__main__":
    main()
