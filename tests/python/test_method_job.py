"""Any method with a job factory runs from Python with no binding of its own
(issue 41): tempera.methods.registry.make_job gives the one _native.FrameJob
that `tempera stylize --method NAME` runs, and every per-frame job's class
derives from it."""
import numpy as np
import pytest

import tempera
from tempera import _native, read_image
from tempera.app import guide_cache
from tempera.methods import registry
from tempera.methods.lazyfluids import lazyfluids
from tempera.methods.stylit.stylize import StylizeJob

from synthetic_cache import make_cache, make_exemplar

H, W = 32, 40


def smoke(n=20, seed=3):
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:n, 0:n]
    alpha = np.clip((0.42 * n - np.hypot(xx - (n - 1) / 2, yy - (n - 1) / 2)) / 1.5, 0, 1)
    return np.dstack([rng.random((n, n, 3)), alpha]).astype(np.float32)


@pytest.fixture()
def shot(tmp_path):
    yy, xx = np.mgrid[0:H, 0:W]
    for f in range(1, 4):
        alpha = np.clip(10 - np.hypot(xx - 14 - 2 * f, yy - H / 2) + 0.5, 0, 1).astype(np.float32)
        flow = np.zeros((H, W, 2), np.float32)
        flow[..., 0] = 2.0
        guide_cache.write_frame(tmp_path / "guides", f, {"alpha": alpha, "fluid_velocity": flow})
    tempera.write_image(str(tmp_path / "smoke.png"), smoke())
    return tmp_path


def test_the_registry_says_which_methods_have_a_job_factory():
    jobs = {m["name"] for m in registry.METHODS if m["job"]}
    assert {m["name"] for m in registry.METHODS} == jobs  # the rigid-body method's too (issue 41)
    assert "--lambda" in registry.find("lazyfluids")["options_help"]
    for job_class in (_native.StylizeJob, _native.NoisySequence, _native.LazyFluidsJob, _native.FluidymationJob):
        assert issubclass(job_class, _native.FrameJob)
    assert issubclass(_native.TciaJob, _native.SegmentJob)


def test_lazyfluids_by_the_registry_equals_its_own_class(shot):
    """The same options given as the command line's flags and as the class's
    keywords give the same frames, byte for byte."""
    own = lazyfluids.FluidJob(shot / "smoke.png", shot / "guides", [1, 2, 3], shot / "own", em_iterations=2,
                              threads=2, temporal_weight=0.35, motion_blur=2.5, rotations=True)
    job = registry.make_job("lazyfluids", shot / "smoke.png", shot / "guides", [1, 2, 3], shot / "by_registry",
                            options={"em-iters": 2, "threads": 2, "lambda": 0.35, "motion_blur": 2.5,
                                     "rotations": True})
    assert job.frames == [1, 2, 3] and job.has_contact_sheet
    for i, frame in enumerate(job.frames):
        assert job.run_frame(i)["status"] == own.run_frame(i)["status"] == "stylized"
        assert np.array_equal(read_image(job.output_path(frame)), read_image(own.output_path(frame)))
    assert job.output_path(1).startswith(str(shot / "by_registry" / "frames"))  # as the command's OUT/frames
    assert [job.run_frame(i)["status"] for i in range(3)] == ["skipped"] * 3  # resume
    job.write_contact_sheet(shot / "sheet.png")
    assert read_image(str(shot / "sheet.png")).shape[1] > W


def test_a_registered_job_cancels_and_names_bad_options(shot):
    job = registry.make_job("lazyfluids", shot / "smoke.png", shot / "guides", [1, 2], shot / "out",
                            options={"em-iters": 1})
    with pytest.raises(tempera.Cancelled):
        job.run_frame(0, progress=lambda fraction: False)
    assert not (shot / "out" / "frames" / "frame_0001.png").exists()
    with pytest.raises(ValueError, match="unknown option '--bogus' for --method lazyfluids"):
        registry.make_job("lazyfluids", shot / "smoke.png", shot / "guides", [1, 2], shot / "o", options={"bogus": 1})
    with pytest.raises(ValueError, match="temporal weight"):  # --lambda is λ, the temporal weight
        registry.make_job("lazyfluids", shot / "smoke.png", shot / "guides", [1, 2], shot / "o", options={"lambda": -1})
    with pytest.raises(FileNotFoundError, match="tracks.json: no rigid-body tracks"):
        registry.make_job("rigid", shot / "smoke.png", shot / "guides", [1, 2], shot / "o")
    with pytest.raises(ValueError, match="unknown --method 'ebsynth'"):
        registry.make_job("ebsynth", shot / "smoke.png", shot / "guides", [1, 2], shot / "o")


