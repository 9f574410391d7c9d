"""Runs blender_tests/ with pytest inside Blender, against the add-on zip.

    blender -b --factory-startup --python-exit-code 1 --python blender_tests/run.py \
        -- --addon-zip dist/tempera-addon-X.Y.Z.zip --junit report.xml [pytest args...]

Installs the zip into a fresh temporary user-scripts folder with Blender's
own installer, enables it, runs pytest and exits with pytest's exit code
("no tests collected" counts as a failure). Extra arguments go to pytest,
e.g. `-k save` or `-x`.
"""
import argparse
import os
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tools"))

import blender_env  # noqa: E402  (needs tools/ on sys.path)


def main():
    parser = argparse.ArgumentParser(prog="blender_tests/run.py")
    parser.add_argument("--addon-zip", required=True)
    parser.add_argument("--junit", help="write a JUnit XML report here")
    args, pytest_args = parser.parse_known_args(blender_env.script_args())

    scripts_dir = blender_env.install_addon_zip(args.addon_zip)
    # The tests check that they see this copy of the add-on.
    os.environ["TEMPERA_TEST_SCRIPTS_DIR"] = str(scripts_dir)
    try:
        import pytest

        argv = [str(HERE), "-q", "-p", "no:cacheprovider", *pytest_args]
        if args.junit:
            argv.append(f"--junitxml={args.junit}")
        code = int(pytest.main(argv))
    finally:
        shutil.rmtree(scripts_dir, ignore_errors=True)
    if code == pytest.ExitCode.NO_TESTS_COLLECTED:
        print("blender_tests: no tests were collected", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
