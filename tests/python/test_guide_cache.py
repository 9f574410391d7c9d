"""tempera.app.guide_cache: cache layout, manifest, frame I/O and the numpy conversions."""
import json

import numpy as np
import pytest

from tempera.app import guide_cache
from tempera.engine import guides


def test_channel_names_of_the_documented_guides():
    assert guide_cache.channel_names("FULL") == ["FULL.R", "FULL.G", "FULL.B"]
    assert guide_cache.channel_names("velocity_forward") == ["velocity_forward.X", "velocity_forward.Y"]
    assert guide_cache.channel_names("tensor") == ["tensor.XX", "tensor.XY", "tensor.YY"]
    assert guide_cache.channel_names("occlusion_backward") == ["occlusion_backward.V"]
    assert guide_cache.channel_names(guide_cache.mask_guide("OB", "Cube.001")) == ["mask.OB_Cube_001.V"]
    with pytest.raises(ValueError, match="unknown guide 'NOPE'"):
        guide_cache.channel_names("NOPE")


def test_the_documented_table_is_the_native_one():
    """docs/guide_cache.md's guide table lists exactly the guides and channels
    of the native tables (light paths and app/guide_cache.hpp), in order."""
    from pathlib import Path
    import re

    text = (Path(__file__).resolve().parents[2] / "docs" / "guide_cache.md").read_text()
    text = text.split("| guide | channels | what it is |", 1)[1].split("\n\n", 1)[0]
    rows = re.findall(r"^\| `([A-Za-z0-9_]+)` \| `([^`]+)` \|", text, flags=re.M)
    documented = {name: channels for name, channels in rows}
    native = {name: f"{name}." + "/".join(components) for name, components in guide_cache.GUIDES.items()}
    assert list(documented) == list(native)
    assert documented == native


def test_lpe_guide_names_are_exr_safe_and_distinct():
    assert guide_cache.lpe_guide("LDE") == "lpe_LDE"
    assert guide_cache.channel_names("lpe_LDE") == ["lpe_LDE.R", "lpe_LDE.G", "lpe_LDE.B"]
    expressions = ["L.*DDE", "L.*D.E", "L.*D*E", "LD{2}E", "LD{1,2}E", "LD+E", "LD*E", "L(D|S)E", "L[DS]E",
                   "L_DDE", "LD2E", "...", "LDE"]
    names = [guide_cache.lpe_guide(e) for e in expressions]
    assert len(set(names)) == len(names)
    for name in names:
        assert name.startswith("lpe_") and all(c.isalnum() or c == "_" for c in name), name
    assert guide_cache.lpe_guide("L.*DDE").startswith("lpe_L_DDE_") and len(guide_cache.lpe_guide("L.*DDE")) == 18


def test_split_expressions_keeps_braced_commas():
    assert guide_cache.split_expressions("L.*SDE; LD{1,2}E, LSE ;") == ["L.*SDE", "LD{1,2}E", "LSE"]
    assert guide_cache.split_expressions("  ") == []


def test_frames_round_trip_by_guide_name(tmp_path):
    rng = np.random.default_rng(0)
    frame = {
        "FULL": rng.random((5, 7, 3), np.float32),
        "velocity_forward": rng.normal(size=(5, 7, 2)).astype(np.float32),
        "alpha": rng.random((5, 7), np.float32),
        "mask.OB_Cube": (rng.random((5, 7)) > 0.5).astype(np.float32),
    }
    path = guide_cache.write_frame(tmp_path, 3, frame)
    assert path == tmp_path / "frame_0003.exr"
    back = guide_cache.read_frame(tmp_path, 3, list(frame))
    for name, array in frame.items():
        np.testing.assert_array_equal(back[name], array)
    with pytest.raises(ValueError, match="has 2 channels"):
        guide_cache.write_frame(tmp_path, 4, {"FULL": np.zeros((2, 2, 2))})


def test_manifest_is_written_atomically_and_frames_are_current_by_key(tmp_path):
    assert guide_cache.read_manifest(tmp_path) is None
    key = guide_cache.frame_key({"samples": 4}, {"camera": "Camera", "frame": 1})
    assert key != guide_cache.frame_key({"samples": 8}, {"camera": "Camera", "frame": 1})
    manifest = {"guides": ["alpha"], "frames": {"1": {"key": key}}}
    guide_cache.write_manifest(tmp_path, manifest)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["manifest.json"]
    read = guide_cache.read_manifest(tmp_path)
    assert read["format"] == guide_cache.FORMAT_VERSION and read["frames"]["1"]["key"] == key
    assert not guide_cache.is_frame_current(tmp_path, read, 1, key)  # no EXR yet
    guide_cache.write_frame(tmp_path, 1, {"alpha": np.ones((2, 2))})
    assert not guide_cache.is_frame_current(tmp_path, read, 1, key)  # no size and checksum recorded
    read["frames"]["1"] = guide_cache.frame_entry(tmp_path, 1, key)
    assert guide_cache.is_frame_current(tmp_path, read, 1, key)
    assert not guide_cache.is_frame_current(tmp_path, read, 1, "other")
    assert not guide_cache.is_frame_current(tmp_path, read, 2, key)
    assert set(guide_cache.read_frame(tmp_path, 1)) == {"alpha"}
    (tmp_path / "manifest.json").write_text("{ broken")
    with pytest.warns(UserWarning, match="damaged"):
        assert guide_cache.read_manifest(tmp_path) is None


