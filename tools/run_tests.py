#!/usr/bin/env python3
"""Runs Tempera's test levels and prints one summed closing line.

    cpp        C++ unit tests (GoogleTest under ctest)
    python     Python tests (pytest under /usr/bin/python3, importing `tempera` from addon/)
    blender    blender_tests in Debian's Blender 3.4 (`blender -b`), legacy add-on zip
    blender42  blender_tests in blender.org 4.2 LTS (PyPI bpy), the extension's minimum version
    blender45  blender_tests in blender.org 4.5 LTS (PyPI bpy), extension zip installed as a user does
    blender50  blender_tests in blender.org 5.0 (PyPI bpy), extension zip
    blender52  blender_tests in blender.org 5.2 LTS (PyPI bpy on CPython 3.13), extension zip's cp313 wheel
    blender53  blender_tests in blender.org 5.3 (PyPI bpy on CPython 3.13), extension zip's cp313 wheel
    wheel      tests/wheel: pip install of the repaired wheel, ldd, the Dask farm (venv-tools)
    wheel313   tests/wheel with the cp313 wheel on CPython 3.13 (venv-tools313): farm nodes on 3.13
    flamenco   farm/flamenco tests under Node (node --test)

Counts come from JUnit XML that every level writes, so they do not depend on
parsing console text. Exits non-zero if anything failed or a level did not run.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def junit_counts(path):
    """(passed, failed, skipped) from a JUnit XML file; None if it is missing."""
    if not path.exists() or path.stat().st_size == 0:
        return None
    root = ET.parse(path).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    if not any(suite.get("tests") is not None for suite in suites):
        # Node's reporter: bare test cases, outcome in child elements.
        cases = list(root.iter("testcase"))
        failed = sum(1 for c in cases if c.find("failure") is not None or c.find("error") is not None)
        skipped = sum(1 for c in cases if c.find("skipped") is not None)
        return len(cases) - failed - skipped, failed, skipped
    tests = failed = skipped = 0
    for suite in suites:
        tests += int(suite.get("tests", 0))
        failed += int(suite.get("failures", 0)) + int(suite.get("errors", 0))
        skipped += int(suite.get("skipped", 0)) + int(suite.get("disabled", 0))
    return tests - failed - skipped, failed, skipped


def run_level(name, cmd, junit, env=None, cwd=ROOT):
    print(f"\n=== {name}: {' '.join(str(c) for c in cmd)}", flush=True)
    rc = subprocess.call([str(c) for c in cmd], env=env, cwd=cwd)
    counts = junit_counts(junit)
    if counts is None:
        print(f"=== {name}: did not run (no report; exit code {rc})", flush=True)
        return None
    passed, failed, skipped = counts
    if rc != 0 and failed == 0:
        failed = 1  # crashed after writing a report, or a collection error
    print(f"=== {name}: {passed} passed, {failed} failed, {skipped} skipped", flush=True)
    return passed, failed, skipped


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--addon-zip", help="legacy add-on zip (level blender)")
    parser.add_argument("--extension-zip", help="extension zip (levels blender45, blender50)")
    parser.add_argument("--wheel", help="repaired cp311 wheel (levels blender*, wheel)")
    parser.add_argument("--wheel313", help="repaired cp313 wheel (levels blender52, blender53, wheel313)")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--bpy42", help="Python with PyPI bpy 4.2 (tools/setup_venvs.sh)")
    parser.add_argument("--bpy45", help="Python with PyPI bpy 4.5")
    parser.add_argument("--bpy50", help="Python with PyPI bpy 5.0")
    parser.add_argument("--bpy52", help="CPython 3.13 with PyPI bpy 5.2 LTS")
    parser.add_argument("--bpy53", help="CPython 3.13 with PyPI bpy 5.3")
    parser.add_argument("--tools-python", help="Python with dask and pytest (venv-tools)")
    parser.add_argument("--tools-python313", help="CPython 3.13 with dask and pytest (venv-tools313)")
    parser.add_argument("--levels", default="cpp,python,blender,blender42,blender45,blender50,blender52,blender53,"
                                            "wheel,wheel313,flamenco")
    args = parser.parse_args()
    build = (ROOT / args.build).resolve()
    reports = Path(tempfile.mkdtemp(prefix="tempera-tests-"))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(build / "bin" / "tempera"),
               TEMPERA_BLENDER=args.blender)
    if args.wheel:
        env["TEMPERA_TEST_WHEEL"] = str(Path(args.wheel).resolve())

    def needs(*names):
        missing = [n for n in names if not getattr(args, n.replace("-", "_"))]
        if missing:
            print(f"=== missing {', '.join('--' + n for n in missing)}", flush=True)
        return not missing

    def blender_level(name, python, version, wheel="wheel"):
        if not needs("extension-zip", version, wheel):
            return None
        if not Path(python).exists():
            print(f"=== {name}: {python} does not exist (tools/setup_venvs.sh makes it; a CPython 3.13 for 5.1+, "
                  "see README.md)", flush=True)
            return None
        level_env = dict(env, TEMPERA_TEST_WHEEL=str(Path(getattr(args, wheel)).resolve()))
        return run_level(
            f"Blender tests ({name}, extension)",
            [python, ROOT / "blender_tests" / "run.py", "--extension-zip", Path(args.extension_zip).resolve(),
             "--junit", reports / f"{version}.xml"],
            reports / f"{version}.xml", env=level_env)

    def wheel_level(tag, python, wheel, name):
        if not python or not wheel or not Path(python).exists():
            print(f"=== {name}: no {tag} wheel or no Python to install it into ({python}; tools/setup_venvs.sh, "
                  "a CPython 3.13 for cp313, see README.md)", flush=True)
            return None
        return run_level(
            f"Wheel and Dask farm tests ({tag})",
            [python, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/wheel", f"--junitxml={reports / name}.xml"],
            reports / f"{name}.xml", env=dict(env, PYTHONPATH="", TEMPERA_TEST_WHEEL=str(Path(wheel).resolve())))

    levels = {
        "cpp": lambda: run_level(
            "C++ unit tests",
            ["ctest", "--test-dir", build, "--output-on-failure", "--output-junit", reports / "cpp.xml"],
            reports / "cpp.xml"),
        "python": lambda: run_level(
            "Python tests",
            ["/usr/bin/python3", "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests/python",
             f"--junitxml={reports / 'python.xml'}"],
            reports / "python.xml", env=env),
        "blender": lambda: needs("addon-zip") and run_level(
            "Blender tests (Debian 3.4, legacy add-on)",
            [args.blender, "-b", "--factory-startup", "--python-exit-code", "1",
             "--python", ROOT / "blender_tests" / "run.py", "--",
             "--addon-zip", Path(args.addon_zip).resolve(), "--junit", reports / "blender.xml"],
            reports / "blender.xml", env=env) or None,
        "blender42": lambda: blender_level("blender.org 4.2", args.bpy42, "bpy42"),
        "blender45": lambda: blender_level("blender.org 4.5", args.bpy45, "bpy45"),
        "blender50": lambda: blender_level("blender.org 5.0", args.bpy50, "bpy50"),
        "blender52": lambda: blender_level("blender.org 5.2 LTS", args.bpy52, "bpy52", "wheel313"),
        "blender53": lambda: blender_level("blender.org 5.3", args.bpy53, "bpy53", "wheel313"),
        "wheel": lambda: wheel_level("cp311", args.tools_python, args.wheel, "wheel"),
        "wheel313": lambda: wheel_level("cp313", args.tools_python313, args.wheel313, "wheel313"),
        "flamenco": lambda: run_level(
            "Flamenco job type tests (Node)",
            ["node", "--test", "--test-reporter=spec", "--test-reporter-destination=stdout",
             "--test-reporter=junit", f"--test-reporter-destination={reports / 'flamenco.xml'}",
             ROOT / "farm" / "flamenco" / "tempera.test.js"],
            reports / "flamenco.xml"),
    }
    total_passed = total_failed = total_skipped = 0
    missing = []
    for name in args.levels.split(","):
        if name not in levels:
            parser.error(f"unknown level {name!r}; levels: {', '.join(levels)}")
        started = time.monotonic()
        result = levels[name]()
        print(f"=== {name}: {time.monotonic() - started:.0f} s", flush=True)
        if result is None:
            missing.append(name)
            continue
        total_passed += result[0]
        total_failed += result[1]
        total_skipped += result[2]
    if missing:
        print(f"levels that did not run: {', '.join(missing)}")
    print(f"{total_passed} passed, {total_failed} failed, {total_skipped} skipped")
    return 1 if (total_failed or missing) else 0


if __name__ == "__main__":
    sys.exit(main())
