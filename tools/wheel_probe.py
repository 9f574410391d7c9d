"""Loads the repaired wheel's engine into a host process and uses it: a
guided synthesis and an LPE trace, then reports which copies of OpenImageIO,
Embree and TBB the process has mapped (the wheel's renamed ones, and the
host's own). Used by blender_tests/test_wheel.py inside each Blender:

    blender -b --factory-startup --python tools/wheel_probe.py -- SITE_DIR        (a Blender executable)
    PYTHON tools/wheel_probe.py --import-bpy SITE_DIR                            (a bpy-module Python)
    PYTHON tools/wheel_probe.py --import-bpy-global SITE_DIR                     (as the executable has it)

--import-bpy-global loads bpy and the libraries it bundles (OpenImageIO,
Embree 4, TBB) into the global symbol scope, where the blender.org Blender
executable has them (they are its own dependencies) but the bpy module, loaded
like any extension module, does not: the wheel's libraries must work beside
them there too.

SITE_DIR is the unpacked wheel (its tempera/, tempera_native/ and
tempera_native.libs/). Prints one line 'WHEEL_PROBE {json}'; exits non-zero
with the error if anything fails.
"""
import json
import os
import math
import sys


def mapped_libraries():
    names = set()
    with open("/proc/self/maps") as maps:
        for line in maps:
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            if any(key in path for key in ("OpenImageIO", "embree", "libtbb")):
                names.add(path)
    return sorted(names)


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else argv[1:]
    if args and args[0] in ("--import-bpy", "--import-bpy-global"):
        if args[0] == "--import-bpy-global":
            sys.setdlopenflags(os.RTLD_NOW | os.RTLD_GLOBAL)
        import bpy  # noqa: F401  (the host's libraries first, as in Blender)

        sys.setdlopenflags(os.RTLD_NOW)
        args = args[1:]
    site = args[0]
    host_before = mapped_libraries()
    sys.path.insert(0, site)
    import numpy as np

    import tempera

    yy, xx = np.mgrid[0:24, 0:32].astype(np.float32)
    style = np.dstack([xx / 32, yy / 24, 0.5 + 0.4 * np.sin(xx / 3) * np.cos(yy / 4)]).astype(np.float32)
    image, _ = tempera.synthesize(style, [(style, style, 1.0)])  # identity guide: the style back
    synthesis_correlation = float(np.corrcoef(image.ravel(), style.ravel())[0, 1])

    camera = np.eye(4, dtype=np.float32)
    camera[2, 3] = 5.0
    plane = {
        "vertices": np.array([[-100, -100, 0], [100, -100, 0], [100, 100, 0], [-100, 100, 0]], np.float32),
        "triangles": np.array([[0, 1, 2], [0, 2, 3]], np.int32),
        "triangle_materials": np.zeros(2, np.int32),
        "materials": [{"base_color": [0.5] * 3, "specular": 0.0, "roughness": 1.0}],
        "lights": [{"type": "sun", "direction": [0.0, 0.0, 1.0], "irradiance": [2.0] * 3}],
        "world": {"radiance": [0.0, 0.0, 0.0]},
        "camera": {"type": "perspective", "camera_to_world": camera, "width": 16, "height": 12,
                   "tan_half_fov_x": 0.4, "tan_half_fov_y": 0.3},
    }
    (lde,), alpha = tempera.trace_lpe(plane, ["LDE"], samples=4)
    report = {
        "tempera": tempera.__file__,
        "native": tempera._native.__file__,
        "synthesis_correlation": synthesis_correlation,
        "lde_mean": float(lde.mean()),
        "lde_expected": 0.5 / math.pi * 2.0,
        "alpha_mean": float(alpha.mean()),
        "host_libraries": host_before,
        "libraries": mapped_libraries(),
    }
    print("WHEEL_PROBE " + json.dumps(report), flush=True)
    if any(lib.startswith("/usr/lib") and "libOpenImageIO" in lib for lib in host_before):
        # The host links the same OpenImageIO 2.4 as the wheel (Debian's
        # Blender 3.4, which takes the legacy add-on, not the wheel): renamed
        # sonames keep the files apart but not the C++ symbols, and the two
        # copies' exit-time destructors of OIIO's string table collide (a
        # segfault in __cxa_finalize, seen for some extraction paths). The
        # work above is what this probe checks; skip that teardown.
        os._exit(0)


if __name__ == "__main__":
    main(sys.argv)
