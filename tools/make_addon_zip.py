#!/usr/bin/env python3
"""Packs addon/tempera (with the compiled _native module) into the legacy
add-on zip for Blender 3.x (Debian's 3.4: the module links Debian's shared
libraries). Blender 4.2+ gets the extension zip (tools/make_extension.py);
the manifest stays out of this zip, so 4.2+ does not take it for one.

With --kit DIR (a folder written by scenes/exemplar_kit.py), the kit's
painting, render and guide cache go into the zip as tempera/kit/<variant>/,
the add-on's bundled exemplar (tempera.app.exemplar_kit)."""
import argparse
import sys
import zipfile
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "addon" / "tempera"


def kit_files(kit):
    """What the add-on needs of a kit folder; exits naming what is missing."""
    files = [kit / "style.png", kit / "render.png", kit / "guides" / "manifest.json"]
    files += sorted((kit / "guides").glob("frame_*.exr"))
    missing = [str(f) for f in files[:3] if not f.is_file()]
    if missing or len(files) == 3:
        sys.exit(f"make_addon_zip: kit {kit} is incomplete (missing {missing or 'guides/frame_*.exr'}); "
                 "run scenes/exemplar_kit.py")
    return files


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", required=True)
    parser.add_argument("--kit", action="append", default=[], metavar="DIR",
                        help="exemplar kit folder to bundle (repeatable; the variant is its folder name)")
    args = parser.parse_args()
    natives = list(PACKAGE.glob("_native*.so"))
    if not natives:
        sys.exit("make_addon_zip: addon/tempera has no compiled _native module; run 'make build' first")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".zip.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(PACKAGE.rglob("*")):
            if path.is_dir() or "__pycache__" in path.parts or path.suffix == ".pyc" \
                    or path.name == "blender_manifest.toml":
                continue
            zf.write(path, Path("tempera") / path.relative_to(PACKAGE))
        for kit in map(Path, args.kit):
            for path in kit_files(kit):
                zf.write(path, Path("tempera") / "kit" / kit.name / path.relative_to(kit))
    tmp.replace(out)
    print(f"add-on zip: {out} ({out.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
