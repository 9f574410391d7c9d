"""`tempera stylize --method tcia --layer NAME=MASK[,PAINTING]`: layers solved
separately (Bénard 2013 Fig. 10), written RGBA, composited; resumable per
layer and segment; bad layers named."""
import signal
import subprocess

import numpy as np
import pytest

import tempera
from synthetic_cache import H, W, layer_masks, make_cache, make_exemplar, write_frame
from test_cli_stylize import stylize

FRAMES = range(1, 5)
START, SPEED = 20.0, 2.0  # make_cache's defaults: the blob's centre at frame 1 and its motion


@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    p = tmp_path_factory.mktemp("tcia_layers")
    make_cache(p / "cache", frames=tuple(FRAMES), forward=True, masks=True)
    make_exemplar(p / "exemplar", p / "paint.png")
    write_frame(p / "exemplar", 1, W / 2, 0.0, masks=True)  # the exemplar's own layer masks
    paint = tempera.read_image(str(p / "paint.png"))
    tempera.write_image(str(p / "blue.png"), paint[:, :, ::-1].copy())  # the blob's own painting
    return p


def args(p, out, *extra):
    return ("--method", "tcia", "--guides", p / "cache", "--exemplar", p / "paint.png", "--exemplar-guides",
            p / "exemplar", "--frames", "1-4", "--out", p / out, "--levels", "2", "--patch-size", "7",
            "--no-video", *extra)


def layers(p):
    return ("--layer", f"blob=mask.CO_Blob,{p / 'blue.png'}", "--layer", "rest=mask.CO_Rest")


def files(p, out):
    root = p / out / "frames"
    return {str(f.relative_to(root)): f.read_bytes() for f in sorted(root.rglob("frame_*.png"))}


def run_layered(cli_path, p):
    if not (p / "layered" / "frames" / "frame_0004.png").is_file():
        result = stylize(cli_path, *args(p, "layered", *layers(p), "--threads", "2"))
        assert result.returncode == 0, result.stderr
        assert "1 segment(s) stylized" in result.stdout
    return files(p, "layered")


def test_each_layer_is_written_rgba_and_the_frames_are_their_composite(cli_path, shot):
    made = run_layered(cli_path, shot)
    assert sorted(made) == sorted([f"frame_{f:04d}.png" for f in FRAMES] +
                                  [f"layers/{n}/frame_{f:04d}.png" for n in ("blob", "rest") for f in FRAMES])
    for i, f in enumerate(FRAMES):
        masks = layer_masks(START + SPEED * i)
        blob = tempera.read_image(str(shot / "layered" / "frames" / "layers" / "blob" / f"frame_{f:04d}.png"))
        rest = tempera.read_image(str(shot / "layered" / "frames" / "layers" / "rest" / f"frame_{f:04d}.png"))
        out = tempera.read_image(str(shot / "layered" / "frames" / f"frame_{f:04d}.png"))
        assert blob.shape == (H, W, 4) and out.shape[2] == 3
        np.testing.assert_array_equal(blob[:, :, 3], masks["mask.CO_Blob"])  # alpha: the layer's mask
        inside = masks["mask.CO_Blob"] > 0.5
        # Exclusive masks: the composite is each layer on its own pixels.
        assert np.abs(out[inside] - blob[inside][:, :3]).max() <= 1e-6
        assert np.abs(out[~inside] - rest[~inside][:, :3]).max() <= 1e-6
        # The blob's own painting (the channels swapped) is what paints the blob.
        assert blob[inside][:, 2].mean() > blob[inside][:, 0].mean()
        assert rest[~inside][:, 0].mean() > rest[~inside][:, 2].mean()
        # Each layer's matches come from its part of the exemplar (the exemplar cache's same mask).
        for layer, painting, part in ((blob, "blue.png", "mask.CO_Blob"), (rest, "paint.png", "mask.CO_Rest")):
            source = tempera.read_image(str(shot / painting))[layer_masks(W / 2)[part] > 0.5]
            allowed = {tuple(c) for c in np.round(source * 255).astype(int)}
            used = {tuple(c) for c in np.round(layer[:, :, :3].reshape(-1, 3) * 255).astype(int)}
            assert used <= allowed, (painting, len(used - allowed))


def test_resume_per_layer_equals_an_uninterrupted_run(cli_path, shot):
    layered = run_layered(cli_path, shot)
    cmd = [str(cli_path), "stylize", *map(str, args(shot, "resumed", *layers(shot), "--threads", "1"))]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:  # the second layer under way (each layer is half of the segment)
        if "sweep" in line and int(line.split("%")[0].split()[-1]) > 55:
            proc.send_signal(signal.SIGTERM)
            break
    proc.stdout.read()
    assert proc.wait(timeout=120) == 130
    kept = files(shot, "resumed")
    assert sorted(kept) == [f"layers/blob/frame_{f:04d}.png" for f in FRAMES]  # the first layer, whole
    mtimes = {f: (shot / "resumed" / "frames" / "layers" / "blob" / f"frame_{f:04d}.png").stat().st_mtime_ns
              for f in FRAMES}
    again = stylize(cli_path, *args(shot, "resumed", *layers(shot), "--threads", "1"))
    assert again.returncode == 0, again.stderr
    assert files(shot, "resumed") == layered  # and 1 thread equals 2
    assert all((shot / "resumed" / "frames" / "layers" / "blob" / f"frame_{f:04d}.png").stat().st_mtime_ns == t
               for f, t in mtimes.items())  # the finished layer was not solved again
    assert "0 segment(s) stylized, 1 skipped" in stylize(cli_path, *args(shot, "resumed", *layers(shot))).stdout
    # Another order only re-composites; another painting of one layer redoes that layer only.
    given = stylize(cli_path, *args(shot, "resumed", *layers(shot), "--layer-order", "given"))
    assert given.returncode == 0 and "1 segment(s) stylized" in given.stdout
    assert all((shot / "resumed" / "frames" / "layers" / "blob" / f"frame_{f:04d}.png").stat().st_mtime_ns == t
               for f, t in mtimes.items())


