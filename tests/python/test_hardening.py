"""Issue 18, part 2: hostile input never crashes, hangs or loses work.

Each test reproduces one defect of the audit. Calls that crashed the process
(stack overflow, std::terminate, Embree assertions) run in a child Python,
so that a regression fails the test instead of killing the test run."""
import json
import multiprocessing
import os
import shutil
import struct
import subprocess
import sys
import textwrap
import threading
import time
import zlib
from pathlib import Path

import numpy as np
import pytest

import tempera
from tempera import _native
from tempera.app import guide_cache
from tempera.app.frames import MAX_FRAME, parse_frames
from tempera.methods.stylit import stylize
from tempera.methods.stylit.stylize import StylizeJob

from synthetic_cache import H, W, make_cache, make_exemplar

ROOT = Path(__file__).resolve().parents[2]
ADDON = ROOT / "addon"


def child(code, timeout=60, memory_mb=None, env=None):
    """Runs `code` in a fresh /usr/bin/python3 with the tempera package;
    `memory_mb` caps its address space (RLIMIT_AS)."""
    prelude = ""
    if memory_mb:
        prelude = (f"import resource; resource.setrlimit(resource.RLIMIT_AS, ({memory_mb << 20}, {memory_mb << 20}))\n")
    return subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, env=dict(os.environ, PYTHONPATH=str(ADDON), **(env or {})))


def expect_value_error(code, match, timeout=60, memory_mb=None):
    result = child(f"""
        import numpy as np, tempera
        from tempera.engine import guides
        try:
            {code}
        except ValueError as exc:
            print("ValueError:", exc)
        else:
            print("no error")
        """, timeout=timeout, memory_mb=memory_mb)
    assert result.returncode == 0, f"child died with status {result.returncode}: {result.stderr[-2000:]}"
    assert "ValueError:" in result.stdout and match in result.stdout, result.stdout
    return result.stdout


@pytest.fixture()
def caches(tmp_path):
    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    return tmp_path


def job(p, frames=(1, 2, 3), out=None, **kwargs):
    return StylizeJob(p / "paint.png", p / "exemplar", p / "cache", list(frames), out or p / "out", threads=1,
                      **kwargs)


# --------------------------------------------------------------------------- 1, 2: LPE compiler

@pytest.mark.parametrize("expression, match", [
    ("'(' * 60000 + 'L' + ')' * 60000", "at most 1000"),   # parser recursion
    ("'L' + '?' * 100000", "at most 1000"),                # NFA build recursion
    ("'(' * 400 + 'L' + ')' * 400", "nested more than 64"),
    ("'L' + '*?' * 200", "nested more than 64"),
])
def test_deep_lpe_is_refused_not_a_stack_overflow(expression, match):
    expect_value_error(f"tempera.check_lpe({expression})", match)


@pytest.mark.parametrize("expression, match", [
    ("L.*D.{20}E", "too complex"),
    ("L.*D.{30}E", "too complex"),
    ("LD{100}{100}{100}E", "too large"),
])
def test_exponential_lpe_is_refused_quickly_and_small(expression, match):
    start = time.monotonic()
    expect_value_error(f"tempera.check_lpe({expression!r})", match, timeout=30, memory_mb=1024)
    assert time.monotonic() - start < 20


def test_ordinary_lpes_still_compile():
    for expression in ("L.*E", "LDE", "L.*DDE", "LD{1,2}E", "LS+DE", "L[DS]{1,8}E", "L(D|S){0,10}E"):
        tempera.check_lpe(expression)


# --------------------------------------------------------------------------- 3: Gaussian radius

def test_huge_structure_tensor_sigma_is_a_value_error():
    expect_value_error("guides.structure_tensor(np.zeros((8, 8, 1), np.float32), 1e9)", "sigma must be from 0 to")
    expect_value_error("guides.structure_tensor(np.zeros((8, 8, 1), np.float32), 1e7)", "sigma must be from 0 to",
                       memory_mb=1024)


