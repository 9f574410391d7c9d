"""The artist's journey in a real Blender window (run under a virtual display
by tests/python/test_ui_window.py): the operators invoked as buttons invoke
them (modal, a worker thread, timers), not through execute().

Stylize Frame, then Stylize Animation, then a long Stylize Animation that
must ask first. Checked: the frame is shown in an Image Editor window, the
animation switches the window to the result scene (Standard view), no job
steps after it finished, the long run waits for its confirmation, starts on
OK (Return) and stops on Esc. Prints
"WINDOW_JOURNEY OK" or "WINDOW_JOURNEY FAIL: ..." and quits."""
import sys
import time
from pathlib import Path

import bpy

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent / "tools"))
sys.path.insert(0, str(HERE.parent))
from blender_env import install_addon_zip  # noqa: E402

args = sys.argv[sys.argv.index("--") + 1:]
install_addon_zip(args[0])
out = Path(args[1])

from guide_scene import FRAMES, build_scene  # noqa: E402

scene = build_scene("Window journey")
window = bpy.context.window_manager.windows[0]
window.scene = scene
settings = scene.tempera
settings.output_dir, settings.guide_dir = str(out / "out"), str(out / "guides")
settings.guide_frame_range = "CUSTOM"
settings.guide_frame_start, settings.guide_frame_end = FRAMES[0], FRAMES[-1]
settings.guide_samples, settings.quality = 4, "preview"

from tempera.blender import stylize_operator  # noqa: E402
from tempera.blender.job_operator import running_job  # noqa: E402

steps_after_finish = []
reports = []
_step = stylize_operator.StylizeRun.step


def step(self, progress=None):
    if self.finished:
        steps_after_finish.append((self.mode, self.index))
    return _step(self, progress)


stylize_operator.StylizeRun.step = step
state = {"phase": "start", "deadline": time.monotonic() + 240}


def fail(message):
    print(f"WINDOW_JOURNEY FAIL: {message}", flush=True)
    bpy.ops.wm.quit_blender()


def invoke(mode):
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    with bpy.context.temp_override(window=window, area=area):
        return bpy.ops.tempera.stylize("INVOKE_DEFAULT", mode=mode)


def image_editors():
    return [a.spaces.active.image.name for w in bpy.context.window_manager.windows for a in w.screen.areas
            if a.type == "IMAGE_EDITOR" and a.spaces.active.image]


def tick():
    phase = state["phase"]
    if time.monotonic() > state["deadline"]:
        return fail(f"timed out in phase {phase}")
    if phase == "start":
        import subprocess

        subprocess.run(["xdotool", "mousemove", "300", "1075", "click", "1"], check=False)  # close the splash
        scene.frame_set(FRAMES[1])
        if invoke("FRAME") != {"RUNNING_MODAL"}:
            return fail("Stylize Frame did not start")
        state["phase"] = "frame"
    elif phase == "frame":
        if running_job():
            return 0.25
        state["phase"], state["wait"] = "frame shown", time.monotonic() + 5
    elif phase == "frame shown":
        if f"Tempera frames {FRAMES[1]}" not in image_editors():
            return 0.25 if time.monotonic() < state["wait"] else fail(f"no Image Editor shows the frame: {image_editors()}")
        if invoke("ANIMATION") != {"RUNNING_MODAL"}:
            return fail("Stylize Animation did not start")
        if bpy.ops.tempera.render_guides.poll():
            return fail("Render Guides is enabled while Stylize runs")
        state["phase"] = "animation"
    elif phase == "animation":
        if running_job():
            return 0.25
        if window.scene.name != scene.name + " Tempera":
            return fail(f"the window shows scene {window.scene.name!r}, not the result")
        if window.scene.view_settings.view_transform != "Standard":
            return fail("the result scene is not in the Standard view transform")
        window.scene = scene
        settings.guide_frame_start, settings.guide_frame_end = 1, 80
        invoke("ANIMATION")  # 80 frames: a confirmation dialog, nothing runs yet
        state["phase"], state["wait"] = "asked", time.monotonic() + 2
    elif phase == "asked":
        if time.monotonic() < state["wait"]:
            return 0.25
        if running_job():
            return fail("the 80-frame run started without confirmation")
        import subprocess

        subprocess.run(["xdotool", "mousemove", "300", "1050", "sleep", "0.3", "click", "1"], check=False)  # OK
        state["phase"], state["wait"] = "confirmed", time.monotonic() + 20
    elif phase == "confirmed":
        if not running_job():
            if time.monotonic() < state["wait"]:
                return 0.25
            bpy.ops.screen.screenshot(filepath=str(out / "no_start.png"))
            return fail("OK did not start the long run")
        import subprocess

        subprocess.run(["xdotool", "mousemove", "900", "500", "search", "--name", "Blender", "windowfocus", "--sync", "%1",
                        "key", "--window", "%1", "Escape"], check=False)
        state["phase"], state["wait"] = "stopped", time.monotonic() + 60
    elif phase == "stopped":
        if running_job():
            return 0.25 if time.monotonic() < state["wait"] else fail("Esc did not stop the long run")
        if steps_after_finish:
            return fail(f"finished jobs were stepped again: {steps_after_finish}")
        print("WINDOW_JOURNEY OK", flush=True)
        bpy.ops.wm.quit_blender()
        return None
    return 0.25


bpy.app.timers.register(tick, first_interval=3.0)
