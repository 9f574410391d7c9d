#!/usr/bin/env python3
"""Checks that a change leaves the demo's frames bit-identical: the guard of
every refactoring step (issue 41). Before the change, keep a reference:

    make demo DEMO_OUT=REF/demo DEMO_RIGID_OUT=REF/rigid DEMO_FLUIDS_OUT=REF/fluids

then, with the change built (make build addon-zip):

    /usr/bin/python3 tools/demo_guard.py --reference REF --out NEW

Two runs of `make demo` never match byte for byte, with or without a change:
Blender's Cycles renders the guide passes a little differently each time
(up to 4e-6, in about 1% of the values, measured with Blender 3.4 on
2026-12-04), and the synthesis carries any difference into the frames. So
the guard reruns only what Tempera computes, from the reference's renders:

- the demo (tools/run_demo.py, the add-on's operators in background Blender)
  with the reference's guide cache copied in: the cache is current, so
  nothing is rendered again; per-frame StyLit, the noise pass and the
  coherent run (its keys are painted from the same guides) run as in the demo;
- the fluid demos' stylization (make demo-fluids-stylize) on the reference's
  guides, exemplars and plates;
- the rigid-body demo whole (Blender's rigid bodies are deterministic).

Every PNG and EXR of the rerun is then compared pixel for pixel, every
channel, with the reference's. Exits 1 if one differs or is missing.
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "addon"))
IMAGES = (".png", ".exr")


def run(cmd, **kwargs):
    print("demo_guard: " + " ".join(map(str, cmd)), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, cwd=ROOT, **kwargs)


def rerun(reference, out, blender, addon_zip):
    (out / "demo").mkdir(parents=True)
    shutil.copytree(reference / "demo" / "guides", out / "demo" / "guides")
    run([sys.executable, ROOT / "tools" / "run_demo.py", "--addon-zip", addon_zip, "--blender", blender,
         "--out", out / "demo"])
    run(["make", "-s", "demo-fluids-stylize", f"DEMO_FLUIDS_IN={reference / 'fluids'}",
         f"DEMO_FLUIDS_OUT={out / 'fluids'}", f"BLENDER={blender}"])
    run(["make", "-s", "demo-rigid", f"DEMO_RIGID_OUT={out / 'rigid'}", f"BLENDER={blender}"])


def compare(reference, out):
    """(compared, problems): every image the rerun wrote against the reference's."""
    import numpy as np
    import tempera

    problems, compared = [], 0
    for new in sorted(p for p in out.rglob("*") if p.suffix in IMAGES):
        name = new.relative_to(out)
        old = reference / name
        if not old.is_file():
            problems.append(f"{name}: not in the reference")
            continue
        a, b = tempera.read_image(str(old)), tempera.read_image(str(new))
        compared += 1
        if a.shape != b.shape:
            problems.append(f"{name}: shape {b.shape}, reference {a.shape}")
        elif not np.array_equal(a, b):
            problems.append(f"{name}: {np.mean(a != b):.2%} of values differ, at most by {np.abs(a - b).max():.3g}")
    return compared, problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reference", required=True, help="folder with demo/, rigid/, fluids/ of a make demo")
    parser.add_argument("--out", required=True, help="new, empty folder for the rerun")
    parser.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    parser.add_argument("--addon-zip", help="default: dist/tempera-addon-VERSION.zip (make addon-zip)")
    args = parser.parse_args()
    reference, out = Path(args.reference).resolve(), Path(args.out).resolve()
    for part in ("demo/guides", "fluids/chimney/guides", "fluids/ink/guides", "rigid"):
        if not (reference / part).is_dir():
            sys.exit(f"demo_guard: {reference / part} is missing: make the reference with the command in --help")
    if out.exists() and any(out.iterdir()):
        sys.exit(f"demo_guard: {out} is not empty")
    if not args.addon_zip:
        import tempera

        args.addon_zip = ROOT / "dist" / f"tempera-addon-{tempera.__version__}.zip"
    rerun(reference, out, args.blender, Path(args.addon_zip).resolve())
    compared, problems = compare(reference, out)
    for problem in problems:
        print("demo_guard: DIFFERS " + problem)
    print(f"demo_guard: {compared} images compared, {len(problems)} differ or are missing")
    return 1 if problems or not compared else 0


if __name__ == "__main__":
    sys.exit(main())
