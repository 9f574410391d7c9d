"""The `tempera` batch command line, and tempera.app.cli which locates it."""
import os
import subprocess
import sys

import pytest

import tempera
from tempera.app import cli


def run(cli_path, *args):
    return subprocess.run([str(cli_path), *args], capture_output=True, text=True, timeout=30)


def test_version(cli_path):
    result = run(cli_path, "--version")
    assert result.returncode == 0, result.stderr
    assert result.stdout == f"tempera {tempera.__version__}\n"


def test_help(cli_path):
    result = run(cli_path, "--help")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("usage: tempera")
    assert "--version" in result.stdout


def test_help_lists_the_core_commands_and_those_method_folders_register(cli_path):
    """`tempera noisy` is registered by Color Me Noisy's folder (native/cli/commands.hpp);
    the moved `tempera rigid` is registered too, but not listed."""
    listed = [line.split()[0] for line in run(cli_path, "--help").stdout.split("commands:\n")[1].splitlines()
              if line.startswith("  ")]
    assert listed == ["noisy", "render-guides", "stylize", "synth"]


def test_the_moved_rigid_command_names_its_new_form(cli_path):
    result = run(cli_path, "rigid", "--cache", "c")
    assert result.returncode == 2
    assert "'tempera rigid' is now 'tempera stylize --method rigid" in result.stderr


def test_no_arguments_prints_usage_and_fails(cli_path):
    result = run(cli_path)
    assert result.returncode == 2
    assert result.stdout.startswith("usage: tempera")


def test_unknown_command_fails_naming_it(cli_path):
    result = run(cli_path, "no-such-command")
    assert result.returncode == 2
    assert "no-such-command" in result.stderr


def test_find_cli_explicit_file_and_folder(cli_path):
    assert cli.find_cli(str(cli_path)) == cli_path.resolve()
    assert cli.find_cli(str(cli_path.parent)) == cli_path.resolve()
    assert cli.cli_version(cli.find_cli(str(cli_path))) == tempera.__version__


def test_find_cli_on_path(cli_path, monkeypatch):
    monkeypatch.setenv("PATH", str(cli_path.parent))
    assert cli.find_cli() == cli_path.resolve()
    monkeypatch.setenv("PATH", "")
    with pytest.raises(cli.CliError, match="not found on PATH"):
        cli.find_cli()


def test_find_cli_falls_back_to_the_wheels_cli(cli_path, tmp_path, monkeypatch):
    """Not on PATH, but installed with the wheel (tempera_native/bin/tempera): the extension's
    case. Blender unpacks the wheel without file modes, and again whenever the extension is
    enabled: the package gives its CLI the executable bit back when it is looked up."""
    import importlib.util
    import shutil
    import types
    from pathlib import Path

    package = tmp_path / "site" / "tempera_native"
    (package / "bin").mkdir(parents=True)
    source = Path(__file__).resolve().parents[2] / "native" / "python" / "tempera_native" / "__init__.py"
    shutil.copy(source, package / "__init__.py")
    bundled = package / "bin" / "tempera"
    shutil.copy(cli_path, bundled)
    bundled.chmod(0o644)  # as Blender's installer leaves it
    spec = importlib.util.spec_from_file_location("tempera_native", package / "__init__.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.setitem(sys.modules, "tempera_native", module)
    bundled.chmod(0o644)  # unpacked again after the import (the extension enabled again)
    assert cli.find_cli() == bundled.resolve()
    assert os.stat(bundled).st_mode & 0o777 == 0o755
    bundled.chmod(0o644)
    assert cli.find_cli(str(bundled)) == bundled.resolve()  # named in the preferences
    monkeypatch.setitem(sys.modules, "tempera_native", types.SimpleNamespace(cli=lambda: tmp_path / "missing"))
    with pytest.raises(cli.CliError, match="not found on PATH"):
        cli.find_cli()


def test_find_cli_rejects_missing_and_non_executable(tmp_path):
    with pytest.raises(cli.CliError, match="not found"):
        cli.find_cli(str(tmp_path / "tempera"))
    plain = tmp_path / "tempera"
    plain.write_text("#!/bin/sh\n")
    os.chmod(plain, 0o644)
    with pytest.raises(cli.CliError, match="not executable"):
        cli.find_cli(str(plain))


def test_cli_version_rejects_other_programs(tmp_path):
    impostor = tmp_path / "tempera"
    impostor.write_text("#!/bin/sh\necho 'something else entirely'\n")
    os.chmod(impostor, 0o755)
    with pytest.raises(cli.CliError, match="did not answer"):
        cli.cli_version(impostor)
    with pytest.raises(cli.CliError, match="cannot run"):
        cli.cli_version(tmp_path / "missing")
