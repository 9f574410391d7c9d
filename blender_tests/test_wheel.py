"""The self-contained wheel inside this Blender, next to Blender's own
libraries: a synthesis and an LPE trace with its engine (tools/wheel_probe.py
in a fresh process of the same Blender, so that the add-on's own copy of the
engine does not interfere), and the libraries that process maps."""
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import bpy
import pytest

ROOT = Path(__file__).resolve().parent.parent
WHEEL = os.environ.get("TEMPERA_TEST_WHEEL")


@pytest.fixture(scope="module")
def probe(tmp_path_factory):
    if not WHEEL:
        pytest.fail("TEMPERA_TEST_WHEEL is not set (tools/run_tests.py sets it; run 'make wheel')")
    site = tmp_path_factory.mktemp("wheel")
    with zipfile.ZipFile(WHEEL) as zf:
        zf.extractall(site)
    (site / "tempera_native" / "bin" / "tempera").chmod(0o755)
    script = ROOT / "tools" / "wheel_probe.py"
    if not bpy.app.binary_path:  # blender.org's bpy module (no executable)
        command = [sys.executable, str(script), "--import-bpy", str(site)]
    else:  # a Blender executable (Debian's 3.4)
        command = [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                   "--python", str(script), "--", str(site)]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
    lines = [line for line in result.stdout.splitlines() if line.startswith("WHEEL_PROBE ")]
    assert result.returncode == 0 and lines, result.stdout[-2000:] + result.stderr[-2000:]
    report = json.loads(lines[-1][len("WHEEL_PROBE "):])
    report["site"] = str(site)
    return report


def test_the_wheels_engine_synthesizes_and_traces(probe):
    site = Path(probe["site"])
    assert Path(probe["tempera"]).parent == site / "tempera"
    assert Path(probe["native"]).parent == site / "tempera_native"
    assert probe["synthesis_correlation"] > 0.9  # identity guide: the style back
    assert abs(probe["lde_mean"] - probe["lde_expected"]) < 1e-3 * probe["lde_expected"]
    assert probe["alpha_mean"] == 1.0


def test_the_wheels_libraries_are_loaded_beside_blenders(probe):
    libs = Path(probe["site"]) / "tempera_native.libs"
    mine = [p for p in probe["libraries"] if Path(p).parent == libs]
    for name in ("libOpenImageIO-", "libembree3-", "libtbb-"):
        assert any(Path(p).name.startswith(name) for p in mine), (name, probe["libraries"])
    # Blender's own TBB (5.0 bundles libtbb.so.12, the very file name of Debian's) stays loaded too.
    host_tbb = [p for p in probe["host_libraries"] if Path(p).name.startswith("libtbb.so")]
    if bpy.app.version >= (4, 2, 0):
        assert host_tbb, probe["host_libraries"]
    assert not [p for p in host_tbb if Path(p).parent == libs]
