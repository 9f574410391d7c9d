"""Screenshots of the real Tempera panel for docs/user_guide.md.

    /usr/bin/python3 docs/make_panel_screenshots.py [--addon-zip dist/tempera-addon-0.1.0.zip]

Outside Blender: starts Blender with a window on a virtual X display
(xvfb-run, from the xvfb package; tools/install_deps.sh installs it), the
add-on installed from the zip as a user installs it, and this same file as
its startup script. Inside Blender: the big area becomes a Properties editor
on the Output tab, the Blender panels above Tempera's are collapsed, and once
the window has drawn, Blender's own screenshot operator saves each view of
the panel into docs/images/. The screenshots are therefore the panel as it
is, at Blender's default UI scale, and stay current when it changes.
"""
import argparse
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
IMAGES = HERE / "images"
# (file, width of the Properties area, what is set up first)
SHOTS = (("panel_top.png", "top"), ("panel_custom_exemplar.png", "custom"), ("panel_guides.png", "guides"),
         ("panel_fluid.png", "fluid"), ("panel_natural_media.png", "media"))
# Blender's default layout on a tall screen: its Properties editor keeps the
# default width (333 px, as at 1920x1080) and is tall enough for the panel.
WINDOW = (1920, 2300)


# --------------------------------------------------------------------------- outside Blender

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--addon-zip", default=str(ROOT / "dist" / "tempera-addon-0.1.0.zip"))
    parser.add_argument("--blender", default=os.environ.get("TEMPERA_BLENDER", "blender"))
    parser.add_argument("--out", default=str(IMAGES))
    args = parser.parse_args()
    if not Path(args.addon_zip).is_file():
        sys.exit(f"{args.addon_zip} not found: run 'make addon-zip' first")
    for tool in ("xvfb-run", args.blender):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            sys.exit(f"{tool} not found (tools/install_deps.sh installs xvfb)")
    width, height = WINDOW
    command = ["xvfb-run", "-a", "-s", f"-screen 0 {width}x{height}x24", args.blender, "--factory-startup",
               "--window-geometry", "0", "0", str(width), str(height), "--python", __file__, "--",
               "--addon-zip", str(Path(args.addon_zip).resolve()), "--out", str(Path(args.out).resolve())]
    result = subprocess.run(command, timeout=600)
    missing = [name for name, _ in SHOTS if not (Path(args.out) / name).is_file()]
    if result.returncode != 0 or missing:
        sys.exit(f"screenshots failed (Blender exit status {result.returncode}; missing {missing})")
    for name, _ in SHOTS:
        crop_empty_bottom(Path(args.out) / name)
        print(Path(args.out) / name)


def crop_empty_bottom(path, margin=8, footer=60):
    """Drops the empty editor background below the last panel: rows that are
    one flat colour beside the tab column (the bottom `footer` rows, where
    Blender's status bar may be, are never content)."""
    sys.path.insert(0, str(ROOT / "addon"))
    import numpy as np
    import tempera

    image = tempera.read_image(str(path))
    rows = image[: image.shape[0] - footer, 40:-10, :3]
    busy = (rows.max(axis=1) - rows.min(axis=1)).max(axis=1) > 0.03
    last = int(np.nonzero(busy)[0][-1]) if busy.any() else image.shape[0] - 1
    tempera.write_image(str(path), np.ascontiguousarray(image[: min(image.shape[0], last + 1 + margin)]))


# --------------------------------------------------------------------------- inside Blender

