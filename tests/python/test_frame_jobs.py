"""The job core's per-frame jobs look alike from Python (tempera.app.frame_job):
every method's run_frame returns the one FrameResult as the same dict, and a
progress callback that returns None goes on while False cancels."""
import numpy as np
import pytest

import tempera
from tempera.app import guide_cache
from tempera.app.frame_job import FrameJob
from tempera.methods.fluidymation import fluidymation
from tempera.methods.lazyfluids import lazyfluids
from tempera.methods.noisy import noisy
from tempera.methods.stylit.stylize import StylizeJob

from synthetic_cache import make_cache, make_exemplar
from test_fluidymation import make_inputs

KEYS = {"frame", "path", "status", "seconds", "flicker", "source_coverage"}


def jobs(p):
    make_cache(p / "cache")
    make_exemplar(p / "exemplar", p / "paint.png")
    yield StylizeJob(p / "paint.png", p / "exemplar", p / "cache", [1, 2], p / "stylit", threads=1, levels=1)
    rgba = np.dstack([np.random.default_rng(1).random((16, 16, 3)), np.ones((16, 16))]).astype(np.float32)
    tempera.write_image(str(p / "smoke.png"), rgba)
    for f in (1, 2):
        guide_cache.write_frame(p / "fluid", f, {"alpha": np.ones((20, 24), np.float32)})
    yield lazyfluids.FluidJob(p / "smoke.png", p / "fluid", [1, 2], p / "lazy", em_iterations=1, threads=1)
    (p / "fluidymation").mkdir()
    exemplar, cache = make_inputs(p / "fluidymation", frames=2)
    yield fluidymation.MediaJob(exemplar, cache, [1, 2], p / "media", levels=1, threads=1)
    medium = np.random.default_rng(4).random((64, 64, 3)).astype(np.float32)
    tempera.write_image(str(p / "medium.png"), medium)
    (p / "R").mkdir()
    for f in (1, 2):
        tempera.write_image(str(p / "R" / f"frame_{f:04d}.png"), medium[4:44, 6:54])
    yield noisy.NoisySequence(p / "medium.png", p / "R", [1, 2], p / "noisy", noise=2.2, threads=1)


def test_every_per_frame_job_returns_the_one_result(tmp_path):
    seen = []
    for job in jobs(tmp_path):
        assert isinstance(job, FrameJob) and job.frames == [1, 2]
        with pytest.raises(tempera.Cancelled):
            job.run_frame(0, progress=lambda f: False)
        first = job.run_frame(0, progress=lambda f: None)  # None goes on
        assert set(first) == KEYS and first["frame"] == 1 and first["status"] in ("stylized", "made")
        assert first["path"] == job.output_path(1) and first["seconds"] > 0
        assert job.run_frame(0)["status"] == "skipped"
        seen.append(type(job).__name__)
    assert seen == ["StylizeJob", "FluidJob", "MediaJob", "NoisySequence"]


def native_constructors():
    from tempera import _native
    from tempera.methods.stylit import stylize
    from tempera.methods.tcia import tcia

    return {"StylizeJob": lambda **c: _native.StylizeJob(_native.StylizeJobConfig(**c), stylize.options()),
            "FluidJob": lambda **c: _native.LazyFluidsJob(_native.JobConfig(**c), lazyfluids.options()),
            "MediaJob": lambda **c: _native.FluidymationJob(_native.FluidymationJobConfig(**c),
                                                            fluidymation.options()),
            "NoisySequence": lambda **c: _native.NoisySequence(_native.NoisySequenceConfig(**c), noisy.options()),
            "ShotJob": lambda **c: _native.TciaJob(_native.TciaJobConfig(**c), tcia.options())}


@pytest.mark.parametrize("name", ["StylizeJob", "FluidJob", "MediaJob", "NoisySequence", "ShotJob"])
def test_every_job_binding_reads_the_job_config_one_way(name):
    """The core's JobConfig fields are read one way by every job's binding (bind_job_config.hpp)."""
    make = native_constructors()[name]
    with pytest.raises(ValueError, match=f"{name} config needs 'exemplar'"):
        make(frames=[1], out="o")
    with pytest.raises(ValueError, match="frames expects a list of whole numbers, got '1-3'"):
        make(exemplar="e", frames="1-3", out="o")


def test_a_job_config_is_a_typed_class(tmp_path):
    """Issue 41, step 6: a config crosses the binding as a class, field by
    field: paths as str or os.PathLike, every unknown keyword named, each bad
    value named with what its field expects."""
    from tempera import _native

    config = _native.JobConfig(exemplar=tmp_path / "paint.png", frames=range(3, 5), out=str(tmp_path))
    assert (config.exemplar, config.frames, config.out) == (str(tmp_path / "paint.png"), [3, 4], str(tmp_path))
    assert (config.guides, config.format, config.resume) == ("", "png", True)
    assert repr(config).startswith(f"JobConfig(exemplar={str(tmp_path / 'paint.png')!r}, guides='', frames=[3, 4]")
    config.resume = False
    assert config.resume is False
    with pytest.raises(ValueError, match="unknown JobConfig field\\(s\\) 'colour', 'speed' \\(known: exemplar, guides"):
        _native.JobConfig(colour=1, speed=2)
    for field, value, kind in (("frames", [1, "x"], "a list of whole numbers"), ("format", 5, "a string or path"),
                               ("resume", "yes", "True or False")):
        with pytest.raises(ValueError, match=f"{field} expects {kind}"):
            setattr(config, field, value)


def test_the_coherent_methods_config_holds_its_parts():
    """Keys, layers, the line term and the orientation are typed classes too;
    a part's attributes are set in place, the guide weights by name."""
    from tempera import _native

    config = _native.TciaJobConfig(exemplar="paint.png", frames=[1, 2], out="o", weights={"LDE": 3},
                                   keys=[_native.TciaKey(frame=2, painting="k.png")],
                                   layers=[_native.TciaLayer(name="suit", mask="mask.CO_Suit",
                                                             keys=[_native.TciaKey(frame=1, painting="s.png",
                                                                                   mask="m.png")])])
    assert config.weights["LDE"] == 3 and config.weights["FULL"] == _native.StylitOptions().weights["FULL"]
    assert [(k.frame, k.painting, k.mask) for k in config.keys] == [(2, "k.png", "")]
    assert [(k.frame, k.mask) for k in config.layers[0].keys] == [(1, "m.png")]
    assert config.segment is None and config.layer_order == "depth"
    config.lines.weight = 2.0
    config.orientation.from_cache = True
    assert (config.lines.weight, config.orientation.from_cache) == (2.0, True)
    config.segment = (1, 2)
    assert config.segment == (1, 2)
    with pytest.raises(ValueError, match="unknown guide 'DIFFUSE'"):
        config.weights = {"DIFFUSE": 1}
    with pytest.raises(ValueError, match="frame expects a whole number"):
        _native.TciaKey(frame="two")
