"""The method registry (native/include/tempera/methods/registry.hpp): every
method named once, and every front end reading it: the native command's
--method, the `tempera` console script, the panel's Method list, the farm."""
import os
import subprocess
import sys

import pytest

from conftest import ROOT
from tempera.app import farm
from tempera.methods import registry

UNITS = {"frame", "segment", "chained frame"}


def test_every_method_once_with_what_the_front_ends_need():
    names = registry.names()
    assert len(names) == len(set(names)) and {"stylit", "tcia", "rigid", "lazyfluids", "fluidymation"} <= set(names)
    for m in registry.METHODS:
        assert m["unit"] in UNITS, m
        assert m["title"] and m["summary"] and m["paper"], m
        assert (ROOT / m["docs"]).is_file(), m["docs"]
    assert [item[0] for item in registry.panel_items()] == [n.upper() for n in names]


def _native_stylize(cli_path, *args):
    return subprocess.run([str(cli_path), "stylize", *args], capture_output=True, text=True, timeout=60)


def test_the_native_command_runs_every_method(cli_path):
    for m in registry.METHODS:
        result = _native_stylize(cli_path, "--method", m["name"], "--help")
        assert result.returncode == 0 and f"usage: tempera stylize --method {m['name']}" in result.stdout, result.stderr


def test_every_method_takes_no_video(cli_path, tmp_path):
    """A farm script passes --no-video to every method: those that write no
    video accept it too (the scene form stops at the missing Blender, after
    every option was read)."""
    blend = tmp_path / "shot.blend"
    blend.write_bytes(b"BLENDER")  # never opened
    for m in registry.METHODS:
        guides = ("--exemplar-guides", tmp_path) if m["light_path_guides"] else ()
        result = _native_stylize(cli_path, blend, "--method", m["name"], "--exemplar", tmp_path / "x.png", *guides,
                                 "--frames", "1-2", "--out", tmp_path / "o", "--no-video",
                                 "--blender", tmp_path / "no_blender")
        assert result.returncode == 1 and "cannot run" in result.stderr, (m["name"], result.stderr)


def test_an_unknown_method_is_refused_naming_every_method(cli_path):
    result = _native_stylize(cli_path, "--method", "ebsynth", "--help")
    assert result.returncode == 2 and "unknown --method 'ebsynth'" in result.stderr
    assert all(name in result.stderr for name in registry.names())
    with pytest.raises(ValueError, match="unknown --method 'ebsynth'"):
        registry.find("ebsynth")


def test_the_console_script_hands_every_method_to_the_native_command(cli_path):
    env = dict(os.environ, TEMPERA_CLI=str(cli_path))
    for m in registry.METHODS:
        result = subprocess.run([sys.executable, "-m", "tempera", "stylize", "--method", m["name"], "--help"],
                                capture_output=True, text=True, timeout=120, cwd=ROOT / "addon", env=env)
        assert result.returncode == 0 and f"usage: tempera stylize --method {m['name']}" in result.stdout, result.stderr


def test_the_farm_plans_by_the_methods_unit():
    shot = dict(frames="1-24", out="/o", exemplar="/s.png", guides="/g", exemplar_guides="/eg", chunk_size=8)
    per_frame = [t for t in farm.plan(**shot) if t.kind == "stylize"]
    assert len(per_frame) == 3
    chained = [m["name"] for m in registry.METHODS if m["unit"] == "chained frame"]
    assert chained  # lazyfluids, fluidymation: each frame made from the previous, so one task
    own_exemplar = {k: v for k, v in shot.items() if k != "exemplar_guides"}  # not guided by light paths
    for name in chained:
        tasks = [t for t in farm.plan(**own_exemplar, stylize_args=["--method", name]) if t.kind == "stylize"]
        assert len(tasks) == 1 and tasks[0].frames == list(range(1, 25))
    with pytest.raises(farm.FarmError, match="unknown --method 'ebsynth'"):
        farm.plan(**shot, stylize_args=["--method", "ebsynth"])