def in_blender(argv):
    import tempfile

    import bpy

    sys.path.insert(0, str(ROOT / "tools"))
    from blender_env import install_addon_zip

    parser = argparse.ArgumentParser()
    parser.add_argument("--addon-zip", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    install_addon_zip(args.addon_zip)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="tempera-shots-"))

    scene = bpy.context.scene
    scene.tempera.output_dir = str(work / "out")  # absolute: no "save the .blend first" line
    scene.tempera.guide_dir = str(work / "guides")

    # The Output tab's own panels, closed and registered again after
    # Tempera's, so that Tempera's panel comes first.
    ours = {"TEMPERA_PT_output"}
    panels = [cls for cls in bpy.types.Panel.__subclasses__()
              if getattr(cls, "bl_space_type", "") == "PROPERTIES" and getattr(cls, "bl_context", "") == "output"
              and cls.__name__ not in ours and cls.is_registered]
    names = {cls.__name__ for cls in panels} | {getattr(cls, "bl_idname", cls.__name__) for cls in panels}
    children = [cls for cls in bpy.types.Panel.__subclasses__()
                if getattr(cls, "bl_parent_id", "") in names and cls.is_registered]
    moved = []
    for cls in children + panels:
        try:
            bpy.utils.unregister_class(cls)
            moved.append(cls)
        except RuntimeError:
            pass
    for cls in moved:
        cls.bl_options = set(getattr(cls, "bl_options", set())) | {"DEFAULT_CLOSED"}
    while moved:  # parents before their children, in as many passes as it takes
        left = []
        for cls in reversed(moved):
            try:
                bpy.utils.register_class(cls)
            except RuntimeError:
                left.append(cls)
        if len(left) == len(moved):
            break
        moved = list(reversed(left))

    window = bpy.context.window_manager.windows[0]
    screen = window.screen
    area = next(a for a in screen.areas if a.type == "PROPERTIES")  # the default layout's, at its default width

    steps = list(SHOTS)

    def setup(kind):
        settings = scene.tempera
        if kind == "custom":
            settings.exemplar_source = "CUSTOM"
            from tempera.app.exemplar_kit import kit_exemplar

            style, guides = kit_exemplar()
            settings.exemplar_style, settings.exemplar_guide_dir = str(style), str(guides)
        elif kind == "guides":
            settings.exemplar_source = "KIT"
            settings.guide_lpe = "L.*SDE; LD{2}E"
        elif kind == "fluid":
            settings.guide_lpe = ""
            settings.method, settings.media_exemplar_kind, settings.media_exemplar = "LAZYFLUIDS", "STILL", "//smoke.png"
        elif kind == "media":
            settings.method, settings.media_exemplar_kind, settings.media_exemplar = "FLUIDYMATION", "MOVIE", "//ink.mov"
            settings.fm_target_object = scene.objects.get("Cube")

    def shoot():
        if not steps:
            bpy.ops.wm.quit_blender()
            return None
        if not getattr(shoot, "started", False):  # a click beside the splash screen closes it
            subprocess.run(["xdotool", "mousemove", "300", str(WINDOW[1] - 5), "click", "1"], check=False)
            shoot.started = True
            return 1.0
        name, kind = steps[0]
        if getattr(shoot, "pending", None) != name:  # set up, then let two redraws pass
            area.spaces.active.context = "OUTPUT"
            setup(kind)
            region = next(r for r in area.regions if r.type == "WINDOW")
            if kind == "guides":
                with bpy.context.temp_override(window=window, area=area, region=region):
                    bpy.ops.view2d.scroll_down(deltay=2000)
            else:
                with bpy.context.temp_override(window=window, area=area, region=region):
                    bpy.ops.view2d.scroll_up(deltay=4000)
            area.tag_redraw()
            shoot.pending = name
            return 1.5 if getattr(shoot, "shots", 0) else 6.0  # the first waits for the thumbnail to load
        with bpy.context.temp_override(window=window, area=area):
            bpy.ops.screen.screenshot_area(filepath=str(out / name))
        print(f"screenshot: {out / name}", flush=True)
        shoot.shots = getattr(shoot, "shots", 0) + 1
        steps.pop(0)
        return 0.5

    bpy.app.timers.register(shoot, first_interval=4.0)


if __name__ == "__main__":
    if "bpy" in sys.modules or "--addon-zip" in sys.argv and "--" in sys.argv:
        try:
            import bpy  # noqa: F401

            in_blender(sys.argv[sys.argv.index("--") + 1:])
        except ImportError:
            main()
    else:
        main()
