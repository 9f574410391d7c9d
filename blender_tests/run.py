"""Runs blender_tests/ with pytest inside Blender, against the installed add-on.

Debian's Blender 3.4 (a Blender executable), with the legacy add-on zip:

    blender -b --factory-startup --python-exit-code 1 --python blender_tests/run.py \\
        -- --addon-zip dist/tempera-addon-X.Y.Z.zip --junit report.xml [pytest args...]

blender.org 4.5 / 5.0 as PyPI's bpy module (a Python where `import bpy`
works, tools/setup_venvs.sh), with the extension zip:

    ~/.cache/tempera/venv-bpy50/bin/python blender_tests/run.py \\
        --extension-zip dist/tempera-X.Y.Z-linux-x64.zip --junit report.xml [pytest args...]

Installs the add-on with Blender's own installer into fresh temporary user
folders (the legacy zip into a scripts folder, the extension into the user
extension repository, as "Install from Disk" does), enables it, runs pytest
and exits with pytest's exit code ("no tests collected" counts as a failure).
Extra arguments go to pytest, e.g. `-k save` or `-x`. The tests learn what
was installed from TEMPERA_TEST_ADDON_MODULE ('tempera' or
'bl_ext.user_default.tempera') and TEMPERA_TEST_INSTALL ('legacy' or
'extension'); with the extension, TEMPERA_CLI is the CLI of its wheel.
"""
import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tools"))

import blender_env  # noqa: E402  (needs tools/ on sys.path)


def main():
    in_blender = "bpy" in sys.modules  # a Blender executable imported it before running this script
    argv = blender_env.script_args() if in_blender or "--" in sys.argv else sys.argv[1:]
    parser = argparse.ArgumentParser(prog="blender_tests/run.py")
    kind = parser.add_mutually_exclusive_group(required=True)
    kind.add_argument("--addon-zip", help="legacy add-on zip (Blender 3.x)")
    kind.add_argument("--extension-zip", help="extension zip (Blender 4.2+)")
    parser.add_argument("--junit", help="write a JUnit XML report here")
    args, pytest_args = parser.parse_known_args(argv)

    user_dir = Path(tempfile.mkdtemp(prefix="tempera-blender-user-"))
    if not in_blender:
        # blender.org's bpy module reads these when imported: fresh user
        # folders, i.e. factory settings and nothing of ~/.config/blender.
        os.environ.update(blender_env.isolated_user_env(user_dir))
    try:
        import bpy

        print(f"blender_tests: Blender {bpy.app.version_string} "
              f"({'executable' if in_blender else 'bpy module'})", flush=True)
        if args.addon_zip:
            installed = blender_env.install_addon_zip(args.addon_zip, user_dir / "scripts")
            os.environ["TEMPERA_TEST_ADDON_MODULE"] = blender_env.ADDON_MODULE
            os.environ["TEMPERA_TEST_INSTALL"] = "legacy"
        else:
            installed = blender_env.install_extension(args.extension_zip)
            os.environ["TEMPERA_TEST_EXTENSION_ZIP"] = str(Path(args.extension_zip).resolve())
            os.environ["TEMPERA_TEST_ADDON_MODULE"] = blender_env.extension_module()
            os.environ["TEMPERA_TEST_INSTALL"] = "extension"
            # The CLI that came with the extension's wheel, as its users have it: it shares the
            # module's OpenImageIO (PyPI's 3.2), where build/bin/tempera links Debian's 2.4.
            import tempera_native

            os.environ["TEMPERA_CLI"] = str(tempera_native.cli())
        # The tests check that they see this copy of the add-on.
        os.environ["TEMPERA_TEST_SCRIPTS_DIR"] = str(installed)
        import pytest

        argv = [str(HERE), "-q", "-p", "no:cacheprovider", *pytest_args]
        if args.junit:
            argv.append(f"--junitxml={args.junit}")
        code = int(pytest.main(argv))
    finally:
        shutil.rmtree(user_dir, ignore_errors=True)
    if code == pytest.ExitCode.NO_TESTS_COLLECTED:
        print("blender_tests: no tests were collected", file=sys.stderr)
    return code


if __name__ == "__main__":
    code = main()
    if "bpy" in sys.modules and not sys.modules["bpy"].app.binary_path:
        # blender.org's bpy module (4.2) can crash while the interpreter tears
        # it down, after every test has run and the report is written: leave
        # with pytest's code without that teardown.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    sys.exit(code)