def test_vector_pass_signs():
    """A point moving right by 2 px and up the image (y up) by 1 px per frame:
    Blender stores XY = p(f-1) - p(f) = (-2, -1), ZW = p(f) - p(f+1) = (-2, -1).
    In rows-down pixels it moves by (+2, -1) per frame, forward and backward."""
    vector = np.tile(np.float32([-2, -1, -2, -1]), (3, 4, 1))
    backward, forward = guide_cache.velocities_from_vector_pass(vector)
    np.testing.assert_array_equal(backward[1, 1], [2, -1])
    np.testing.assert_array_equal(forward[1, 1], [2, -1])


def test_vector_pass_of_a_moving_square_gives_clean_occlusion():
    """Converted velocities feed tempera.engine.guides: a square moving right by 3 px
    reveals 3 columns behind it (chi- = 0) and nothing else."""
    h, w = 12, 24

    def vector_pass(frame):
        v = np.zeros((h, w, 4), np.float32)
        v[3:9, 6 + 3 * frame:12 + 3 * frame, 0] = -3  # X = p(f-1) - p(f)
        v[3:9, 6 + 3 * frame:12 + 3 * frame, 2] = -3  # Z = p(f) - p(f+1)
        return v

    back1, _ = guide_cache.velocities_from_vector_pass(vector_pass(1))
    _, fwd0 = guide_cache.velocities_from_vector_pass(vector_pass(0))
    chi = guides.occlusion_backward(back1, fwd0)
    expected = np.ones((h, w), np.float32)
    expected[3:9, 6:9] = 0
    np.testing.assert_array_equal(chi, expected)


def test_line_guide_marks_silhouettes_on_the_near_side_and_creases():
    h, w = 10, 12
    depth = np.full((h, w), 1e10, np.float32)  # background
    normal = np.zeros((h, w, 3), np.float32)
    depth[2:8, 3:9] = 5.0  # a box facing the camera ...
    normal[2:8, 3:9] = (0, 0, 1)
    normal[2:8, 6:9] = (1, 0, 0)  # ... with a crease between x = 5 and 6
    lines = guide_cache.line_guide(depth, normal)
    assert lines.dtype == np.float32 and lines.shape == (h, w)
    box = np.zeros((h, w), bool)
    box[2:8, 3:9] = True
    border = box & ~np.pad(box[1:-1, 1:-1] & box[:-2, 1:-1] & box[2:, 1:-1] & box[1:-1, :-2] & box[1:-1, 2:],
                           1)
    assert np.all(lines[border] == 1)  # the silhouette, inside the box
    assert np.all(lines[~box] == 0)  # nothing on the background
    assert np.all(lines[3:7, 5] == 1) and np.all(lines[3:7, 4] == 0) and np.all(lines[3:7, 6:8] == 0)
    d = guides.line_distance(lines, 4.0)
    assert d[4, 5] == 0 and d[4, 4] == pytest.approx(0.25)


def test_line_guide_ignores_smooth_slopes():
    depth = np.tile(np.linspace(4, 4.5, 16, dtype=np.float32), (8, 1))  # a tilted plane
    normal = np.tile(np.float32([0, 0.2, 1]), (8, 16, 1))
    assert guide_cache.line_guide(depth, normal).sum() == 0


def test_manifest_is_plain_json(tmp_path):
    guide_cache.write_manifest(tmp_path, {"params": guide_cache.DEFAULT_PARAMS, "frames": {}})
    data = json.loads((tmp_path / "manifest.json").read_text())
    assert data["params"]["occlusion_epsilon"] == 2.0


def test_conversions_reject_wrong_shapes():
    with pytest.raises(ValueError, match=r"Vector pass must be \(H, W, 4\)"):
        guide_cache.velocities_from_vector_pass(np.zeros((4, 4, 2)))
    with pytest.raises(ValueError, match="differ in size"):
        guide_cache.line_guide(np.ones((4, 4)), np.zeros((4, 5, 3)))
    with pytest.raises(ValueError, match="kind must be"):
        guide_cache.mask_guide("XX", "a")
