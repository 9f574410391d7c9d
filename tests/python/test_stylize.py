"""tempera.methods.stylit.stylize: StyLit over a guide cache through the native StylizeJob."""
import json
import math

import numpy as np
import pytest

import tempera
from tempera import _native
from tempera.app import guide_cache
from tempera.engine.guides import tonemap
from tempera.methods.stylit import stylize
from tempera.methods.stylit.stylize import StylizeJob, stylize_frame

from conftest import assert_releases_gil
from synthetic_cache import H, W, light_paths, make_cache, make_exemplar


@pytest.fixture()
def inputs(tmp_path):
    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    return tmp_path


def job(p, **kwargs):
    return StylizeJob(p / "paint.png", p / "exemplar", p / "cache", [1, 2, 3], p / "out", **kwargs)


def leftovers(folder):
    return [f.name for f in folder.iterdir() if f.name.startswith(".") or ".tmp" in f.name]


def test_job_end_to_end_then_resume_skips(inputs):
    j = job(inputs, temporal_weight=1.0, threads=2)
    assert j.frames == [1, 2, 3] and j.warnings == []
    results = [j.run_frame(i) for i in range(3)]
    assert [r["status"] for r in results] == ["stylized"] * 3
    assert math.isnan(results[0]["flicker"]) and all(0 <= r["flicker"] < 0.2 for r in results[1:])
    for r in results:
        assert r["path"] == j.output_path(r["frame"]) == str(inputs / "out" / f"frame_{r['frame']:04d}.png")
        assert tempera.read_image(r["path"]).shape == (H, W, 3)
        assert 0 < r["source_coverage"] <= 1 and r["seconds"] > 0
    report = json.loads((inputs / "out" / "tempera_stylize.json").read_text())
    assert sorted(report["frames"]) == ["1", "2", "3"]

    again = job(inputs, temporal_weight=1.0, threads=2)
    skipped = [again.run_frame(i) for i in range(3)]
    assert [r["status"] for r in skipped] == ["skipped"] * 3
    assert skipped[1]["flicker"] == pytest.approx(results[1]["flicker"], rel=1e-6)
    assert leftovers(inputs / "out") == []

    sheet = inputs / "sheet.png"
    again.write_contact_sheet(sheet)
    assert tempera.image_info(str(sheet))["width"] == 2 * W + 4  # painting + 3 frames on a 2x2 grid


def test_changed_settings_redo_the_frames(inputs):
    j = job(inputs, threads=2)
    j.run_frame(0)
    assert job(inputs, threads=2, seed=5).run_frame(0)["status"] == "stylized"
    assert job(inputs, threads=2, seed=5, resume=False).run_frame(0)["status"] == "stylized"


def test_unknown_config_keys_are_named():
    with pytest.raises(ValueError, match="'colour'.*'speed'|'speed'.*'colour'"):
        _native.StylizeJobConfig(exemplar="a", exemplar_guides="b", guides="c", frames=[1], out="d", colour=1,
                                 speed=2)
    with pytest.raises(ValueError, match="unknown guide 'DIFFUSE'"):
        stylize.options(weights={"DIFFUSE": 1.0})
    with pytest.raises(TypeError, match="unknown stylit option 'colour'"):
        StylizeJob("a", "b", "c", [1], "d", colour=1)


def test_missing_files_and_guides_are_named(inputs):
    with pytest.raises(FileNotFoundError, match="nope.png"):
        StylizeJob(inputs / "nope.png", inputs / "exemplar", inputs / "cache", [1], inputs / "out")
    with pytest.raises(FileNotFoundError, match="frame\\(s\\) 7, 8"):
        StylizeJob(inputs / "paint.png", inputs / "exemplar", inputs / "cache", [1, 7, 8], inputs / "out")
    with pytest.raises(ValueError, match="guide 'LD12E' missing from '.*frame_0001.exr'"):
        job(inputs, weights={"LD12E": 1.0})
    guide_cache.write_frame(inputs / "exemplar", 2, light_paths(10))
    with pytest.raises(ValueError, match="Exemplar Frame"):
        job(inputs)
    assert job(inputs, exemplar_frame=1).frames == [1, 2, 3]


def test_run_frame_releases_the_gil(inputs):
    j = job(inputs, threads=1, resume=False)
    assert_releases_gil(lambda: [j.run_frame(i) for i in range(3)])


def test_cancel_from_progress_leaves_no_file(inputs):
    j = job(inputs, threads=2)
    seen = []

    def progress(fraction):
        seen.append(fraction)
        return len(seen) < 3

    with pytest.raises(tempera.Cancelled):
        j.run_frame(0, progress)
    assert len(seen) == 3
    out = inputs / "out"
    assert not (out / "frame_0001.png").exists() and leftovers(out) == []
    assert j.run_frame(0, lambda f: None)["status"] == "stylized"  # None means "go on"


