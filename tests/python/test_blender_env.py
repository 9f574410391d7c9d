"""tools/blender_env.py: the parts that run outside Blender."""
import os
import sys

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tools"))
import blender_env  # noqa: E402


def test_blender_command():
    cmd = blender_env.blender_command("blender", ROOT / "scenes" / "demo_scene.py", ["--out", 3])
    assert cmd[:5] == ["blender", "-b", "--factory-startup", "--python-exit-code", "1"]
    assert cmd[5:] == ["--python", str(ROOT / "scenes" / "demo_scene.py"), "--", "--out", "3"]


def test_script_args():
    assert blender_env.script_args(["blender", "-b", "--python", "x.py", "--", "--out", "d"]) == ["--out", "d"]
    assert blender_env.script_args(["blender", "-b"]) == []


def test_hide_source_addon(monkeypatch):
    import tempera  # noqa: F401  (imported from addon/, so there is something to forget)

    addon = str(ROOT / "addon")
    monkeypatch.setattr(sys, "path", [addon, "/elsewhere", addon + "/"])
    monkeypatch.setenv("PYTHONPATH", f"{addon}:/other")
    saved = {name: module for name, module in sys.modules.items() if name.split(".")[0] == "tempera"}
    try:
        blender_env.hide_source_addon()
        assert sys.path == ["/elsewhere"]
        assert os.environ["PYTHONPATH"] == "/other"
        assert not [name for name in sys.modules if name.split(".")[0] == "tempera"]
    finally:
        sys.modules.update(saved)
