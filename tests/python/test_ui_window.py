"""Issue 18: the operators in a real Blender window on a virtual display
(xvfb-run), invoked as a button invokes them: blender_tests/ui/window_journey.py."""
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BLENDER = os.environ.get("TEMPERA_BLENDER", "blender")
ZIP = Path(os.environ.get("TEMPERA_ADDON_ZIP", ROOT / "dist" / "tempera-addon-0.1.0.zip"))


@pytest.mark.skipif(shutil.which("xvfb-run") is None or shutil.which("xdotool") is None,
                    reason="needs xvfb and xdotool (tools/install_deps.sh)")
def test_stylize_in_a_real_window(tmp_path):
    if not ZIP.is_file():
        pytest.skip(f"{ZIP} not built (make addon-zip)")
    result = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", BLENDER, "--factory-startup",
                             "--window-geometry", "0", "0", "1920", "1080", "--python",
                             str(ROOT / "blender_tests" / "ui" / "window_journey.py"), "--", str(ZIP), str(tmp_path)],
                            capture_output=True, text=True, timeout=400)
    lines = [line for line in result.stdout.splitlines() if line.startswith("WINDOW_JOURNEY")]
    assert lines == ["WINDOW_JOURNEY OK"], "\n".join(lines) + result.stdout[-3000:] + result.stderr[-2000:]