def _reference_blur(image, sigma):
    """Unclamped Gaussian with replicated borders, in numpy (float64)."""
    radius = int(np.ceil(3 * sigma))
    taps = np.arange(-radius, radius + 1)
    kernel = np.exp(-0.5 * taps**2 / sigma**2)
    kernel /= kernel.sum()
    h, w = image.shape[:2]
    out = np.zeros_like(image, np.float64)
    for i, k in zip(taps, kernel):
        out += k * image[:, np.clip(np.arange(w) + i, 0, w - 1)]
    final = np.zeros_like(out)
    for i, k in zip(taps, kernel):
        final += k * out[np.clip(np.arange(h) + i, 0, h - 1)]
    return final


def test_wide_kernel_is_clamped_to_the_image_exactly():
    from tempera.engine import guides

    rng = np.random.default_rng(1)
    image = rng.random((8, 11, 1), dtype=np.float32)
    tensor = np.asarray(guides.structure_tensor(image, 0.0), np.float64)
    start = time.monotonic()
    blurred = np.asarray(guides.structure_tensor(image, 900.0))
    assert time.monotonic() - start < 2  # a 5401-tap kernel folded onto 11 and 8 pixels
    np.testing.assert_allclose(blurred, _reference_blur(tensor, 900.0), rtol=1e-4, atol=1e-6)


# --------------------------------------------------------------------------- 4: outputs on inputs

def test_stylize_refuses_an_output_folder_that_is_the_guide_cache(caches):
    before = {p.name: p.read_bytes() for p in (caches / "cache").iterdir()}
    with pytest.raises(ValueError, match="is the guide cache folder"):
        job(caches, out=caches / "cache", format="exr")
    with pytest.raises(ValueError, match="exemplar guide cache"):
        job(caches, out=caches / "exemplar" / ".." / "exemplar")
    assert {p.name: p.read_bytes() for p in (caches / "cache").iterdir()} == before


