#!/usr/bin/env python3
"""Runs Tempera's three test levels and prints one summed closing line.

1. C++ unit tests (GoogleTest under ctest),
2. Python tests (pytest under /usr/bin/python3, importing `tempera` from addon/),
3. blender_tests (pytest inside `blender -b --factory-startup`, add-on enabled).

Counts come from JUnit XML that every level writes, so they do not depend on
parsing console text. Exits non-zero if anything failed or a level did not run.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def junit_counts(path):
    """(passed, failed, skipped) from a JUnit XML file; None if it is missing."""
    if not path.exists() or path.stat().st_size == 0:
        return None
    root = ET.parse(path).getroot()
    suites = [root] if root.tag == "testsuite" else root.iter("testsuite")
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
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--build", default="build")
    parser.add_argument("--addon-zip", required=True)
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--levels", default="cpp,python,blender")
    args = parser.parse_args()
    build = (ROOT / args.build).resolve()
    reports = Path(tempfile.mkdtemp(prefix="tempera-tests-"))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(build / "bin" / "tempera"),
               TEMPERA_BLENDER=args.blender)
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
        "blender": lambda: run_level(
            "Blender tests",
            [args.blender, "-b", "--factory-startup", "--python-exit-code", "1",
             "--python", ROOT / "blender_tests" / "run.py", "--",
             "--addon-zip", Path(args.addon_zip).resolve(), "--junit", reports / "blender.xml"],
            reports / "blender.xml", env=env),
    }
    total_passed = total_failed = total_skipped = 0
    missing = []
    for name in args.levels.split(","):
        result = levels[name]()
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
