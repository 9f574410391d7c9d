"""`tempera stylize`: a shot from guide caches (render farm form) and from a .blend."""
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import tempera
from synthetic_cache import H, W, make_cache, make_exemplar

ROOT = Path(__file__).resolve().parents[2]
BLENDER = os.environ.get("TEMPERA_BLENDER", "blender")


def stylize(cli_path, *args, timeout=300):
    return subprocess.run([str(cli_path), "stylize", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ, TEMPERA_BLENDER=BLENDER))


@pytest.fixture()
def caches(tmp_path):
    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    return tmp_path


def farm_args(p, *extra):
    return ("--guides", p / "cache", "--exemplar", p / "paint.png", "--exemplar-guides", p / "exemplar",
            "--frames", "1-3", "--out", p / "out", "--threads", "2", *extra)


def video_frames(path):
    result = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                             "stream=nb_read_frames", "-of", "csv=p=0", str(path)], capture_output=True, text=True)
    return int(result.stdout.strip())


def test_farm_form_writes_frames_sheet_and_video_then_resumes(cli_path, caches):
    result = stylize(cli_path, *farm_args(caches, "--temporal", "0.5"))
    assert result.returncode == 0, result.stderr
    out = caches / "out"
    for f in (1, 2, 3):
        assert tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png")).shape == (H, W, 3)
    assert "frame 3/3 (#3)" in result.stdout and "mean flicker" in result.stdout
    assert tempera.image_info(str(out / "contact_sheet.png"))["width"] == 2 * W + 4
    if shutil.which("ffmpeg"):
        assert video_frames(out / "stylized.mp4") == 3
    assert [f.name for f in out.rglob("*") if f.name.startswith(".")] == []

    again = stylize(cli_path, *farm_args(caches, "--temporal", "0.5"))
    assert again.returncode == 0, again.stderr
    assert again.stdout.count("skipped, already current") == 3
    assert "0 frame(s) stylized, 3 skipped" in again.stdout
    changed = stylize(cli_path, *farm_args(caches, "--temporal", "0.5", "--weights", "LDE=3", "--no-video"))
    assert "3 frame(s) stylized, 0 skipped" in changed.stdout


def test_exr_output_and_preview_quality(cli_path, caches):
    result = stylize(cli_path, *farm_args(caches, "--format", "exr", "--quality", "preview"))
    assert result.returncode == 0, result.stderr
    assert (caches / "out" / "frames" / "frame_0002.exr").is_file()
    assert "no video: it needs consecutive PNG frames" in result.stdout


def test_errors_and_exit_codes(cli_path, caches):
    missing = caches / "missing.png"
    result = stylize(cli_path, "--guides", caches / "cache", "--exemplar", missing, "--exemplar-guides",
                     caches / "exemplar", "--frames", "1-3", "--out", caches / "out")
    assert result.returncode == 1 and str(missing) in result.stderr, result.stderr
    result = stylize(cli_path, *farm_args(caches, "--sparkle"))
    assert result.returncode == 2 and "unknown option '--sparkle'" in result.stderr
    result = stylize(cli_path, *farm_args(caches, "--weights", "SSS=1"))
    assert result.returncode == 2 and "unknown guide 'SSS'" in result.stderr
    result = stylize(cli_path, "--exemplar", caches / "paint.png", "--frames", "1", "--out", caches / "o",
                     "--exemplar-guides", caches / "exemplar")
    assert result.returncode == 2 and "--guides DIR" in result.stderr
    result = stylize(cli_path, *farm_args(caches)[:-4], "--frames", "1-5", "--out", caches / "o")
    assert result.returncode == 1 and "frame(s) 4, 5" in result.stderr
    help_text = stylize(cli_path, "--help")
    assert help_text.returncode == 0
    for option in ("--exemplar-scene", "--weights", "--temporal", "--quality", "--no-resume", "--fps", "--samples"):
        assert option in help_text.stdout
    own = stylize(cli_path, "--method", "stylit", "--help")  # StyLit's page of the one command
    assert own.returncode == 0 and own.stdout.startswith("usage: tempera stylize --method stylit")
    for option in ("--exemplar-guides", "--exemplar-scene", "--weights", "--temporal", "--noise", "--fps", "--samples"):
        assert option in own.stdout, option