def test_cli_stylize_out_whose_frames_folder_is_the_guides(cli_path, caches):
    work = caches / "work"
    shutil.copytree(caches / "cache", work / "frames")
    result = subprocess.run([str(cli_path), "stylize", "--guides", str(work / "frames"), "--exemplar",
                             str(caches / "paint.png"), "--exemplar-guides", str(caches / "exemplar"), "--frames",
                             "1-3", "--format", "exr", "--out", str(work), "--no-video"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    assert "would overwrite the guides" in result.stderr
    assert "FULL.R" in tempera.image_info(str(work / "frames" / "frame_0001.exr"))["channels"]


def test_cli_synth_refuses_output_equal_to_an_input(cli_path, caches):
    style = caches / "paint.png"
    before = style.read_bytes()
    guide = caches / "cache" / "frame_0001.exr"
    result = subprocess.run([str(cli_path), "synth", "--style", str(style), "--guide", f"{guide}:FULL",
                             f"{guide}:FULL", "--output", str(style), "--quiet"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "is also an input" in result.stderr, result.stderr
    assert style.read_bytes() == before


# --------------------------------------------------------------------------- 5: shared folders

def _merge_frames(cache, worker, count):
    for i in range(count):
        frame = worker * 1000 + i
        guide_cache.update_manifest(cache, lambda m: m.setdefault("frames", {}).update(
            {str(frame): {"key": f"k{frame}"}}))


def test_concurrent_manifest_updates_lose_nothing(tmp_path):
    ctx = multiprocessing.get_context("spawn")
    workers = [ctx.Process(target=_merge_frames, args=(tmp_path, w, 40)) for w in range(3)]
    for p in workers:
        p.start()
    for p in workers:
        p.join(60)
        assert p.exitcode == 0
    assert len(guide_cache.read_manifest(tmp_path)["frames"]) == 120
    assert sorted(p.name for p in tmp_path.iterdir()) == ["manifest.json"]  # no lock or temporary file left


def test_manifest_update_waits_for_the_folder_lock(tmp_path):
    done = threading.Event()
    with guide_cache.manifest_lock(tmp_path):
        writer = threading.Thread(target=lambda: (_merge_frames(tmp_path, 0, 1), done.set()))
        writer.start()
        assert not done.wait(0.5)
    assert done.wait(10)


def test_stylize_record_is_merged_under_the_folder_lock(caches):
    """A second process holding the output folder's lock (flock) keeps a
    frame's record from being written until it lets go."""
    import fcntl

    j = job(caches, frames=[1])
    out = caches / "out"
    result = {}
    fd = os.open(out, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    worker = threading.Thread(target=lambda: result.update(r=j.run_frame(0)))
    worker.start()
    try:
        worker.join(3)
        assert worker.is_alive(), "the frame's record was written without taking the folder's lock"
    finally:
        os.close(fd)
    worker.join(30)
    assert result["r"]["status"] == "stylized"
    assert list(json.loads((out / "tempera_stylize.json").read_text())["frames"]) == ["1"]


def _stylize_some(folder, frames):
    j = StylizeJob(folder / "paint.png", folder / "exemplar", folder / "cache", frames, folder / "out", threads=1,
                   quality="preview")
    for i in range(len(frames)):
        j.run_frame(i)


def test_concurrent_stylize_runs_keep_every_record(tmp_path):
    make_cache(tmp_path / "cache", frames=range(1, 9))
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    ctx = multiprocessing.get_context("spawn")
    workers = [ctx.Process(target=_stylize_some, args=(tmp_path, frames))
               for frames in ([1, 3, 5, 7], [2, 4, 6, 8])]
    for p in workers:
        p.start()
    for p in workers:
        p.join(120)
        assert p.exitcode == 0
    report = json.loads((tmp_path / "out" / "tempera_stylize.json").read_text())
    assert sorted(map(int, report["frames"])) == list(range(1, 9))


def test_temporary_names_differ_between_processes_with_the_same_pid(tmp_path):
    """Two processes that are both PID 1 (PID namespaces, as in containers)
    write the same image names into one folder at once."""
    probe = subprocess.run(["unshare", "--pid", "--fork", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("unshare --pid is not permitted here")
    code = ("import os, numpy as np, tempera\n"
            "assert os.getpid() == 1\n"
            "a = np.zeros((64, 64, 3), np.float32)\n"
            f"for i in range(150): tempera.write_image('{tmp_path}/frame_%d.png' % (i % 3), a)\n")
    procs = [subprocess.Popen(["unshare", "--pid", "--fork", sys.executable, "-c", code],
                              env=dict(os.environ, PYTHONPATH=str(ADDON)), stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    errors = [p.communicate(timeout=120)[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], errors
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frame_0.png", "frame_1.png", "frame_2.png"]


# --------------------------------------------------------------------------- 7: threads

def test_absurd_thread_count_is_clamped_to_the_cores(caches):
    result = child(f"""
        from tempera.methods.stylit.stylize import StylizeJob
        j = StylizeJob({str(caches / 'paint.png')!r}, {str(caches / 'exemplar')!r}, {str(caches / 'cache')!r}, [1],
                       {str(caches / 'out')!r}, threads=4096, quality="preview")
        print(j.run_frame(0)["status"])
        """, timeout=120)
    assert result.returncode == 0 and "stylized" in result.stdout, result.stderr[-2000:]


# --------------------------------------------------------------------------- 8: frame ranges

def test_frame_ranges_are_bounded_by_blenders_last_frame(cli_path, caches):
    with pytest.raises(ValueError, match="outside 0-1048574"):
        parse_frames("1-99999999999")
    with pytest.raises(ValueError, match="outside"):
        parse_frames(f"{MAX_FRAME + 1}")
    assert parse_frames(f"{MAX_FRAME - 1}-{MAX_FRAME}") == [MAX_FRAME - 1, MAX_FRAME]
    for frames in ("1-2147483647", "2147483647", "1048575"):
        result = subprocess.run([str(cli_path), "stylize", "--guides", str(caches / "cache"), "--exemplar",
                                 str(caches / "paint.png"), "--exemplar-guides", str(caches / "exemplar"),
                                 "--frames", frames, "--out", str(caches / "o")],
                                capture_output=True, text=True, timeout=20)
        assert result.returncode == 2 and "outside 0-1048574" in result.stderr, (frames, result.stderr)
    with pytest.raises(ValueError, match="0 to 1048574"):
        job(caches, frames=[1, MAX_FRAME + 1])


def test_duplicate_check_of_a_million_frames_is_fast(caches):
    frames = list(range(MAX_FRAME)) + [7]
    start = time.monotonic()
    with pytest.raises(ValueError, match="frame 7 is listed twice"):
        job(caches, frames=frames)
    assert time.monotonic() - start < 10


# --------------------------------------------------------------------------- 9: memory

def _png_declaring(width, height):
    """A tiny PNG whose header declares width x height RGB pixels (its data is one empty row)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\x00")) + chunk(b"IEND", b""))


def _open_in_a_small_child(path):
    """read_image and image_info of `path` in a child with 1.2 GB of memory; each OSError printed."""
    return child(f"""
        import tempera
        for call in (tempera.read_image, tempera.image_info):
            try:
                call({str(path)!r})
            except OSError as exc:
                print("OSError:", exc)
        """, memory_mb=1200)


def test_declared_image_size_is_capped_before_allocating(tmp_path):
    bomb = tmp_path / "bomb.png"
    bomb.write_bytes(_png_declaring(12000, 12000))
    assert bomb.stat().st_size < 100
    result = _open_in_a_small_child(bomb)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.count("more than the limit of 50000000 pixels") == 2, result.stdout
    # The cap can be raised (then the file fails as the broken PNG it is, within memory).
    raised = child(f"""
        import tempera
        tempera.set_max_image_pixels(200_000_000)
        print(tempera.image_info({str(bomb)!r})["width"])
        """)
    assert raised.stdout.strip() == "12000", raised.stderr
    env = child(f"import tempera; print(tempera.max_image_pixels())", env={"TEMPERA_MAX_IMAGE_PIXELS": "1234"})
    assert env.stdout.strip() == "1234"
    with pytest.raises(ValueError):
        tempera.set_max_image_pixels(0)


def _tiff_declaring(width, height, channels):
    """A tiny 8-bit TIFF whose header declares width x height pixels of `channels` channels."""
    entries = [(256, width), (257, height), (258, 8), (259, 1), (262, 1), (273, None), (277, channels),
               (278, height), (279, 1), (284, 1)]
    data_offset = 8 + 2 + 12 * len(entries) + 4
    ifd = b"".join(struct.pack("<HHII", tag, 4, 1, data_offset if value is None else value) for tag, value in entries)
    return b"II*\x00" + struct.pack("<IH", 8, len(entries)) + ifd + struct.pack("<I", 0) + b"\x00"


def test_declared_channels_count_against_the_cap(tmp_path, cli_path):
    """1000x500 pixels pass the 50 Mpix cap, but 1024 channels of them decode to 2 GB."""
    bomb = tmp_path / "bomb.tif"
    bomb.write_bytes(_tiff_declaring(1000, 500, 1024))
    assert bomb.stat().st_size < 200
    result = _open_in_a_small_child(bomb)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.count("1000x500 pixels of 1024 channels, 2048 MB decoded, more than the limit") == 2, \
        result.stdout
    style = tmp_path / "style.png"
    tempera.write_image(str(style), np.full((8, 8, 3), 0.5, np.float32))
    cli = subprocess.run([str(cli_path), "synth", "--style", str(bomb), "--guide", str(style), str(style),
                          "--output", str(tmp_path / "out.png")], capture_output=True, text=True, timeout=60)
    assert cli.returncode == 1 and "1024 channels" in cli.stderr, cli.stderr
    # A guide frame's many channels fit: 64x48 pixels of 1024 channels are 12 MB.
    small = tmp_path / "small.tif"
    small.write_bytes(_tiff_declaring(64, 48, 1024))
    assert len(tempera.image_info(str(small))["channels"]) == 1024


def test_levels_have_an_upper_bound():
    style = np.zeros((16, 16, 3), np.float32)
    with pytest.raises(ValueError, match="levels"):
        tempera.synthesize(style, [(style, style, 1.0)], levels=1_000_000)


def test_contact_sheet_streams_downscaled_frames(caches):
    """16 frames of 1024x1024 float EXR: holding them all would take 200 MB."""
    frames = list(range(1, 17))
    make_cache(caches / "cache", frames=frames)
    out = caches / "out"
    out.mkdir()
    big = np.random.default_rng(0).random((1024, 1024, 3), dtype=np.float32)
    for f in frames:
        tempera.write_image(str(out / f"frame_{f:04d}.exr"), big)
    result = child(f"""
        import resource
        from tempera.methods.stylit.stylize import StylizeJob
        j = StylizeJob({str(caches / 'paint.png')!r}, {str(caches / 'exemplar')!r}, {str(caches / 'cache')!r},
                       {frames!r}, {str(out)!r}, format="exr")
        base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        j.write_contact_sheet({str(caches / 'sheet.png')!r})
        print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) // 1024)
        """, timeout=180)
    assert result.returncode == 0, result.stderr[-2000:]
    grown_mb = int(result.stdout.strip())
    assert grown_mb < 100, f"the contact sheet took {grown_mb} MB more"
    assert tempera.image_info(str(caches / "sheet.png"))["width"] <= 2000


# --------------------------------------------------------------------------- 10: singular camera

def test_singular_camera_matrix_is_a_value_error():
    result = child("""
        import numpy as np, tempera
        scene = {"vertices": np.array([[-9, -9, 0], [9, -9, 0], [0, 9, 0]], np.float32),
                 "triangles": np.array([[0, 1, 2]], np.int32), "triangle_materials": np.zeros(1, np.int32),
                 "materials": [{"base_color": [0.5] * 3, "specular": 0.0, "roughness": 1.0}],
                 "lights": [{"type": "sun", "direction": [0.0, 0.0, 1.0], "irradiance": [1.0] * 3}],
                 "world": {"radiance": [0.0, 0.0, 0.0]},
                 "camera": {"type": "perspective", "camera_to_world": np.zeros((4, 4), np.float32),
                            "width": 8, "height": 6, "tan_half_fov_x": 0.4, "tan_half_fov_y": 0.3}}
        try:
            tempera.trace_lpe(scene, ["LDE"], samples=1)
        except ValueError as exc:
            print("ValueError:", exc)
        """)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "ValueError:" in result.stdout and "singular" in result.stdout, result.stdout


# --------------------------------------------------------------------------- 11: integrity

def test_garbage_output_is_redone_and_the_sheet_still_works(caches):
    j = job(caches)
    for i in range(3):
        j.run_frame(i)
    frame = caches / "out" / "frame_0002.png"
    frame.write_bytes(b"not a png at all")
    again = job(caches)
    assert [again.run_frame(i)["status"] for i in range(3)] == ["skipped", "stylized", "skipped"]
    assert tempera.read_image(str(frame)).shape == (H, W, 3)
    again.write_contact_sheet(caches / "sheet.png")


def test_truncated_cache_frame_is_not_current(tmp_path):
    guide_cache.write_frame(tmp_path, 1, {"alpha": np.ones((32, 32))})
    manifest = {"frames": {"1": guide_cache.frame_entry(tmp_path, 1, "k")}}
    assert guide_cache.is_frame_current(tmp_path, manifest, 1, "k")
    path = guide_cache.frame_path(tmp_path, 1)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    assert not guide_cache.is_frame_current(tmp_path, manifest, 1, "k")
    assert not guide_cache.is_frame_current(tmp_path, manifest, 1, "k", verify=False)
    path.write_bytes(data[:-1] + bytes([data[-1] ^ 0xFF]))  # same size, other bytes
    assert not guide_cache.is_frame_current(tmp_path, manifest, 1, "k")


@pytest.mark.parametrize("text", ["{ broken", "[1, 2]", '{"format": 1, "frames": {"1": 5}}', "\xff\xfe"])
def test_damaged_manifest_is_set_aside_with_a_warning(tmp_path, text):
    (tmp_path / "manifest.json").write_bytes(text.encode("latin-1"))
    seen = []
    assert guide_cache.read_manifest(tmp_path, seen.append) is None
    assert len(seen) == 1 and "damaged" in seen[0] and "set aside" in seen[0]
    assert not (tmp_path / "manifest.json").exists()
    assert len(list(tmp_path.glob("manifest.json.corrupt-*"))) == 1
    guide_cache.update_manifest(tmp_path, lambda m: m.update(frames={"2": {"key": "k"}}))
    assert list(guide_cache.read_manifest(tmp_path)["frames"]) == ["2"]


@pytest.mark.parametrize("damage", ["garbage", "truncated", "old format"])
def test_damaged_stylize_record_is_set_aside_and_frames_redone(caches, damage):
    j = job(caches)
    for i in range(3):
        j.run_frame(i)
    record = caches / "out" / "tempera_stylize.json"
    text = record.read_text()
    record.write_text({"garbage": "\x00{{{", "truncated": text[: len(text) // 2],
                       "old format": text.replace("tempera-stylize 2", "tempera-stylize 1")}[damage])
    again = job(caches)
    assert [again.run_frame(i)["status"] for i in range(3)] == ["stylized"] * 3
    assert any("set aside" in w for w in again.warnings), again.warnings
    assert len(list((caches / "out").glob("tempera_stylize.json.corrupt-*"))) == 1
    assert sorted(json.loads(record.read_text())["frames"]) == ["1", "2", "3"]


# --------------------------------------------------------------------------- 12: messages

def test_manifest_is_as_readable_as_the_frames(tmp_path):
    old = os.umask(0o022)
    try:
        guide_cache.write_manifest(tmp_path, {"frames": {}})
        guide_cache.write_frame(tmp_path, 1, {"alpha": np.ones((2, 2))})
    finally:
        os.umask(old)
    modes = {p.name: p.stat().st_mode & 0o777 for p in tmp_path.iterdir()}
    assert modes == {"manifest.json": 0o644, "frame_0001.exr": 0o644}


def test_huge_frame_number_in_a_file_name_is_no_stoi_error(caches):
    shutil.copy(caches / "exemplar" / "frame_0001.exr", caches / "exemplar" / "frame_99999999999999.exr")
    assert job(caches).frames == [1, 2, 3]  # the only real frame of the exemplar cache is taken


def test_conversion_errors_name_the_option(caches):
    config = {"exemplar": str(caches / "paint.png"), "exemplar_guides": str(caches / "exemplar"),
              "guides": str(caches / "cache"), "frames": [1], "out": str(caches / "out")}
    for key, value, kind in (("frames", "1-3", "list of whole numbers"), ("format", 5, "string")):
        with pytest.raises(ValueError, match=f"{key} expects a {kind}"):
            _native.StylizeJobConfig(**dict(config, **{key: value}))
    for key, value in (("patch_size", "five"), ("temporal_weight", "high")):
        with pytest.raises(ValueError, match=f"{key} expects"):
            stylize.options(**{key: value})


def test_unreadable_file_is_reported_as_such(tmp_path):
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="tempera-perm-", dir="/tmp"))  # others may enter it
    folder.chmod(0o755)
    path = folder / "frame.exr"
    tempera.write_image(str(path), np.ones((4, 4, 3), np.float32))
    path.chmod(0)
    code = (f"import tempera\ntry:\n    tempera.read_image({str(path)!r})\nexcept OSError as exc:\n    print(exc)\n")
    if os.geteuid() == 0:  # root reads anything: run the reader as nobody
        if shutil.which("setpriv") is None:
            pytest.skip("no setpriv to drop root")
        tmp_path.chmod(0o755)
        command = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", sys.executable, "-c", code]
    else:
        command = [sys.executable, "-c", code]
    result = subprocess.run(command, capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ADDON)),
                            timeout=60)
    if "ModuleNotFoundError" in result.stderr or "Permission denied: '" in result.stderr:
        pytest.skip("the package is not readable by nobody here")
    shutil.rmtree(folder)
    assert "Permission denied" in result.stdout and "OpenEXR" not in result.stdout, result.stdout + result.stderr


def test_bad_values_exit_2_as_documented(cli_path, caches):
    base = ["stylize", "--guides", str(caches / "cache"), "--exemplar", str(caches / "paint.png"),
            "--exemplar-guides", str(caches / "exemplar"), "--frames", "1", "--out", str(caches / "o")]
    for extra, message in ((["--patch-size", "4"], "patch size must be odd"),
                           (["--format", "tiff"], "unknown output format"),
                           (["--threads", "-1"], "threads must be")):
        result = subprocess.run([str(cli_path), *base, *extra], capture_output=True, text=True, timeout=60)
        assert result.returncode == 2 and message in result.stderr, (extra, result.returncode, result.stderr)
    assert "2 bad usage or bad values" in subprocess.run([str(cli_path), "stylize", "--help"], capture_output=True,
                                                         text=True).stdout


def test_blender_that_fails_silently_is_reported(cli_path, tmp_path):
    scene = tmp_path / "scene.blend"
    scene.write_bytes(b"BLENDER")
    result = subprocess.run([str(cli_path), "render-guides", str(scene), "--frames", "1", "--out",
                             str(tmp_path / "g"), "--blender", "/bin/false"], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 1
    assert "'/bin/false') exited with status 1" in result.stderr, result.stderr


@pytest.mark.skipif(shutil.which("ffmpeg") is None, reason="needs ffmpeg")
def test_percent_in_the_output_folder_keeps_the_video(cli_path, caches):
    out = caches / "100%d done"
    result = subprocess.run([str(cli_path), "stylize", "--guides", str(caches / "cache"), "--exemplar",
                             str(caches / "paint.png"), "--exemplar-guides", str(caches / "exemplar"),
                             "--frames", "1-3", "--out", str(out), "--quality", "preview", "--threads", "2"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert (out / "stylized.mp4").stat().st_size > 0


def test_user_guide_shows_the_screenshots_the_script_takes():
    """docs/make_panel_screenshots.py makes every panel picture of the user guide."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("shots", ROOT / "docs" / "make_panel_screenshots.py")
    shots = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(shots)
    guide = (ROOT / "docs" / "user_guide.md").read_text()
    for name, _ in shots.SHOTS:
        assert f"images/{name}" in guide and (ROOT / "docs" / "images" / name).is_file()


def test_two_cli_runs_into_one_folder_are_safe(cli_path, caches):
    """A second `tempera stylize` into the same folder is made safe by the
    folder lock: both finish, every frame is whole and recorded once."""
    make_cache(caches / "cache", frames=range(1, 7))
    command = [str(cli_path), "stylize", "--guides", str(caches / "cache"), "--exemplar", str(caches / "paint.png"),
               "--exemplar-guides", str(caches / "exemplar"), "--frames", "1-6", "--out", str(caches / "shared"),
               "--quality", "preview", "--threads", "1", "--no-video"]
    runs = [subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outputs = [r.communicate(timeout=300) for r in runs]
    assert [r.returncode for r in runs] == [0, 0], outputs
    record = json.loads((caches / "shared" / "frames" / "tempera_stylize.json").read_text())
    assert sorted(map(int, record["frames"])) == list(range(1, 7))
    for f in range(1, 7):
        assert tempera.read_image(str(caches / "shared" / "frames" / f"frame_{f:04d}.png")).shape == (H, W, 3)
    again = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert "0 frame(s) stylized, 6 skipped" in again.stdout, again.stdout


def test_a_status_reader_leaves_a_damaged_manifest_in_place(tmp_path):
    (tmp_path / "manifest.json").write_text("{ broken")
    assert guide_cache.read_manifest(tmp_path, set_aside=False) is None
    assert (tmp_path / "manifest.json").read_text() == "{ broken"
