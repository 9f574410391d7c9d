"""`tempera render-guides`: the guide cache of a .blend made by somebody else,
rendered by the CLI through background Blender, without touching the file."""
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from tempera.app import guide_cache

ROOT = Path(__file__).resolve().parents[2]
BLENDER = os.environ.get("TEMPERA_BLENDER", "blender")

# Builds the demo's animated scene, then makes it awkward the way users' files
# are: saved with EEVEE as the engine, an odd resolution at 50 %, motion blur off.
MAKE_BLEND = """
import sys, bpy
sys.path.insert(0, {scenes!r})
import demo_scene
scene = bpy.context.scene
demo_scene.build_scene(scene)
scene.render.engine = "BLENDER_EEVEE"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 97, 73, 50
scene.frame_start, scene.frame_end = 1, 8
bpy.ops.wm.save_as_mainfile(filepath={path!r})
"""


@pytest.fixture(scope="module")
def user_blend(tmp_path_factory):
    path = tmp_path_factory.mktemp("blend") / "someone_elses.blend"
    code = MAKE_BLEND.format(scenes=str(ROOT / "scenes"), path=str(path))
    result = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr", code],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and path.is_file(), result.stdout[-2000:] + result.stderr[-2000:]
    return path


def render_guides(cli_path, *args):
    return subprocess.run([str(cli_path), "render-guides", *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=dict(os.environ, TEMPERA_BLENDER=BLENDER))


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_renders_the_cache_at_the_effective_resolution_and_leaves_the_file_alone(cli_path, user_blend, tmp_path):
    before = digest(user_blend)
    out = tmp_path / "cache"
    result = render_guides(cli_path, user_blend, "--frames", "2-3", "--out", out, "--samples", "4",
                           "--ld12e-samples", "4")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "rendered 2 frame(s)" in result.stdout
    assert digest(user_blend) == before, "the .blend on disk was modified"
    manifest = guide_cache.read_manifest(out)
    assert manifest["resolution"] == [48, 36]  # 97x73 at 50 %
    guides = guide_cache.read_frame(out, 2)
    assert guides["FULL"].shape[:2] == (36, 48)
    assert "velocity_forward" in guides and "occlusion_backward" in guides and "LD12E" in guides

    again = render_guides(cli_path, user_blend, "--frames", "2-3", "--out", out, "--samples", "4",
                          "--ld12e-samples", "4")
    assert again.returncode == 0, again.stderr[-2000:]
    assert "rendered 0 frame(s), 2 already current" in again.stdout


def test_clear_errors(cli_path, user_blend, tmp_path):
    cases = [
        ((user_blend, "--out", tmp_path), "--frames is required"),
        ((user_blend, "--frames", "1-2"), "--out is required"),
        ((tmp_path / "missing.blend", "--frames", "1", "--out", tmp_path), "scene file not found"),
        ((user_blend, "--frames", "3-1", "--out", tmp_path), "ends before it starts"),
        ((user_blend, "--frames", "1", "--out", tmp_path, "--scene", "Nope"), "no scene named 'Nope'"),
    ]
    for args, message in cases:
        result = render_guides(cli_path, *args)
        assert result.returncode != 0, args
        assert message in result.stderr, (args, result.stderr[-1500:])


def test_lpe_options_reach_the_guide_cache(cli_path, user_blend, tmp_path):
    out = tmp_path / "cache"
    result = render_guides(cli_path, user_blend, "--frames", "2", "--out", out, "--samples", "2", "--ld12e-samples",
                           "2", "--masks", "none", "--lpe", "LDE", "--lpe", "L.*SDE", "--lpe-samples", "4")
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    manifest = guide_cache.read_manifest(out)
    assert manifest["params"]["lpe"] == ["LDE", "L.*SDE"] and manifest["params"]["lpe_samples"] == 4
    caustics = guide_cache.lpe_guide("L.*SDE")
    assert manifest["lpe"] == {"lpe_LDE": "LDE", caustics: "L.*SDE"}
    guides = guide_cache.read_frame(out, 2, ["lpe_LDE", caustics])
    assert guides["lpe_LDE"].shape == (36, 48, 3) and guides["lpe_LDE"].max() > 0

    bad = render_guides(cli_path, user_blend, "--frames", "2", "--out", tmp_path / "bad", "--lpe", "L(DE")
    assert bad.returncode != 0
    assert "Light path expression 1 'L(DE' is malformed" in bad.stderr and "position 4" in bad.stderr
    assert not (tmp_path / "bad").exists()


@pytest.mark.parametrize("args, message", [
    (["--tensor-sigma", "1e9"], "tensor_sigma (structure tensor sigma (pixels)) must be from 0 to 1000"),
    (["--lpe", "(" * 60000 + "L" + ")" * 60000], "at most 1000"),
    (["--lpe", "L.*D.{30}E"], "too complex"),
    (["--samples", "0"], "samples (Cycles samples) must be from 1"),
])
def test_bad_values_exit_2_before_rendering_and_leave_nothing(cli_path, user_blend, tmp_path, args, message):
    """Issue 18: these crashed Blender (exit 139), hung it, or left temporary folders."""
    private_tmp = tmp_path / "tmp"  # the system's temporary folder of this run alone (others share /tmp)
    private_tmp.mkdir()
    result = subprocess.run([str(cli_path), "render-guides", str(user_blend), "--frames", "1", "--out",
                             str(tmp_path / "g"), *args], capture_output=True, text=True, timeout=300,
                            env=dict(os.environ, TEMPERA_BLENDER=BLENDER, TMPDIR=str(private_tmp)))
    assert result.returncode == 2, result.stdout[-1500:] + result.stderr[-1500:]
    assert message in result.stderr
    assert not (tmp_path / "g").exists()
    assert [p.name for p in private_tmp.iterdir() if p.name.startswith("tempera-guides-")] == []


def test_frames_beyond_blenders_last_frame_exit_2(cli_path, user_blend, tmp_path):
    result = render_guides(cli_path, user_blend, "--frames", "1-99999999999", "--out", tmp_path / "g")
    assert result.returncode == 2 and "outside 0-1048574" in result.stderr, result.stderr[-1500:]


def test_ctrl_c_keeps_the_finished_frames(cli_path, user_blend, tmp_path):
    """Issue 18: Ctrl-C at frame 3 of 8 used to leave an empty cache (frames
    waited in the system's temporary folder for the whole range)."""
    import signal
    import time

    private_tmp = tmp_path / "tmp"  # the system's temporary folder of this run alone (others share /tmp)
    private_tmp.mkdir()
    out = tmp_path / "g"
    process = subprocess.Popen([str(cli_path), "render-guides", str(user_blend), "--frames", "1-60", "--out",
                                str(out), "--samples", "2", "--ld12e-samples", "2"], start_new_session=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=dict(os.environ, TEMPERA_BLENDER=BLENDER, TMPDIR=str(private_tmp)))
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and not (out / "frame_0002.exr").exists() and process.poll() is None:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)  # what a terminal's Ctrl-C does
    _, err = process.communicate(timeout=240)
    assert process.returncode == 130, err[-2000:]
    assert "interrupted; the frames finished so far are in the cache" in err
    manifest = guide_cache.read_manifest(out)
    kept = sorted(int(f) for f in manifest["frames"])
    assert kept and kept == list(range(1, len(kept) + 1)) and len(kept) < 60
    for f in kept:
        assert guide_cache.is_frame_current(out, manifest, f, manifest["frames"][str(f)]["key"])
    assert [p.name for p in private_tmp.iterdir() if p.name.startswith("tempera-guides-")] == []
    again = render_guides(cli_path, user_blend, "--frames", f"1-{len(kept) + 2}", "--out", out, "--samples", "2",
                          "--ld12e-samples", "2")
    assert again.returncode == 0 and f"{len(kept)} already current" in again.stdout, again.stdout[-1500:]
    assert not list(out.glob(".tempera-render-*"))


