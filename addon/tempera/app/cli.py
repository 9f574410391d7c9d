"""Locating and checking the `tempera` batch command line (no bpy).

The CLI runs Tempera's solvers on files on disk without Blender, so a render
farm can split a shot by frames. The add-on preferences may name it
explicitly; otherwise it is looked up on PATH, and then in the installed
wheel (tempera_native/bin/tempera, which the extension brings along).
"""
import os
import shutil
import subprocess
from pathlib import Path


class CliError(RuntimeError):
    """The `tempera` CLI is missing, not executable or answered unexpectedly."""


def bundled_cli():
    """The wheel's CLI (tempera_native/bin/tempera) if that is installed, else None."""
    try:
        import tempera_native
    except ImportError:
        return None
    path = Path(tempera_native.cli())  # with the executable bit Blender's installer drops
    return path if path.is_file() and os.access(path, os.X_OK) else None


def find_cli(path=""):
    """Absolute path of the CLI: `path` if given (a file or a folder holding
    `tempera`, '~' expanded), else `tempera` on PATH, else the one of the
    installed wheel. Raises CliError."""
    if path:
        candidate = Path(os.path.expanduser(path))
        if candidate.is_dir():
            candidate = candidate / "tempera"
        if not candidate.is_file():
            raise CliError(f"tempera CLI not found at '{candidate}'")
        bundled_cli()  # `path` may name the wheel's own CLI, whose mode Blender's installer drops
        if not os.access(candidate, os.X_OK):
            raise CliError(f"tempera CLI at '{candidate}' is not executable")
        return candidate.resolve()
    found = shutil.which("tempera") or bundled_cli()
    if not found:
        raise CliError("tempera CLI not found on PATH; set its path in the add-on preferences")
    return Path(found).resolve()


def cli_version(path, timeout=10.0):
    """The version the CLI at `path` reports, e.g. '0.1.0'. Raises CliError."""
    try:
        result = subprocess.run([str(path), "--version"], capture_output=True, text=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise CliError(f"cannot run tempera CLI '{path}': {exc}") from exc
    words = result.stdout.split()
    if result.returncode != 0 or len(words) != 2 or words[0] != "tempera":
        raise CliError(
            f"'{path} --version' did not answer 'tempera <version>' "
            f"(exit code {result.returncode}, output {result.stdout.strip()!r})"
        )
    return words[1]
