"""Running Blender for Tempera's tests and demo, with the add-on installed
from its zip the way a user installs it.

Two halves, one module so that the tests and the demo cannot drift apart:

* outside Blender: `blender_command()` builds the background command line;
* inside Blender: `install_addon_zip()` installs the zip into a fresh
  temporary user-scripts folder and enables it, making sure that `import
  tempera` afterwards is the zipped copy, never addon/ from the source tree
  (which tools/run_tests.py puts on PYTHONPATH for the Python-level tests).

Scripts running inside Blender import this file by putting tools/ on sys.path.
"""
import os
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SOURCE_ADDON_DIR = ROOT / "addon"
ADDON_MODULE = "tempera"


def blender_command(blender, script, script_args=()):
    """Background Blender (factory settings, no user add-ons or preferences)
    running `script`; Python errors make Blender exit with code 1."""
    return [str(blender), "-b", "--factory-startup", "--python-exit-code", "1",
            "--python", str(script), "--", *(str(a) for a in script_args)]


def script_args(argv=None):
    """The arguments after '--' on Blender's command line."""
    argv = sys.argv if argv is None else argv
    return argv[argv.index("--") + 1:] if "--" in argv else []


def _is_source_addon_dir(entry):
    try:
        return Path(entry or ".").resolve() == SOURCE_ADDON_DIR
    except OSError:
        return False


def hide_source_addon():
    """Remove addon/ of the source tree from sys.path and PYTHONPATH (the latter
    for subprocesses), and forget any `tempera` imported from anywhere."""
    sys.path[:] = [p for p in sys.path if not _is_source_addon_dir(p)]
    if "PYTHONPATH" in os.environ:
        kept = [p for p in os.environ["PYTHONPATH"].split(os.pathsep) if p and not _is_source_addon_dir(p)]
        os.environ["PYTHONPATH"] = os.pathsep.join(kept)
    for name in [m for m in sys.modules if m == ADDON_MODULE or m.startswith(ADDON_MODULE + ".")]:
        del sys.modules[name]


def install_addon_zip(zip_path, scripts_dir=None):
    """Inside Blender: install the add-on zip and enable it; returns the
    user-scripts folder it went into (a new temporary one unless given).

    Uses Blender's own installer (preferences.addon_install) with the
    'Preferences' target, i.e. <scripts_dir>/addons/tempera, so nothing is
    written to the user's ~/.config/blender. Raises RuntimeError if the
    add-on does not install, does not enable, or resolves to another copy.
    """
    zip_path = Path(zip_path).resolve()
    if not zip_path.is_file():
        raise RuntimeError(f"add-on zip not found: {zip_path} (run 'make addon-zip')")
    hide_source_addon()
    created = scripts_dir is None
    scripts_dir = Path(scripts_dir or tempfile.mkdtemp(prefix="tempera-blender-scripts-")).resolve()
    try:
        _install_and_enable(zip_path, scripts_dir)
    except BaseException:
        if created:
            shutil.rmtree(scripts_dir, ignore_errors=True)
        raise
    return scripts_dir


def _install_and_enable(zip_path, scripts_dir):
    import addon_utils
    import bpy

    (scripts_dir / "addons").mkdir(parents=True, exist_ok=True)
    filepaths = bpy.context.preferences.filepaths
    if not hasattr(filepaths, "script_directory"):
        # 3.6 replaced the single folder with a list, 4.2 installs extensions
        # differently; this harness is written for Debian's Blender 3.4.
        raise RuntimeError(f"install_addon_zip supports Blender 3.4/3.5, not {bpy.app.version_string}")
    filepaths.script_directory = str(scripts_dir)
    bpy.utils.refresh_script_paths()

    result = bpy.ops.preferences.addon_install(filepath=str(zip_path), target="PREFS", overwrite=True)
    installed = scripts_dir / "addons" / ADDON_MODULE / "__init__.py"
    if result != {"FINISHED"} or not installed.is_file():
        raise RuntimeError(f"installing {zip_path} into {scripts_dir} failed ({result})")

    errors = []
    addon_utils.modules_refresh()
    module = addon_utils.enable(ADDON_MODULE, default_set=True, handle_error=errors.append)
    if module is None or errors:
        raise RuntimeError(f"enabling the '{ADDON_MODULE}' add-on failed: {errors[0] if errors else 'unknown error'}")
    if Path(module.__file__).resolve() != installed.resolve():
        raise RuntimeError(f"'{ADDON_MODULE}' was imported from {module.__file__}, not from the installed {installed}")
