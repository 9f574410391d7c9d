"""The chimney-smoke shot of the fluid demo (scenes/chimney_smoke.py) at a
bench's size: a finer smoke domain, the guide cache of the smoke alone (alpha,
fluid_velocity), no plates. LazyFluids' warm-start bench runs on it
(bench/bench_lazyfluids.py --shot, docs/benchmarks.md).

    blender -b --factory-startup --python-exit-code 1 --python bench/make_chimney_shot.py -- \\
        --out /tmp/chimney_512 [--size 512x384] [--domain 64] [--samples 4]
"""
import argparse
import sys
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
sys.path.insert(0, str(ROOT / "scenes"))
import chimney_smoke  # noqa: E402


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="bench/make_chimney_shot.py")
    parser.add_argument("--out", required=True)
    parser.add_argument("--size", default="512x384", help="WxH of the render")
    parser.add_argument("--domain", type=int, default=64, help="the smoke domain's resolution (the demo's: 40)")
    parser.add_argument("--samples", type=int, default=4, help="Cycles samples of the guides")
    args = parser.parse_args(argv)
    chimney_smoke.RESOLUTION = tuple(int(v) for v in args.size.split("x"))
    chimney_smoke.DOMAIN_RESOLUTION = args.domain
    chimney_smoke.GUIDE_SAMPLES = args.samples
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    scene = bpy.context.scene
    house, domain = chimney_smoke.build(scene, out / "cache")
    chimney_smoke.bake(scene, domain)
    chimney_smoke.render_smoke_guides(scene, house, out)
    print(f"chimney shot: {out / 'guides'}")


if __name__ == "__main__":
    main()