def test_stylits_options_come_from_its_one_table(cli_path, caches):
    """Issue 41, step 6: --temporal and --quality, their help, the Python
    defaults and keywords, and the panel's tooltips read StyLit's option table."""
    from tempera.app import settings
    from tempera.methods.stylit import stylize as stylit

    table = {row["name"]: row for row in tempera._native.StylitOptions.table()}
    assert (table["temporal_weight"]["flag"], table["quality"]["choices"]) == ("temporal", ["final", "preview"])
    defaults = tempera._native.StylitOptions()
    assert (defaults.temporal_weight, defaults.quality) == (0.0, "final")
    assert settings.STYLIT_OPTIONS == table and settings.DEFAULT_QUALITY == "final"
    help_text = stylize(cli_path, "--help").stdout
    assert table["quality"]["help"] in help_text and table["temporal_weight"]["help"] in help_text
    for bad, message in ((("--quality", "best"), "unknown quality 'best' (choose final, preview)"),
                         (("--temporal", "x"), "--temporal expects a number, got 'x'"),
                         (("--temporal", "-1"), "temporal weight must be finite and >= 0")):
        result = stylize(cli_path, *farm_args(caches, *bad))
        assert result.returncode == 2 and message in result.stderr, (bad, result.stderr)
    config = dict(style=caches / "paint.png", exemplar_guides=caches / "exemplar", guides=caches / "cache",
                  frames=[1], out=caches / "py")
    with pytest.raises(ValueError, match="unknown quality 'best'"):
        stylit.StylizeJob(**config, quality="best")
    assert stylit.StylizeJob(**config, quality="preview", temporal_weight=1).frames == [1]


