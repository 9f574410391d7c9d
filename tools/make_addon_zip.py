#!/usr/bin/env python3
"""Packs addon/tempera (with the compiled _native module) into an installable
add-on zip for Blender 3.4 (legacy add-on) and 4.2+ (extension manifest)."""
import argparse
import sys
import zipfile
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "addon" / "tempera"


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    natives = list(PACKAGE.glob("_native*.so"))
    if not natives:
        sys.exit("make_addon_zip: addon/tempera has no compiled _native module; run 'make build' first")
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".zip.tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(PACKAGE.rglob("*")):
            if path.is_dir() or "__pycache__" in path.parts or path.suffix == ".pyc":
                continue
            zf.write(path, Path("tempera") / path.relative_to(PACKAGE))
    tmp.replace(out)
    print(f"add-on zip: {out} ({out.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
