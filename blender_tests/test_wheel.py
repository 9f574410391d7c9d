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


# "global": the bpy module's libraries in the global symbol scope, as the Blender executable has
# its own (tools/wheel_probe.py); Debian's 3.4 is an executable already.
SCOPES = ["local", "global"] if not bpy.app.binary_path else ["executable"]


@pytest.fixture(scope="module", params=SCOPES)
def probe(tmp_path_factory, request):
    if not WHEEL:
        pytest.fail("TEMPERA_TEST_WHEEL is not set (tools/run_tests.py sets it; run 'make wheel')")
    site = tmp_path_factory.mktemp("wheel")
    with zipfile.ZipFile(WHEEL) as zf:
        zf.extractall(site)
    (site / "tempera_native" / "bin" / "tempera").chmod(0o755)
    script = ROOT / "tools" / "wheel_probe.py"
    if not bpy.app.binary_path:  # blender.org's bpy module (no executable)
        flag = "--import-bpy-global" if request.param == "global" else "--import-bpy"
        command = [sys.executable, str(script), flag, str(site)]
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
    for name in ("libOpenImageIO-", "libOpenImageIO_Util-"):
        assert any(Path(p).name.startswith(name) for p in mine), (name, probe["libraries"])
    # Embree is inside the module (static, hidden); the wheel brings no Embree or TBB of its own.
    assert not [p for p in mine if "embree" in Path(p).name or "libtbb" in Path(p).name], mine
    # Blender's own Embree 4 and OpenImageIO stay loaded beside the wheel's.
    if bpy.app.version >= (4, 2, 0):
        host = {Path(p).name.split(".so")[0] for p in probe["host_libraries"]}
        assert {"libembree4", "libOpenImageIO"} <= host, probe["host_libraries"]
