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
KEY_FRAMES = (2, 11)  # its painted keys of the coherent run (its KEY_FRAMES)


def check_coherent(out):
    """What is wrong with the coherent run's frames, or None: each key frame
    must come out as painted (within 1/255)."""
    sys.path.insert(0, str(blender_env.ROOT / "addon"))
    import numpy as np
    import tempera

    for f in KEY_FRAMES:
        key = tempera.read_image(str(out / "keys" / f"key_{f:04d}.png"))[:, :, :3]
        got = tempera.read_image(str(out / "coherent" / "frames" / f"frame_{f:04d}.png"))[:, :, :3]
        if got.shape != key.shape or np.abs(got - key).max() > 1 / 255 + 1e-6:
            return f"coherent frame {f} is not its painted key"
    return None


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
    # The coherent method (Bénard 2013) with two painted keys (scenes/demo_scene.py KEY_FRAMES).
    expected += [out / "keys" / f"key_{f:04d}.png" for f in KEY_FRAMES]
    expected += [out / "coherent" / "frames" / f"frame_{f:04d}.png" for f in range(1, FRAMES + 1)]
    expected += [out / "coherent" / "contact_sheet.png"]
    # Temporal Noise as the method: the render boiled (scenes/demo_scene.py NOISY_RENDER).
    expected += [out / "noisy_render" / "noisy" / "frames" / f"frame_{f:04d}.png" for f in range(1, FRAMES + 1)]
    missing = [str(p) for p in expected if not p.is_file()]
    if missing:
        print(f"demo: missing outputs: {', '.join(missing)}", file=sys.stderr)
        return 1
    problem = check_coherent(out)
    if problem:
        print(f"demo: {problem}", file=sys.stderr)
        return 1
    print(f"\ndemo finished in {elapsed:.1f} s")
    print(f"  frames           {out / 'frames'}  ({FRAMES} stylized PNG)")
    print(f"  noisy variant    {out / 'noisy'}  ({FRAMES} PNG with Temporal Noise, f = 2.2 px)")
    print(f"  render boiled    {out / 'noisy_render' / 'noisy' / 'frames'}  (Temporal Noise as the method)")
    print(f"  contact sheet    {out / 'contact_sheet.png'}  (the painting, then every frame)")
    print(f"  comparison sheet {out / 'comparison_sheet.png'}  (renders above stylized frames)")
    video = out / "stylized.mp4"
    print(f"  video            {video if video.is_file() else '(none: ffmpeg not found)'}")
    print(f"  blend file       {out / 'demo.blend'}  (open it: scene 'Demo Tempera' plays the result)")
    print(f"  coherent         {out / 'coherent'}  (Bénard 2013 with the keys in {out / 'keys'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
