"""The rigid-body method from Python (tempera.methods.rigid.rigid): the generated exemplar
fitted and transferred onto a target ball, checked against the generator's
oracle; option validation and named errors."""
import numpy as np
import pytest

from tempera import _native
from tempera.methods.rigid import rigid

W, H = 320, 200


@pytest.fixture(scope="module")
def source():
    track = _native.bouncing_ball((40, 50), (4.5, 0), 18, 1.2, 180, 0.6, 0.05, 48)
    return rigid.fit_exemplar(track, rigid.generated_exemplar(track, W, H))


def test_transfer_follows_the_oracle(source):
    # The C++ oracle's target (tests/cpp/test_rigid.cpp), through the binding.
    target = _native.bouncing_ball((290, 30), (-3.5, 1), 16, 1.0, 185, 0.7, -0.08, 64)
    frames = rigid.stylize([source], target, W, H)
    assert len(frames) == 64
    rgba, D, shift = frames[target["events"][0]["frame"]]
    assert rgba.shape == (H, W, 4) and D.shape == (2, 6)
    assert rgba[:, :, 3].max() > 0.9  # inked
    oracle = rigid.oracle_maps(target)
    got = [rigid.stretch_along(f[1], v) for f, v in zip(frames, target["velocity"])]
    want = [rigid.stretch_along(o, v) for o, v in zip(oracle, target["velocity"])]
    assert np.corrcoef(got, want)[0, 1] >= 0.9


def test_the_flip_augmentation_is_what_matches_a_reversed_throw(source):
    # The source is thrown to the right, the target to the left: without the
    # flip (or without augmentation) the stretch no longer follows the oracle.
    target = _native.bouncing_ball((290, 30), (-3.5, 1), 16, 1.0, 185, 0.7, -0.08, 64)
    oracle = rigid.oracle_maps(target)
    want = [rigid.stretch_along(o, v) for o, v in zip(oracle, target["velocity"])]

    def r(**kw):
        got = [rigid.stretch_along(D, v) for (D, _, _), v in zip(rigid.deformations([source], target, **kw),
                                                                 target["velocity"])]
        return np.corrcoef(got, want)[0, 1]

    assert r() >= 0.9
    assert r(flip=False) < 0.6
    assert r(augment=False) < 0.6


def test_switching_damping_off_changes_the_result(source):
    target = _native.bouncing_ball((280, 40), (-1.0, 0), 16, 0.5, 185, 0.5, 0.0, 30)
    damped = rigid.deformations([source], target)
    undamped = rigid.deformations([source], target, damp=False)
    assert any(xi < 0.99 for _, xi, _ in damped)
    assert all(xi == 1.0 for _, xi, _ in undamped)


def test_cancel_and_errors(source):
    target = source[0]
    with pytest.raises(_native.Cancelled):
        rigid.stylize([source], target, W, H, progress=lambda f: f < 2)
    with pytest.raises(ValueError, match="k"):
        rigid.stylize([source], target, W, H, k=0)
    with pytest.raises(ValueError, match="unknown"):
        rigid.RigidOptions(nonsense=1)
    with pytest.raises(ValueError, match="drawings"):
        rigid.fit_exemplar(target, [])
    with pytest.raises(ValueError, match="RGBA"):
        rigid.fit_exemplar(target, [np.zeros((4, 4))] * len(target["centre"]))