def test_stylit_by_the_registry_equals_its_own_class(tmp_path):
    """StyLit's options as the command line's flags (the exemplar render's
    guides, weights, --temporal, engine flags) give the frames of its own
    class, byte for byte, in OUT/frames."""
    make_cache(tmp_path / "cache")
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    inputs = (tmp_path / "paint.png", tmp_path / "exemplar", tmp_path / "cache")
    own = StylizeJob(*inputs, [1, 2, 3], tmp_path / "own", weights={"LDE": 3.0, "LDDE": 0}, temporal_weight=0.8,
                     em_iterations=3, threads=2, seed=4)
    job = registry.make_job("stylit", tmp_path / "paint.png", tmp_path / "cache", [1, 2, 3], tmp_path / "reg",
                            options={"exemplar-guides": tmp_path / "exemplar", "weights": "LDE=3,LDDE=0",
                                     "temporal": 0.8, "em-iters": 3, "threads": 2, "seed": 4})
    assert job.has_contact_sheet and job.output_path(2) == str(tmp_path / "reg" / "frames" / "frame_0002.png")
    for i, frame in enumerate(job.frames):
        mine, theirs = job.run_frame(i), own.run_frame(i)
        assert mine["status"] == theirs["status"] == "stylized"
        assert np.array_equal(read_image(job.output_path(frame)), read_image(own.output_path(frame)))
    different = registry.make_job("stylit", *inputs[::2], [1], tmp_path / "seed5",
                                  options={"exemplar-guides": inputs[1], "em-iters": 3, "threads": 2, "seed": 5})
    different.run_frame(0)
    assert not np.array_equal(read_image(different.output_path(1)), read_image(own.output_path(1)))
    with pytest.raises(ValueError, match="--exemplar-guides is required"):
        registry.make_job("stylit", *inputs[::2], [1], tmp_path / "o")
    with pytest.raises(ValueError, match="unknown guide 'GLOW'"):
        registry.make_job("stylit", *inputs[::2], [1], tmp_path / "o",
                          options={"exemplar-guides": inputs[1], "weights": "GLOW=1"})
    with pytest.raises(ValueError, match="unknown option '--noise' for --method stylit"):
        registry.make_job("stylit", *inputs[::2], [1], tmp_path / "o",
                          options={"exemplar-guides": inputs[1], "noise": 2})


def test_the_coherent_method_by_the_registry_equals_its_own_class(tmp_path):
    """The segment unit from Python: make_job("tcia") gives a segment job
    whose frames equal the coherent method's own class, byte for byte, with
    the stages of its sweeps as progress; it resumes and cancels the same."""
    from tempera.methods.tcia.tcia import ShotJob

    frames = range(1, 6)
    make_cache(tmp_path / "cache", frames=tuple(frames), forward=True)
    make_exemplar(tmp_path / "exemplar", tmp_path / "paint.png")
    key = tmp_path / "key3.png"
    tempera.write_image(str(key), np.roll(read_image(str(tmp_path / "paint.png")), 5, axis=1)[::-1].copy())
    inputs = (tmp_path / "paint.png", tmp_path / "cache", frames)
    own = ShotJob(tmp_path / "paint.png", tmp_path / "exemplar", tmp_path / "cache", frames, tmp_path / "own",
                  keys=[(3, key)], weights={"LDE": 3}, levels=2, patch_size=7, threads=2)
    flags = [("exemplar-guides", tmp_path / "exemplar"), ("key", f"3={key}"), ("weights", "LDE=3"),
             ("levels", 2), ("patch-size", 7), ("threads", 2)]
    job = registry.make_job("tcia", *inputs, tmp_path / "reg", options=flags)
    assert [s[:2] for s in job.segments] == [(1, 3), (3, 5)] and job.selected == [0, 1] and job.whole_shot
    stages = []
    for i in job.selected:
        made = job.run_segment(i, progress=lambda fraction, finished: stages.append(finished) or True)
        assert made["status"] == own.run_segment(i)["status"] == "stylized" and made["frame"] == job.segments[i][0]
    assert "level 2/2 backward sweep" in stages and "level 1/2 forward sweep" in stages
    for f in frames:
        assert (tmp_path / "reg" / "frames" / f"frame_{f:04d}.png").read_bytes() == \
            open(own.output_path(f), "rb").read()
    assert [job.run_segment(i)["status"] for i in job.selected] == ["skipped"] * 2  # resume
    task = registry.make_job("tcia", *inputs, tmp_path / "task", options=flags + [("segment", "3-5")])
    assert task.selected == [1] and not task.whole_shot  # a farm task
    with pytest.raises(tempera.Cancelled):
        task.run_segment(1, progress=lambda fraction, finished: False)
    assert not (tmp_path / "task" / "frames" / "frame_0004.png").exists()
    with pytest.raises(ValueError, match="--segment expects A-B"):
        registry.make_job("tcia", *inputs, tmp_path / "o", options=flags + [("segment", "3")])


def test_fluidymation_by_the_registry_equals_its_own_class(tmp_path):
    """What the panel gives Fluidymation (its masks folder, the target mask, the
    flow, the two passes, a table option) as flags gives MediaJob's frames,
    byte for byte: the panel runs it through make_job."""
    from test_fluidymation import ink_frames, make_inputs
    from tempera.methods.fluidymation import fluidymation

    _, cache = make_inputs(tmp_path, frames=2)
    rgb, masks = tmp_path / "rgb", tmp_path / "masks"
    rgb.mkdir(), masks.mkdir()
    for i, f in enumerate(ink_frames()):
        tempera.write_image(str(rgb / f"f{i:02d}.png"), np.ascontiguousarray(f[..., :3]))
        tempera.write_image(str(masks / f"m{i:02d}.png"), np.ascontiguousarray(f[..., 3:]))
    own = fluidymation.MediaJob(rgb, cache, [1, 2], tmp_path / "own", exemplar_masks=masks, target_mask="alpha",
                                flow="masks", bidirectional=True, boundary_weight=1.5, shape_blur=6, levels=2, threads=2, seed=3)
    job = registry.make_job("fluidymation", rgb, cache, [1, 2], tmp_path / "by_registry",
                            options={"exemplar-masks": masks, "target-mask": "alpha", "flow": "masks",
                                     "bidirectional": True, "boundary-weight": 1.5, "shape-blur": 6, "levels": 2, "threads": 2,
                                     "seed": 3})
    for i, frame in enumerate(job.frames):
        assert job.run_frame(i)["status"] == own.run_frame(i)["status"] == "stylized"
        assert np.array_equal(read_image(job.output_path(frame)), read_image(own.output_path(frame)))
    assert job.output_path(2) == str(tmp_path / "by_registry" / "frames" / "frame_0002.png")
