"""Temporal Noise (Color Me Noisy) on a scene made the way a new user makes
one, only with Blender's own operators and their defaults
(scenes/noisy_turning_suzanne.py: a subdivided Suzanne turning beside a
torus on a plane, a sun, a camera moving sideways, default materials), with
the bundled exemplar kit. The slider runs from the panel's operator (StyLit
per frame, R, then the noise pass) and the CLI (`tempera stylize --noise F`)
on the same guide cache: the CLI's frames are the panel's, every frame keeps
R's large shapes (box_f RMSE <= 0.05, the issue's bound), consecutive frames
differ, and a larger f boils more (the motion-compensated temporal energy)."""
import os
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest
from guide_scene import remove_scene

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "scenes"))
import noisy_turning_suzanne  # noqa: E402

SCENE = "Noisy user scene"
SIZE = (128, 96)
FRAMES = (3, 7)
LOW, HIGH = 1, 8  # Temporal Noise steps: f = 1.3 and 4.3


@pytest.fixture
def user_scene(tmp_path):
    scene = bpy.data.scenes.new(SCENE)
    shown = bpy.context.window.scene
    bpy.context.window.scene = scene
    noisy_turning_suzanne.build(scene, SIZE)
    settings = scene.tempera
    settings.exemplar_source = "KIT"  # the default, said aloud
    settings.output_dir, settings.guide_dir = str(tmp_path / "out"), str(tmp_path / "guides")
    settings.guide_frame_range = "CUSTOM"
    settings.guide_frame_start, settings.guide_frame_end = FRAMES
    settings.guide_samples = 2
    settings.quality = "preview"
    settings.temporal_weight = 0.5
    settings.make_video = False
    settings.load_result = "NONE"
    yield scene
    bpy.context.window.scene = shown
    remove_scene(scene)


def _frames(folder):
    import tempera

    return [tempera.read_image(str(folder / f"frame_{f:04d}.png")) for f in range(FRAMES[0], FRAMES[1] + 1)]


def _energy(frames, guides):
    """Non-DC temporal power along the rendered motion (tempera.engine.temporal)."""
    from tempera.app import guide_cache
    from tempera.engine import temporal

    motion = [guide_cache.read_frame(guides, f, ["velocity_forward", "occlusion_forward"])
              for f in range(FRAMES[0], FRAMES[1] + 1)]
    return temporal.noise_energy(temporal.temporal_power_spectrum(
        frames, [m["velocity_forward"] for m in motion], [m["occlusion_forward"] for m in motion]))


def test_temporal_noise_from_the_panel_and_the_cli(user_scene, tmp_path):
    from tempera.methods.noisy import noisy
    from tempera.engine import temporal
    from tempera.app.exemplar_kit import kit_exemplar

    settings = user_scene.tempera
    settings.noise_level = HIGH
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    out, guides = tmp_path / "out", tmp_path / "guides"
    coherent, high = _frames(out / "frames"), _frames(out / "noisy")
    f_high = noisy.noise_width(HIGH)
    for i, (t, r) in enumerate(zip(high, coherent)):
        assert temporal.box_consistency_error(t, r, f_high) <= 0.05, i  # R's large shapes kept
        assert np.abs(t - r).mean() > 0.003, i                          # and the noise pass changed it
    for i in range(len(high) - 1):  # consecutive frames differ, by more than R's motion alone makes them
        boil, moved = np.abs(high[i] - high[i + 1]).mean(), np.abs(coherent[i] - coherent[i + 1]).mean()
        print(f"frames {i}-{i + 1}: mean |T - T'| {boil:.4f}, |R - R'| {moved:.4f}")
        assert boil > moved > 0, (i, boil, moved)

    # The CLI on the same guide cache, with the panel's settings: the same frames.
    style, exemplar_guides = kit_exemplar()
    cli_out = tmp_path / "cli"
    cli = os.environ.get("TEMPERA_CLI") or str(Path(__file__).resolve().parents[1] / "build" / "bin" / "tempera")
    run = subprocess.run([cli, "stylize", "--guides", str(guides), "--exemplar", str(style), "--exemplar-guides",
                          str(exemplar_guides), "--frames", f"{FRAMES[0]}-{FRAMES[1]}", "--out", str(cli_out),
                          "--quality", "preview", "--temporal", "0.5", "--no-video", "--noise", str(f_high)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    for i, (c, p) in enumerate(zip(_frames(cli_out / "frames"), coherent)):
        np.testing.assert_array_equal(c, p, err_msg=f"coherent frame {i}")
    for i, (c, p) in enumerate(zip(_frames(cli_out / "noisy"), high)):
        np.testing.assert_array_equal(c, p, err_msg=f"noisy frame {i}")

    # A smaller width boils less (the coherent frames are current: only the noise pass runs).
    settings.noise_level = LOW
    assert bpy.ops.tempera.stylize(mode="ANIMATION") == {"FINISHED"}
    low = _frames(out / "noisy")
    e_r, e_low, e_high = _energy(coherent, guides), _energy(low, guides), _energy(high, guides)
    print(f"temporal energy: R {e_r:.5f}, f=1.3 {e_low:.5f}, f=4.3 {e_high:.5f}; box RMSE at 4.3: "
          + ", ".join(f"{temporal.box_consistency_error(t, r, f_high):.4f}" for t, r in zip(high, coherent)))
    assert e_r < e_low < e_high, (e_r, e_low, e_high)