def test_stylize_frame_in_memory_and_tonemap():
    rng = np.random.default_rng(0)
    guides = light_paths(W / 2)
    style = rng.random((H, W, 3), dtype=np.float32)
    image, stats = stylize_frame(style, guides, guides, usage="none", threads=2)
    assert image.shape == (H, W, 3) and stats["seconds"] > 0
    assert np.abs(image - style)[6:-6, 6:-6].mean() < 0.02
    velocity = np.zeros((H, W, 2), np.float32)
    warm, _ = stylize_frame(style, guides, guides, previous=image, velocity_backward=velocity,
                            occlusion_backward=np.ones((H, W)), temporal_weight=1.0, threads=2)
    assert warm.shape == image.shape
    linear = np.array([[[-1.0, 0.0, 0.002], [0.5, 4.0, np.nan]]], np.float32)
    np.testing.assert_allclose(_native.tonemap_guide(linear), tonemap(linear), atol=1e-7)


def test_frames_split_over_machines_stay_current(inputs):
    def split_job(frames):
        return StylizeJob(inputs / "paint.png", inputs / "exemplar", inputs / "cache", frames, inputs / "out",
                          temporal_weight=0.5, threads=2)

    for frames in ([1, 2], [3]):  # two machines, one shared output folder
        j = split_job(frames)
        assert [j.run_frame(i)["status"] for i in range(len(frames))] == ["stylized"] * len(frames)
    whole = split_job([1, 2, 3])
    assert [whole.run_frame(i)["status"] for i in range(3)] == ["skipped"] * 3


def test_tonemap_values():
    from tempera.engine.color import linear_to_srgb

    x = np.array([0.0, 1.0, 3.0, 1e9], dtype=np.float32)
    expected = linear_to_srgb(np.array([0.0, 0.5, 0.75, 1.0]))
    np.testing.assert_allclose(tonemap(x), expected, atol=1e-5)
    np.testing.assert_array_equal(tonemap(np.array([-1.0, np.nan])), [0.0, 0.0])
    ramp = tonemap(np.linspace(0.0, 50.0, 2001))
    assert np.all(np.diff(ramp) > 0)  # strictly increasing: highlights stay distinct
    image = np.random.default_rng(0).uniform(0, 3, (4, 5, 3)).astype(np.float32)
    np.testing.assert_array_equal(tonemap(image)[1:3, 2:4], tonemap(image[1:3, 2:4]))  # per pixel


def test_one_guide_table_everywhere():
    """Names, expressions and default weights of the light-path guides come
    from the native table alone."""
    import tempera
    from tempera.app import guide_cache, settings
    from tempera.tracer import lpe
    from tempera.methods.stylit import stylize

    table = tempera._native.light_path_guides()
    names = [g["name"] for g in table]
    assert list(stylize.GUIDES) == names and names == ["FULL", "LDE", "LSE", "LDDE", "LD12E"]
    assert stylize.DEFAULT_WEIGHTS == settings.DEFAULT_GUIDE_WEIGHTS == {g["name"]: g["weight"] for g in table}
    assert lpe.LIGHT_PATH_EXPRESSIONS["LDDE"] == "L.*DDE" and set(lpe.LIGHT_PATH_EXPRESSIONS) == set(names)
    assert all(guide_cache.GUIDES[n] == "RGB" for n in names)
    assert settings.SEED_DEFAULT == tempera.SynthesisOptions().seed == 1


def test_stylit_options_are_a_typed_class():
    """Issue 41, step 6: StyLit's options cross the binding as a bound class,
    with the guide weights as a dict in matching order and the engine's options."""
    opts = stylize.options(weights={"LDE": 3.0, "LDDE": 0}, temporal_weight=0.25, quality="preview", seed=7)
    assert list(opts.weights) == list(stylize.GUIDES)
    assert opts.weights == dict(stylize.DEFAULT_WEIGHTS, LDE=3.0, LDDE=0.0)
    assert (opts.temporal_weight, opts.quality, opts.synthesis.seed) == (0.25, "preview", 7)
    assert "temporal_weight=0.25" in repr(opts)
    opts.weights = {"FULL": 0}  # the named guide; the others keep theirs
    assert (opts.weights["FULL"], opts.weights["LDE"]) == (0.0, 3.0)
    opts.weights = {"LDE": 0, "LSE": 0, "LDDE": 0, "LD12E": 0}
    with pytest.raises(ValueError, match="guide"):  # every guide left out
        opts.validate()
    with pytest.raises(ValueError, match="temporal"):
        stylize.options(temporal_weight=-1)