# A library whose exit-time teardown crashes Blender: the state Blender is in
# when the wheel's native module brought second copies of the libraries it
# already loaded (their statics are destroyed twice at exit).
CRASH_AT_EXIT_C = r"""
#include <signal.h>
#include <string.h>
#include <unistd.h>
__attribute__((destructor)) static void crash_at_exit(void) {
  char exe[4096] = {0};
  if (readlink("/proc/self/exe", exe, sizeof exe - 1) > 0 && strstr(exe, "blender")) raise(SIGSEGV);
}
"""


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")
def test_blender_ends_without_the_libraries_teardown(cli_path, user_blend, tmp_path):
    """The wheel farm's bug: Debian's Blender 3.4 died with SIGSEGV after
    "Blender quit", in the teardown of libraries loaded twice, with every
    guide written. The guide renderer ends Blender without that teardown,
    and cleans up what Blender's quit would have (its session folder)."""
    source = tmp_path / "crash_at_exit.c"
    source.write_text(CRASH_AT_EXIT_C)
    library = tmp_path / "crash_at_exit.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(library), str(source)], check=True)
    private_tmp = tmp_path / "tmp"  # the system's temporary folder of this run alone (others share /tmp)
    private_tmp.mkdir()
    out = tmp_path / "g"
    result = subprocess.run([str(cli_path), "render-guides", str(user_blend), "--frames", "1-2", "--out", str(out),
                             "--samples", "2", "--ld12e-samples", "2"], capture_output=True, text=True, timeout=300,
                            env=dict(os.environ, TEMPERA_BLENDER=BLENDER, TMPDIR=str(private_tmp),
                                     LD_PRELOAD=str(library)))
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    assert "rendered 2 frame(s)" in result.stdout
    assert "Saved:" in result.stdout  # Blender's own lines, still buffered in C when it ended, are kept
    manifest = guide_cache.read_manifest(out)
    for f in (1, 2):
        assert guide_cache.is_frame_current(out, manifest, f, manifest["frames"][str(f)]["key"])
    assert list(private_tmp.iterdir()) == []  # no session folder of Blender's left, no crash report
