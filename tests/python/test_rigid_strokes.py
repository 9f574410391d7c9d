"""Stroke re-synthesis of the rigid-body method (tempera.methods.rigid.rigid_strokes): the
drawn body's line re-made by the engine from a stroke exemplar on the
stroke-position guide takes the exemplar's look and stays on the line; with
the guide off the ink leaves the line (the test's own check that it is the
guide doing it)."""
import json
import subprocess

import numpy as np
import pytest

from tempera import _native
from tempera.engine import guides
from tempera.methods.rigid import rigid, rigid_strokes, rigid_tracks

W, H = 240, 160
BAND = 3.0  # px: ink this far from the drawn line still counts as on it


def _drawing(frame=12):
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 150, 0.6, 0.05, 30)
    return rigid.generated_exemplar(track, W, H)[frame]


def _measure(drawn, out):
    """(share of the ink farther than BAND px from the drawn line, ink mass
    ratio out / drawn, mean ink colour of out)."""
    band = guides.line_distance(drawn[:, :, 3] > 0.5, 10.0) * 10.0 <= BAND
    ink = out[:, :, 3]
    total = float(ink.sum())
    colour = (out[:, :, :3] * ink[:, :, None]).sum((0, 1)) / max(total, 1e-6)
    return float(ink[~band].sum()) / max(total, 1e-6), total / float(drawn[:, :, 3].sum()), colour


def test_strokes_take_the_exemplars_look_and_stay_on_the_line():
    drawn = _drawing()
    exemplar = rigid_strokes.generated_stroke_exemplar()
    out = rigid_strokes.resynthesize(drawn, exemplar, d_max=4, weight=4)
    outside, mass, colour = _measure(drawn, out)
    graphite = (drawn[:, :, :3] * drawn[:, :, 3:]).sum((0, 1)) / drawn[:, :, 3].sum()
    assert outside <= 0.03
    assert 0.5 <= mass <= 2.0
    # The look: the exemplar's blue brush pen, no longer the grey graphite.
    assert np.abs(colour - rigid_strokes.STROKE_COLOUR).max() < 0.05
    assert np.abs(colour - graphite).max() > 0.2
    # The guide off: the engine copies the exemplar's texture anywhere.
    off_outside, off_mass, _ = _measure(drawn, rigid_strokes.resynthesize(drawn, exemplar, d_max=4, weight=0))
    assert off_outside > 0.03 or off_mass < 0.5


def test_stroke_guide_and_bad_exemplars():
    drawn = _drawing()
    g = rigid_strokes.stroke_guide(drawn, 4.0)
    assert g.max() == 1.0 and g[drawn[:, :, 3] > 0.5].min() == 1.0 and g[0, 0] == 0.0
    with pytest.raises(ValueError, match="must be an RGBA image"):
        rigid_strokes.resynthesize(drawn, np.zeros((8, 8, 3), np.float32))
    with pytest.raises(ValueError, match="has no ink"):
        rigid_strokes.resynthesize(drawn, np.zeros((8, 8, 4), np.float32))
    with pytest.raises(FileNotFoundError, match="stroke exemplar 'nowhere.png' does not exist"):
        rigid_strokes.load_stroke_exemplar("nowhere.png")


def test_cli_strokes_option(tmp_path, cli_path):
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 150, 0.6, 0.05, 30)
    ex = tmp_path / "ex"
    rigid_tracks.write_tracks(ex, {"Ball": track}, 1, (0, 1.2))
    (ex / "drawn").mkdir()
    for i, d in enumerate(rigid.generated_exemplar(track, W, H)):
        _native.write_image(str(ex / "drawn" / f"{1 + i:04d}.png"), d, [])
    cache = tmp_path / "cache"
    target = _native.bouncing_ball((200, 30), (-3.0, 0), 14, 1.0, 150, 0.7, -0.05, 24)
    rigid_tracks.write_tracks(cache, {"Target": target}, 1, (0, 1.0))
    (cache / "manifest.json").write_text(json.dumps({"resolution": [W, H]}))

    def run(out, *extra):
        return subprocess.run([str(cli_path), "stylize", "--method", "rigid", "--guides", str(cache), "--exemplar",
                               str(ex), "--out", str(tmp_path / out), "--frames", "8-9", *extra],
                              capture_output=True, text=True, timeout=300)

    assert run("plain").returncode == 0 and run("strokes", "--strokes", "generated").returncode == 0
    for f in (8, 9):
        plain = _native.read_image(str(tmp_path / "plain" / "frames" / f"frame_{f:04d}.png"), None)
        made = _native.read_image(str(tmp_path / "strokes" / "frames" / f"frame_{f:04d}.png"), None)
        outside, mass, colour = _measure(plain, made)
        assert outside <= 0.03 and 0.5 <= mass <= 2.0
        assert np.abs(colour - rigid_strokes.STROKE_COLOUR).max() < 0.05
    bad = run("bad", "--strokes", str(tmp_path / "none.png"))
    assert bad.returncode == 1 and "none.png' does not exist" in bad.stderr