def test_warm_start_carries_the_matches_along_the_motion():
    """A warm frame starts from the previous frame's matches moved along the
    motion: most of its matches are those, where a cold frame finds its own.
    Flat guides and no temporal guide leave every placement of the painting
    equally good, so only the start decides. (With the temporal guide a cold
    frame finds most of them too: 84% here.)"""
    rng = np.random.default_rng(1)
    style = rng.random((H, W, 3), dtype=np.float32)
    first_guides = next_guides = {k: np.full((H, W, 3), 0.5, np.float32) for k in light_paths(W / 2)}
    velocity = np.zeros((H, W, 2), np.float32)
    velocity[..., 0] = 2.0
    visible = np.ones((H, W), np.float32)
    image, stats = stylize_frame(style, first_guides, first_guides, threads=2)
    assert stats["field"].shape == (H, W, 2) and stats["field"].dtype == np.float32
    advected = np.roll(stats["field"], 2, axis=1)  # p - V-(p): two pixels to the left

    def held(field):  # interior matches within a pixel of the advected ones
        return float((np.abs(field - advected).max(axis=2) <= 1.0)[4:-4, 8:-8].mean())

    common = dict(previous=image, velocity_backward=velocity, occlusion_backward=visible, temporal_weight=0.0,
                  threads=2)
    _, warm = stylize_frame(style, first_guides, next_guides, previous_field=stats["field"], warm_start="on",
                            **common)
    _, cold = stylize_frame(style, first_guides, next_guides, warm_start="off", **common)
    assert held(warm["field"]) > 0.9 and held(cold["field"]) < 0.1
    # The warm frame solves the finest level alone, for 2 EM iterations; the cold one the pyramid.
    assert [(s.width, len(s.energy)) for s in warm["levels"]] == [(W, 2)] and len(cold["levels"]) > 1
    with pytest.raises(ValueError, match="field"):
        stylize_frame(style, first_guides, next_guides, previous_field=stats["field"][:-1], warm_start="on",
                      **common)


def test_warm_start_job_resumes_like_an_uninterrupted_run(inputs):
    whole = job(inputs, temporal_weight=0.5, warm_start="on", threads=2)
    assert [whole.run_frame(i)["status"] for i in range(3)] == ["stylized"] * 3
    fields = inputs / "out" / "tempera_stylize"
    assert sorted(f.name for f in fields.iterdir()) == [f"field_000{f}.exr" for f in (1, 2, 3)]
    uninterrupted = [tempera.read_image(whole.output_path(f)) for f in (1, 2, 3)]

    cold = StylizeJob(inputs / "paint.png", inputs / "exemplar", inputs / "cache", [1, 2, 3], inputs / "cold",
                      temporal_weight=0.5, warm_start="off", threads=2)
    [cold.run_frame(i) for i in range(3)]
    assert np.abs(tempera.read_image(cold.output_path(3)) - uninterrupted[2]).max() > 0.05  # the warm start counts
    assert not (inputs / "cold" / "tempera_stylize").exists()
    # auto, the default, warm-starts only with the temporal guide.
    for weight, warm, warm_started in ((0.0, "auto", False), (0.0, "on", True), (0.5, None, True),
                                       (0.0, None, False)):
        j = StylizeJob(inputs / "paint.png", inputs / "exemplar", inputs / "cache", [1, 2],
                       inputs / f"t{weight}{warm}", temporal_weight=weight, warm_start=warm, threads=2)
        [j.run_frame(i) for i in range(2)]
        assert (inputs / f"t{weight}{warm}" / "tempera_stylize").exists() == warm_started, (weight, warm)

    # Interrupted after frame 2 (frame 3 and its matches gone), then resumed.
    (inputs / "out" / "frame_0003.png").unlink()
    (fields / "field_0003.exr").unlink()
    resumed = job(inputs, temporal_weight=0.5, warm_start="on", threads=2)
    assert [resumed.run_frame(i)["status"] for i in range(3)] == ["skipped", "skipped", "stylized"]
    np.testing.assert_array_equal(tempera.read_image(resumed.output_path(3)), uninterrupted[2])
    # A frame whose matches are gone is made again: the next one starts from them.
    (fields / "field_0002.exr").unlink()
    again = job(inputs, temporal_weight=0.5, warm_start="on", threads=2)
    assert again.run_frame(1)["status"] == "stylized" and (fields / "field_0002.exr").exists()
    # auto (the default) with the temporal guide is the same warm start; switched off, the frames are made
    # again, cold.
    for warm in ("auto", None):
        auto = job(inputs, temporal_weight=0.5, warm_start=warm, threads=2)
        assert [auto.run_frame(i)["status"] for i in range(3)] == ["skipped"] * 3, warm
    assert job(inputs, temporal_weight=0.5, warm_start="off", threads=2).run_frame(1)["status"] == "stylized"
