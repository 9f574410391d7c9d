"""`tempera synth`: the engine on files, as a render farm runs it."""
import json
import subprocess

import numpy as np

import tempera


def run(cli_path, *args):
    return subprocess.run([str(cli_path), "synth", *map(str, args)], capture_output=True, text=True, timeout=120)


def write_inputs(tmp_path):
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[0:48, 0:48].astype(np.float32) / 48
    style = rng.random((48, 48, 3), dtype=np.float32)
    source = np.stack([xx, yy, 0.5 * np.ones_like(xx)], -1)
    paths = {}
    for name, image in {"style": style, "src": source, "tgt": source, "tgt2": source[:, ::-1].copy()}.items():
        paths[name] = tmp_path / f"{name}.png"
        tempera.write_image(str(paths[name]), image)
    return paths


def test_synth_writes_output_and_stats(cli_path, tmp_path):
    p = write_inputs(tmp_path)
    out, stats = tmp_path / "out.png", tmp_path / "stats.json"
    result = run(cli_path, "--style", p["style"], "--guide", p["src"], p["tgt"], "--weight", 4,
                 "--usage", "none", "--output", out, "--stats", stats, "--quiet")
    assert result.returncode == 0, result.stderr
    image = tempera.read_image(str(out))
    style = tempera.read_image(str(p["style"]))
    assert image.shape == (48, 48, 3)
    assert np.abs(image - style)[6:-6, 6:-6].mean() < 2e-3  # guides equal -> the exemplar back
    report = json.loads(stats.read_text())
    assert report["usage"] == "none" and report["levels"][-1]["width"] == 48
    assert [f.name for f in tmp_path.iterdir() if ".tmp" in f.name] == []


def test_synth_defaults_are_budget_mode(cli_path, tmp_path):
    p = write_inputs(tmp_path)
    stats = tmp_path / "s.json"
    result = run(cli_path, "--style", p["style"], "--guide", p["src"], p["tgt2"], "--output",
                 tmp_path / "o.exr", "--stats", stats)
    assert result.returncode == 0, result.stderr
    assert "100%" in result.stderr
    assert json.loads(stats.read_text())["usage"] == "budget"
    assert tempera.read_image(str(tmp_path / "o.exr")).shape == (48, 48, 3)


def test_synth_errors_are_clear(cli_path, tmp_path):
    p = write_inputs(tmp_path)
    cases = [
        (["--style", p["style"], "--guide", p["src"], p["tgt"]], "--output is required"),
        (["--style", p["style"], "--weight", "2", "--guide", p["src"], p["tgt"], "--output", "x.png"],
         "--weight must follow a --guide pair"),
        (["--style", p["style"], "--guide", p["src"], p["tgt"], "--output", "x.png", "--frobnicate"],
         "unknown option '--frobnicate'"),
        (["--style", p["style"], "--guide", p["src"], p["tgt"], "--output", "x.png", "--usage", "sometimes"],
         "unknown patch usage 'sometimes'"),
        (["--style", tmp_path / "missing.png", "--guide", p["src"], p["tgt"], "--output", "x.png"],
         "missing.png"),
        (["--style", p["style"], "--guide", p["src"], p["tgt"], "--output", "x.png", "--patch-size", "five"],
         "--patch-size expects a number"),
    ]
    for args, message in cases:
        result = run(cli_path, *args)
        assert result.returncode != 0, args
        assert message in result.stderr, (args, result.stderr)
    assert not (tmp_path / "x.png").exists()


def test_synth_help(cli_path):
    result = run(cli_path, "--help")
    assert result.returncode == 0
    for flag in ("--style", "--guide", "--weight", "--usage", "--patch-size", "--levels", "--em-iters",
                 "--pm-iters", "--seed", "--threads", "--output", "--stats"):
        assert flag in result.stdout


def test_synth_reads_layers_of_multilayer_guide_files(cli_path, tmp_path):
    """Guides straight from guide-cache style EXRs: FILE:LAYER picks one layer."""
    p = write_inputs(tmp_path)
    source = tempera.read_image(str(p["src"]))
    frame = tmp_path / "frame_0001.exr"
    tempera.write_image(str(frame), np.dstack([source, source[..., :1] * 0]),
                        ["FULL.R", "FULL.G", "FULL.B", "lines.V"])
    out = tmp_path / "o.png"
    result = run(cli_path, "--style", p["style"], "--guide", f"{frame}:FULL", f"{frame}:FULL", "--weight", 4,
                 "--usage", "none", "--output", out, "--quiet")
    assert result.returncode == 0, result.stderr
    style = tempera.read_image(str(p["style"]))
    assert np.abs(tempera.read_image(str(out)) - style)[6:-6, 6:-6].mean() < 2e-3
    bad = run(cli_path, "--style", p["style"], "--guide", f"{frame}:LDE", f"{frame}:FULL", "--output", out)
    assert bad.returncode != 0 and "has no layer 'LDE' (it has: FULL, lines)" in bad.stderr
