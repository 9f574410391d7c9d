"""Turn a photo or scan of a painted exemplar template into a style exemplar.

    /usr/bin/python3 -m tempera.methods.stylit.register_painting PHOTO --kit KIT_DIR --out STYLE.png

KIT_DIR is the folder scenes/exemplar_kit.py wrote (kit.json, guides.exr,
template.pdf, ...). The photo is aligned to the template by its four corner
marks (tempera.methods.stylit.registration) and the picture is written at the guide
resolution, ready to be the `style` of tempera.synthesize with the kit's
guides.exr as the exemplar guides.
"""
import argparse
import sys
from pathlib import Path

import tempera

from .painting_template import read_kit_json
from .registration import register_painting


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tempera.methods.stylit.register_painting",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("photo", help="photo or scan of the painted template (PNG, JPEG, TIFF, ...)")
    parser.add_argument("--kit", required=True, help="the exemplar kit folder (holds kit.json)")
    parser.add_argument("--out", required=True, help="style exemplar image to write, e.g. style.png")
    parser.add_argument("--no-flatten", action="store_true",
                        help="keep the photo's lighting and paper colour (default: even them out, paper white)")
    args = parser.parse_args(argv)

    kit_json = Path(args.kit) / "kit.json"
    if not kit_json.is_file():
        sys.exit(f"register_painting: {kit_json} not found; --kit must be the folder scenes/exemplar_kit.py wrote")
    try:
        photo = tempera.read_image(args.photo)
    except (OSError, ValueError, RuntimeError) as exc:
        sys.exit(f"register_painting: cannot read the photo {args.photo}: {exc}")
    try:
        style = register_painting(photo, read_kit_json(kit_json), flatten=not args.no_flatten)
    except ValueError as exc:
        sys.exit(f"register_painting: {args.photo}: {exc}")
    tempera.write_image(args.out, style)
    print(f"{args.out}: {style.shape[1]} x {style.shape[0]} style exemplar")


if __name__ == "__main__":
    main()