def test_ctrl_c_keeps_finished_frames(cli_path, tmp_path):
    # Frames big enough to take a while, so the interrupt lands mid-run.
    from tempera.app import guide_cache
    from synthetic_cache import light_paths

    h, w = 192, 256
    for f in range(1, 5):
        guides = light_paths(100 + 2 * f, h, w)
        guides["velocity_backward"] = np.zeros((h, w, 2), np.float32)
        guides["occlusion_backward"] = np.ones((h, w), np.float32)
        guide_cache.write_frame(tmp_path / "cache", f, guides)
    guide_cache.write_frame(tmp_path / "exemplar", 1, light_paths(128, h, w))
    tempera.write_image(str(tmp_path / "paint.png"), np.random.default_rng(0).random((h, w, 3), dtype=np.float32))
    process = subprocess.Popen([str(cli_path), "stylize", *map(str, farm_args(tmp_path)[:-2]), "--threads", "1",
                                "--frames", "1-4"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = process.stdout.readline()
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    assert first.startswith("frame 1/4")
    assert process.returncode == 130, stderr
    assert "rerun the same command to resume" in stderr
    frames = tmp_path / "out" / "frames"
    assert (frames / "frame_0001.png").is_file() and not (frames / "frame_0004.png").exists()
    assert [f.name for f in frames.iterdir() if f.name.startswith(".")] == []


@pytest.mark.skipif(shutil.which(BLENDER) is None, reason="Blender not installed")
def test_scene_form_renders_guides_with_blender(cli_path, tmp_path):
    blend = tmp_path / "shot.blend"
    code = (f"import sys, bpy; sys.path.insert(0, {str(ROOT / 'scenes')!r}); import demo_scene; "
            "scene = bpy.context.scene; demo_scene.build_scene(scene); "
            "scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 64, 48, 50; "
            f"bpy.ops.wm.save_as_mainfile(filepath={str(blend)!r})")
    made = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", code],
                          capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr[-2000:]
    painting = tmp_path / "paint.png"
    tempera.write_image(str(painting), np.random.default_rng(1).random((24, 32, 3), dtype=np.float32))
    out = tmp_path / "out"
    result = stylize(cli_path, blend, "--exemplar", painting, "--exemplar-scene", blend, "--frames", "2-3",
                     "--out", out, "--samples", "2", "--temporal", "0.5", "--threads", "2", timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert (out / "guides" / "frame_0003.exr").is_file() and (out / "exemplar_guides" / "frame_0001.exr").is_file()
    assert tempera.read_image(str(out / "frames" / "frame_0003.png")).shape == (24, 32, 3)
    assert "flicker" in result.stdout and (out / "contact_sheet.png").is_file()
    again = stylize(cli_path, blend, "--exemplar", painting, "--exemplar-scene", blend, "--frames", "2-3",
                    "--out", out, "--samples", "2", "--temporal", "0.5", "--threads", "2", "--no-video", timeout=600)
    assert again.returncode == 0, again.stderr[-2000:]
    assert "0 frame(s) stylized, 2 skipped" in again.stdout


def _tiny_scene(blend):
    code = (f"import sys, bpy; sys.path.insert(0, {str(ROOT / 'scenes')!r}); import demo_scene; "
            "scene = bpy.context.scene; demo_scene.build_scene(scene); "
            "scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 64, 48, 50; "
            f"bpy.ops.wm.save_as_mainfile(filepath={str(blend)!r})")
    made = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", code],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=str(ROOT / "addon")))
    assert made.returncode == 0, made.stderr[-2000:]


def _exemplar(kind, out, size, frames):
    made = subprocess.run([sys.executable, "-m", "tempera", "exemplar", kind, "--out", str(out), "--size", size,
                           "--frames", str(frames)], capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=str(ROOT / "addon")))
    assert made.returncode == 0, made.stderr


def test_fluid_methods_default_to_the_projects_own_exemplar(cli_path, tmp_path):
    """Step 5 of issue 41: with no --exemplar, the Python package's `tempera
    stylize` writes the method's default exemplar (its registry entry's
    default_exemplar) into OUT once and runs the method with it; the native
    CLI alone names the way to one."""
    from tempera.app import guide_cache

    yy, xx = np.mgrid[0:40, 0:48].astype(np.float32)
    for f in (1, 2):
        alpha = np.clip(12 - np.hypot(xx - 20 - 2 * f, yy - 20) + 0.5, 0, 1).astype(np.float32)
        flow = np.zeros((40, 48, 2), np.float32)
        flow[..., 0] = 2.0
        guide_cache.write_frame(tmp_path / "guides", f, {"alpha": alpha, "fluid_velocity": flow,
                                                         "velocity_forward": flow * alpha[..., None]})
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(cli_path))
    for method, kind in (("lazyfluids", "smoke"), ("fluidymation", "ink")):
        assert tempera._native.find_method(method)["default_exemplar"] == kind
        out = tmp_path / method
        args = ["stylize", "--method", method, "--guides", str(tmp_path / "guides"), "--frames", "1-2",
                "--out", str(out), "--levels", "2", "--threads", "2"]
        native = subprocess.run([str(cli_path), *args], capture_output=True, text=True, timeout=300)
        assert native.returncode == 2 and f"tempera exemplar {kind} --out DIR" in native.stderr, native.stderr
        run = subprocess.run([sys.executable, "-m", "tempera", *args], capture_output=True, text=True, timeout=300,
                             env=env)
        assert run.returncode == 0, run.stderr[-2000:]
        assert f"the project's own {kind} exemplar" in run.stderr
        exemplar = out / f"exemplar_generated_{kind}"
        assert len(list(exemplar.glob("frame_*.png"))) == 24
        assert tempera.read_image(str(exemplar / "frame_0001.png")).shape == (256, 256, 4)
        assert tempera.read_image(str(out / "frames" / "frame_0002.png")).shape == (40, 48, 4)  # one layout
        written = (exemplar / "frame_0001.png").stat().st_mtime_ns
        again = subprocess.run([sys.executable, "-m", "tempera", *args], capture_output=True, text=True,
                               timeout=300, env=env)
        assert again.returncode == 0 and again.stdout.count("skipped, already current") == 2, again.stdout
        assert (exemplar / "frame_0001.png").stat().st_mtime_ns == written  # made once


def test_light_path_methods_default_to_the_bundled_kit(cli_path, caches):
    """Step 5 of issue 41: with no painting of one's own, the Python package's
    `tempera stylize` gives StyLit (and the coherent method) the bundled
    exemplar kit's painting and guides; the frames are those of the kit given
    by hand. The native CLI alone names the way to one; a missing kit is named."""
    from tempera.app import guide_cache

    kit = caches / "kits" / "sphere_on_table"
    kit.mkdir(parents=True)
    shutil.copy(caches / "paint.png", kit / "style.png")
    shutil.copytree(caches / "exemplar", kit / "guides")
    guide_cache.write_manifest(kit / "guides", {"frames": {}})  # a kit's guides are a whole cache
    for method in ("stylit", "tcia"):
        assert tempera._native.find_method(method)["default_exemplar"] == tempera._native.KIT_EXEMPLAR == "kit"
    args = ["stylize", "--method", "stylit", "--guides", str(caches / "cache"), "--frames", "1-2", "--threads", "2",
            "--levels", "2"]
    native = subprocess.run([str(cli_path), *args, "--out", str(caches / "native")], capture_output=True, text=True,
                            timeout=300)
    assert native.returncode == 2 and "uses the bundled exemplar kit" in native.stderr, native.stderr
    env = dict(os.environ, PYTHONPATH=str(ROOT / "addon"), TEMPERA_CLI=str(cli_path),
               TEMPERA_KIT_DIR=str(caches / "kits"))
    no_method = [a for a in args if a not in ("--method", "stylit")]  # StyLit is the default method
    assert tempera._native.default_method() == "stylit"
    run = subprocess.run([sys.executable, "-m", "tempera", *no_method, "--out", str(caches / "kit_run")],
                         capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "using the bundled exemplar kit" in run.stderr
    by_hand = stylize(cli_path, *args[1:], "--exemplar", kit / "style.png", "--exemplar-guides", kit / "guides",
                      "--out", caches / "by_hand")
    assert by_hand.returncode == 0, by_hand.stderr
    for f in (1, 2):
        name = f"frames/frame_{f:04d}.png"
        assert (caches / "kit_run" / name).read_bytes() == (caches / "by_hand" / name).read_bytes()
    missing = subprocess.run([sys.executable, "-m", "tempera", *args, "--out", str(caches / "no_kit")],
                             capture_output=True, text=True, timeout=300,
                             env=dict(env, TEMPERA_KIT_DIR=str(caches / "nowhere")))
    assert missing.returncode == 1 and "exemplar kit 'sphere_on_table' is not in this build" in missing.stderr


@pytest.mark.skipif(shutil.which(BLENDER) is None, reason="Blender not installed")
def test_fluid_methods_render_a_scenes_guides_first(cli_path, tmp_path):
    """Step 5 of issue 41: `stylize SCENE.blend` for the methods that read a guide cache
    (LazyFluids, Fluidymation) renders the guides into OUT/guides, then runs the method."""
    blend = tmp_path / "shot.blend"
    _tiny_scene(blend)
    _exemplar("smoke", tmp_path / "smoke", "64x64", 1)
    _exemplar("ink", tmp_path / "ink", "64x64", 6)
    runs = {"lazyfluids": ("--exemplar", tmp_path / "smoke" / "frame_0001.png"),
            "fluidymation": ("--exemplar", tmp_path / "ink", "--exemplar-masks", tmp_path / "ink" / "masks")}
    for method, exemplar in runs.items():
        out = tmp_path / method
        args = (blend, "--method", method, *exemplar, "--frames", "1-2", "--out", out, "--samples", "2",
                "--threads", "2")
        result = stylize(cli_path, *args, timeout=600)
        assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
        assert "rendering the guides of" in result.stderr and (out / "guides" / "frame_0002.exr").is_file()
        frames = sorted(out.rglob("frame_000[12].png"))
        assert len(frames) == 2 and all(tempera.read_image(str(f)).shape == (24, 32, 4) for f in frames), frames
        again = stylize(cli_path, *args, timeout=600)
        assert again.returncode == 0, again.stderr[-2000:]
        assert "rendered 0 frame(s), 2 already current" in again.stdout + again.stderr  # Blender's output
        assert again.stdout.count("skipped, already current") == 2, again.stdout[-2000:]


def test_a_scene_for_a_fluid_method_is_checked_before_blender_runs(cli_path, tmp_path):
    blend = tmp_path / "shot.blend"
    blend.write_bytes(b"BLENDER")  # never opened: the checks come first
    base = (blend, "--method", "lazyfluids", "--exemplar", tmp_path / "x.png")
    no_frames = stylize(cli_path, *base, "--out", tmp_path / "o")
    assert no_frames.returncode == 2 and "--frames is required" in no_frames.stderr
    no_blender = stylize(cli_path, *base, "--frames", "1-2", "--out", tmp_path / "o", "--blender",
                         tmp_path / "no_blender")
    assert no_blender.returncode == 1 and "cannot run" in no_blender.stderr, no_blender.stderr
    missing = stylize(cli_path, tmp_path / "none.blend", "--method", "fluidymation", "--exemplar", tmp_path,
                      "--frames", "1-2", "--out", tmp_path / "o")
    assert missing.returncode == 1 and "scene file not found" in missing.stderr


def test_a_scene_form_names_a_bad_option_before_blender_runs(cli_path, tmp_path):
    """The one command reads every method's options (its entry's
    check_options) before Blender renders a scene's guides: a typo costs no
    render. Here no Blender could run at all."""
    blend = tmp_path / "shot.blend"
    blend.write_bytes(b"BLENDER")  # never opened: the options come first
    runs = {"stylit": (("--exemplar-guides", tmp_path, "--sparkle", "1"), "unknown option '--sparkle'"),
            "tcia": (("--exemplar-guides", tmp_path, "--weights", "SSS=1"), "unknown guide 'SSS'"),
            "lazyfluids": (("--lambda", "-1"), "temporal weight"),
            "fluidymation": (("--flow", "wind"), "--flow")}
    for method, (extra, message) in runs.items():
        result = stylize(cli_path, blend, "--method", method, "--exemplar", tmp_path / "x.png", *extra,
                         "--frames", "1-2", "--out", tmp_path / "o", "--blender", tmp_path / "no_blender")
        assert result.returncode == 2 and message in result.stderr, (method, result.stderr)
        assert "rendering the guides" not in result.stderr and not (tmp_path / "o").exists(), method