@pytest.mark.parametrize("extra, message", [
    (("--layer", "blob"), "--layer expects NAME=MASK_GUIDE[,PAINTING], got 'blob'"),
    (("--layer", "a/b=mask.CO_Blob"), "layer name 'a/b' must be letters"),
    (("--layer", "x=mask.CO_Blob", "--layer", "x=mask.CO_Rest"), "layer 'x' is given twice"),
    (("--layer", "x=mask.CO_Nothing"), "layer 'x' needs the mask 'mask.CO_Nothing' in"),
    (("--layer", "x=mask.CO_Blob,SMALL"), "the painting of layer 'x'"),
    (("--layer", "x=mask.CO_Blob", "--layer-order", "size"), "the layer order must be 'depth' or 'given'"),
    (("--layer", "x=mask.CO_Blob", "--method", "stylit"), "--layer needs --method tcia"),
])
def test_bad_layers_name_the_problem(cli_path, shot, extra, message):
    small = shot / "small.png"
    tempera.write_image(str(small), np.zeros((H // 2, W // 2, 3), np.float32))
    extra = [e.replace("SMALL", str(small)) for e in extra]
    result = stylize(cli_path, *args(shot, "bad", *extra))
    assert result.returncode == 2 and message in result.stderr, result.stderr
    assert not (shot / "bad" / "frames" / "layers").exists()


def _key_painting(p):
    """A key for frame 3 that differs from anything the sweeps make alone: the
    blob's painting rolled and flipped, at the frames' size."""
    path = p / "key3.png"
    if not path.is_file():
        paint = tempera.read_image(str(p / "paint.png"))
        tempera.write_image(str(path), np.roll(paint, 9, axis=1)[::-1].copy())
    return path


def test_a_shot_key_survives_the_layer_composite(cli_path, shot):
    """Overpaint kept: with layers, the key frame's composite is the painting
    (within 1/255) on every painted pixel, and the frame after it still
    differs from it (the key is not copied forward)."""
    key = _key_painting(shot)
    result = stylize(cli_path, *args(shot, "layered_key", *layers(shot), "--key", f"3={key}"))
    assert result.returncode == 0, result.stderr
    assert "2 segment(s) stylized" in result.stdout, result.stdout
    painting = tempera.read_image(str(key))[:, :, :3]
    out = tempera.read_image(str(shot / "layered_key" / "frames" / "frame_0003.png"))[:, :, :3]
    assert np.abs(out - painting).max() <= 1 / 255 + 1e-6
    after = tempera.read_image(str(shot / "layered_key" / "frames" / "frame_0004.png"))[:, :, :3]
    assert np.abs(after - painting).mean() > 0.02


def test_a_layer_key_paints_only_its_layer(cli_path, shot):
    """--layer-key blob:3=...: the blob's own key. At frame 3 the composite is
    the painting on the blob's pixels (within 1/255: the blob is in front),
    the rest keeps its own solve (no key there), and the shot splits at 3."""
    key = _key_painting(shot)
    result = stylize(cli_path, *args(shot, "layer_key", *layers(shot), "--layer-key", f"blob:3={key}"))
    assert result.returncode == 0, result.stderr
    assert "2 segment(s) stylized" in result.stdout, result.stdout
    painting = tempera.read_image(str(key))[:, :, :3]
    out = tempera.read_image(str(shot / "layer_key" / "frames" / "frame_0003.png"))[:, :, :3]
    blob = layer_masks(START + SPEED * 2)["mask.CO_Blob"] == 1
    assert blob.sum() > 50
    assert np.abs(out[blob] - painting[blob]).max() <= 1 / 255 + 1e-6
    assert np.abs(out[~blob] - painting[~blob]).mean() > 0.02  # not a shot-wide key
    run_layered(cli_path, shot)  # the same layers without the layer key: the blob is not the painting
    plain = tempera.read_image(str(shot / "layered" / "frames" / "frame_0003.png"))[:, :, :3]
    assert np.abs(plain[blob] - painting[blob]).mean() > 0.02


@pytest.mark.parametrize("value, message", [
    ("blob3=k.png", "--layer-key expects NAME:FRAME=PAINTING[,MASK]"),
    ("nobody:3=KEY", "--layer-key names layer 'nobody', which no --layer gives"),
])
def test_bad_layer_keys_name_the_problem(cli_path, shot, value, message):
    result = stylize(cli_path, *args(shot, "bad_layer_key", *layers(shot), "--layer-key",
                                     value.replace("KEY", str(_key_painting(shot)))))
    assert result.returncode == 2 and message in result.stderr, result.stderr
