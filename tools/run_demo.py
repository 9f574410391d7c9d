#!/usr/bin/env python3
"""Runs Tempera's demo job: scenes/demo_scene.py in background Blender, with
the add-on installed from its zip (see tools/blender_env.py), then checks
that the expected files exist and prints where they are. The job builds an
animated scene and runs the add-on's Stylize Animation with the bundled
exemplar kit (StyLit's "sphere on a table" and a coloured-pencil painting).

    /usr/bin/python3 tools/run_demo.py --addon-zip dist/tempera-addon-X.Y.Z.zip \
        --blender blender --out out/demo
"""
import argparse
import subprocess
import sys
import time
from pathlib import Path

import blender_env

SCENE = blender_env.ROOT / "scenes" / "demo_scene.py"
FRAMES = 12  # scenes/demo_scene.py renders and stylizes frames 1-12 (its FRAMES)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--addon-zip", required=True)
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--out", default="out/demo")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    cmd = blender_env.blender_command(args.blender, SCENE, ["--out", out, "--addon-zip", Path(args.addon_zip).resolve()])
    print("demo:", " ".join(cmd), flush=True)
    started = time.monotonic()
    rc = subprocess.call(cmd, cwd=blender_env.ROOT)
    elapsed = time.monotonic() - started
    if rc != 0:
        print(f"demo: Blender failed (exit code {rc}) after {elapsed:.1f} s", file=sys.stderr)
        return 1

    expected = [out / "guides" / f"frame_{f:04d}.exr" for f in range(1, FRAMES + 1)]
    expected += [out / "frames" / f"frame_{f:04d}.png" for f in range(1, FRAMES + 1)]
    expected += [out / "noisy" / f"frame_{f:04d}.png" for f in range(1, FRAMES + 1)]  # the Temporal Noise variant
    expected += [out / name for name in ("contact_sheet.png", "comparison_sheet.png", "demo.blend")]
    missing = [str(p) for p in expected if not p.is_file()]
    if missing:
        print(f"demo: missing outputs: {', '.join(missing)}", file=sys.stderr)
        return 1
    print(f"\ndemo finished in {elapsed:.1f} s")
    print(f"  frames           {out / 'frames'}  ({FRAMES} stylized PNG)")
    print(f"  noisy variant    {out / 'noisy'}  ({FRAMES} PNG with Temporal Noise, f = 2.2 px)")
    print(f"  contact sheet    {out / 'contact_sheet.png'}  (the painting, then every frame)")
    print(f"  comparison sheet {out / 'comparison_sheet.png'}  (renders above stylized frames)")
    video = out / "stylized.mp4"
    print(f"  video            {video if video.is_file() else '(none: ffmpeg not found)'}")
    print(f"  blend file       {out / 'demo.blend'}  (open it: scene 'Demo Tempera' plays the result)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
