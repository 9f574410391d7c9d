"""Running Blender for Tempera's tests and demo, with the add-on installed
from its zip the way a user installs it.

Two halves, one module so that the tests and the demo cannot drift apart:

* outside Blender: `blender_command()` builds the background command line,
  for a Blender executable (Debian's 3.4) or for a Python that has blender.org's
  `bpy` module (PyPI bpy 4.5 / 5.0, see tools/setup_venvs.sh);
  `isolated_user_env()` the environment that keeps a bpy-module Blender away
  from ~/.config/blender;
* inside Blender: `install_addon_zip()` installs the legacy zip into a fresh
  temporary user-scripts folder and enables it; `install_extension()`
  installs the extension zip (4.2+) into the user extension repository the
  way "Install from Disk" does. Both make sure that `import tempera`
  afterwards is the installed copy, never addon/ from the source tree (which
  tools/run_tests.py puts on PYTHONPATH for the Python-level tests).

Scripts running inside Blender import this file by putting tools/ on sys.path.
This harness is outside the add-on, so it tells Blender versions apart here;
the add-on itself does that only in tempera.blender.compat.
"""
import os
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SOURCE_ADDON_DIR = ROOT / "addon"
ADDON_MODULE = "tempera"


EXTENSION_REPO = "user_default"


def is_bpy_python(blender):
    """True if `blender` is a Python interpreter (one with the bpy module),
    not a Blender executable."""
    return Path(str(blender)).name.startswith("python")


def blender_command(blender, script, script_args=()):
    """Background Blender (factory settings, no user add-ons or preferences)
    running `script`; Python errors make Blender exit with code 1. With a
    bpy-module Python, the script itself imports bpy (use it with
    isolated_user_env())."""
    if is_bpy_python(blender):
        return [str(blender), str(script), "--", *(str(a) for a in script_args)]
    return [str(blender), "-b", "--factory-startup", "--python-exit-code", "1",
            "--python", str(script), "--", *(str(a) for a in script_args)]


def isolated_user_env(base, env=None):
    """Environment for a bpy-module Blender whose user config, scripts and
    extensions live under `base` (a fresh folder): factory settings, and
    nothing read from or written to ~/.config/blender."""
    env = dict(os.environ if env is None else env)
    for name, sub in (("BLENDER_USER_CONFIG", "config"), ("BLENDER_USER_SCRIPTS", "scripts"),
                      ("BLENDER_USER_EXTENSIONS", "extensions"), ("BLENDER_USER_DATAFILES", "datafiles")):
        env[name] = str(Path(base) / sub)
    return env


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
    if hasattr(filepaths, "script_directory"):  # 3.4, 3.5: one folder
        filepaths.script_directory = str(scripts_dir)
        target = "PREFS"
    else:  # 3.6+: a list of named folders, the install target is the name
        entry = filepaths.script_directories.new()
        entry.name, entry.directory = "tempera-tests", str(scripts_dir)
        target = entry.name
    bpy.utils.refresh_script_paths()

    result = bpy.ops.preferences.addon_install(filepath=str(zip_path), target=target, overwrite=True)
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


def extension_module(extension_id=ADDON_MODULE, repo=EXTENSION_REPO):
    """The module name Blender 4.2+ gives an installed extension."""
    return f"bl_ext.{repo}.{extension_id}"


def install_extension(zip_path, repo=EXTENSION_REPO):
    """Inside Blender 4.2+: install the extension zip into the user repository
    `repo` and enable it, as Edit > Preferences > Get Extensions > Install from
    Disk does; returns the extension's folder. Raises RuntimeError if it does
    not install or enable, or if `import tempera` is not the copy that came
    with the extension's wheel."""
    import addon_utils
    import bpy

    zip_path = Path(zip_path).resolve()
    if not zip_path.is_file():
        raise RuntimeError(f"extension zip not found: {zip_path} (run 'make extension')")
    if bpy.app.version < (4, 2, 0):
        raise RuntimeError(f"extensions need Blender 4.2+, this is {bpy.app.version_string}")
    hide_source_addon()
    result = bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo=repo, enable_on_install=True)
    module_name = extension_module(repo=repo)
    if result != {"FINISHED"} or addon_utils.check(module_name) != (True, True):
        raise RuntimeError(f"installing the extension {zip_path} failed ({result}, "
                           f"{module_name} loaded/enabled: {addon_utils.check(module_name)})")
    repo_dir = Path(bpy.utils.user_resource("EXTENSIONS", path=repo))
    import tempera

    site = Path(bpy.utils.user_resource("EXTENSIONS", path=".local")).resolve()
    if site not in Path(tempera.__file__).resolve().parents:
        raise RuntimeError(f"'import tempera' gave {tempera.__file__}, not the extension's wheel under {site}")
    return repo_dir / ADDON_MODULE
