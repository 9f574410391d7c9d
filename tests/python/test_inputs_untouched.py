"""Issue 31, items 3, 4 and 6: no command writes onto one of its inputs.

The job core's rule (app/job_inputs.hpp, docs/cli.md): a job writes only
files that it creates in its output folder. Each case below used to destroy
or pollute an input; each must now stop with exit status 2 before writing,
and leave the input byte for byte as it was."""
import os
import subprocess

import numpy as np
import pytest

import tempera
from tempera.app import guide_cache
from tempera.methods.stylit.stylize import StylizeJob

from synthetic_cache import make_cache, make_exemplar
from test_fluidymation import make_inputs

H, W = 24, 28


def stylize(cli_path, *args):
    return subprocess.run([str(cli_path), "stylize", *map(str, args)], capture_output=True, text=True, timeout=300)


def snapshot(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def rgba_exemplar(path, seed=1):
    rng = np.random.default_rng(seed)
    image = np.dstack([rng.random((16, 16, 3)), np.ones((16, 16))]).astype(np.float32)
    tempera.write_image(str(path), image)


@pytest.fixture()
def fluid_shot(tmp_path):
    """A LazyFluids shot laid out as render-guides lays it out: SHOT/frames/frame_0001.exr."""
    yy, xx = np.mgrid[0:H, 0:W]
    for f in (1, 2):
        alpha = np.clip(8 - np.hypot(xx - 10 - f, yy - H / 2), 0, 1).astype(np.float32)
        guide_cache.write_frame(tmp_path / "shot" / "frames", f,
                                {"alpha": alpha, "fluid_velocity": np.ones((H, W, 2), np.float32)})
    rgba_exemplar(tmp_path / "smoke.png")
    return tmp_path


def test_lazyfluids_refuses_an_output_whose_frames_folder_is_the_guides(cli_path, fluid_shot):
    guides = fluid_shot / "shot" / "frames"
    before = snapshot(guides)
    result = stylize(cli_path, "--method", "lazyfluids", "--guides", guides, "--exemplar", fluid_shot / "smoke.png",
                     "--frames", "1-2", "--out", fluid_shot / "shot", "--format", "exr", "--em-iters", "1")
    assert result.returncode == 2, result.stderr
    assert "is the guide cache folder" in result.stderr
    assert snapshot(guides) == before

    # The same through a symbolic link: OUT/frames points at the guides.
    (fluid_shot / "linked").mkdir()
    (fluid_shot / "linked" / "frames").symlink_to(guides)
    result = stylize(cli_path, "--method", "lazyfluids", "--guides", guides, "--exemplar", fluid_shot / "smoke.png",
                     "--frames", "1-2", "--out", fluid_shot / "linked", "--format", "exr", "--em-iters", "1")
    assert result.returncode == 2 and "is the guide cache folder" in result.stderr, result.stderr
    assert snapshot(guides) == before


def test_lazyfluids_refuses_a_video_exemplar_folder_as_output(cli_path, fluid_shot):
    video = fluid_shot / "video"
    video.mkdir()
    for i in range(2):
        rgba_exemplar(video / f"z_{i}.png", seed=i)
    before = snapshot(video)
    result = stylize(cli_path, "--method", "lazyfluids", "--guides", fluid_shot / "shot" / "frames", "--exemplar",
                     video, "--frames", "1-2", "--out", video, "--em-iters", "1")
    assert result.returncode == 2, result.stderr
    assert "is the exemplar folder" in result.stderr
    assert snapshot(video) == before and not (video / "frames").exists()


def test_fluidymation_refuses_the_exemplar_folder_as_output(cli_path, tmp_path):
    exemplar, cache = make_inputs(tmp_path, frames=2)
    before = snapshot(exemplar)
    result = stylize(cli_path, "--method", "fluidymation", "--guides", cache, "--exemplar", exemplar, "--frames",
                     "1-2", "--out", exemplar, "--levels", "1")
    assert result.returncode == 2, result.stderr
    assert "is the exemplar folder" in result.stderr
    assert snapshot(exemplar) == before and not (exemplar / "frames").exists()  # not even its output folder


def test_tcia_refuses_a_key_painting_kept_where_its_frame_goes(cli_path, tmp_path):
    make_cache(tmp_path / "cache", frames=(1, 2, 3, 4, 5), forward=True)
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    key = tmp_path / "out" / "frames" / "frame_0004.png"
    key.parent.mkdir(parents=True)
    key.write_bytes((tmp_path / "paint.png").read_bytes())
    before = key.read_bytes()
    result = stylize(cli_path, "--method", "tcia", "--guides", tmp_path / "cache", "--exemplar", tmp_path / "paint.png",
                     "--exemplar-guides", tmp_path / "exemplar", "--frames", "1-5", "--out", tmp_path / "out",
                     "--key", f"4={key}", "--levels", "1", "--no-video")
    assert result.returncode == 2, result.stderr
    assert "would overwrite the painting of keyframe 4" in result.stderr
    assert key.read_bytes() == before
    assert sorted(p.name for p in key.parent.iterdir()) == ["frame_0004.png"]


def test_a_hard_link_to_an_input_is_the_input(cli_path, tmp_path):
    """An output name that is a hard link to the painting (StyLit) or the medium
    (tempera noisy) would rewrite the input's bytes through the link."""
    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    (tmp_path / "out").mkdir()
    os.link(tmp_path / "paint.png", tmp_path / "out" / "frame_0002.png")
    before = (tmp_path / "paint.png").read_bytes()
    with pytest.raises(ValueError, match="would overwrite the painting"):
        StylizeJob(tmp_path / "paint.png", tmp_path / "exemplar", tmp_path / "cache", [1, 2, 3], tmp_path / "out")

    (tmp_path / "R").mkdir()
    tempera.write_image(str(tmp_path / "R" / "frame_0001.png"), np.full((20, 20, 3), 0.5, np.float32))
    os.link(tmp_path / "paint.png", tmp_path / "out" / "frame_0001.png")
    result = subprocess.run([str(cli_path), "noisy", "--exemplar", str(tmp_path / "paint.png"), "--reference",
                             str(tmp_path / "R"), "--out", str(tmp_path / "out"), "--frames", "1"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2, result.stderr
    assert "would overwrite the exemplar" in result.stderr
    assert (tmp_path / "paint.png").read_bytes() == before


def test_rigid_refuses_an_output_that_links_to_a_drawing(tmp_path, cli_path):
    """The rigid-body method keeps the rule too, from the CLI and the panel's job."""
    from tempera.methods import registry
    from test_cli_rigid import _cache, _exemplar

    (tmp_path / "ex").mkdir()
    (tmp_path / "cache").mkdir()
    _exemplar(tmp_path / "ex")
    _cache(tmp_path / "cache")
    drawing = tmp_path / "ex" / "drawn" / "0001.png"
    before = drawing.read_bytes()
    (tmp_path / "out" / "frames").mkdir(parents=True)
    (tmp_path / "out" / "frames" / "frame_0001.png").symlink_to(drawing)
    result = subprocess.run([str(cli_path), "stylize", "--method", "rigid", "--guides", str(tmp_path / "cache"),
                             "--exemplar", str(tmp_path / "ex"), "--out", str(tmp_path / "out"), "--frames", "1-2"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and "would overwrite the drawn exemplar frame" in result.stderr, result.stderr
    (tmp_path / "panel" / "frames").mkdir(parents=True)
    (tmp_path / "panel" / "frames" / "frame_0002.png").symlink_to(drawing)
    with pytest.raises(ValueError, match="would overwrite the drawn exemplar frame"):
        registry.make_job("rigid", tmp_path / "ex", tmp_path / "cache", [1, 2], tmp_path / "panel")
    assert drawing.read_bytes() == before
