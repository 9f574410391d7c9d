"""tempera.app.farm without a cluster: frame ranges, the plan of a shot, the
`tempera farm --dry-run` command line, and agreement with the Flamenco job
type (farm/flamenco/tempera.js run under Node with the stand-in API)."""
import json
import shutil
import subprocess
import sys

import pytest

from tempera.app import farm
from tempera.methods import registry
from tempera.methods.tcia import tcia
from conftest import ROOT

SHOT = dict(frames="1-48", out="/shared/out", exemplar="/shared/style.png", scene="/shared/shot010.blend",
            exemplar_scene="/shared/sphere.blend", chunk_size=8, guide_args=["--samples", "32"],
            stylize_args=["--quality", "preview"])


def test_frame_ranges_round_trip():
    assert farm.parse_frames("1-3,7, 5") == [1, 2, 3, 5, 7]
    assert farm.format_frames([1, 2, 3, 5, 7, 8]) == "1-3,5,7-8"
    assert farm.chunk_frames(list(range(1, 11)), 4) == [[1, 2, 3, 4], [5, 6, 7, 8], [9, 10]]
    for bad in ("", "a-b", "9-3", "1,,2"):
        with pytest.raises(farm.FarmError, match="bad frame range"):
            farm.parse_frames(bad)
    with pytest.raises(farm.FarmError, match="chunk size"):
        farm.chunk_frames([1], 0)


def test_plan_of_a_48_frame_shot():
    tasks = farm.plan(**SHOT)
    names = [t.name for t in tasks]
    assert names[0] == "exemplar-guides" and names[-1] == "finish"
    assert [n for n in names if n.startswith("guides")] == [f"guides {a}-{a + 7}" for a in range(1, 48, 8)]
    stylize = [t for t in tasks if t.kind == "stylize"]
    assert [t.frames for t in stylize] == [list(range(a, a + 8)) for a in range(1, 48, 8)]
    assert sorted(f for t in stylize for f in t.frames) == list(range(1, 49))  # each frame once
    assert stylize[1].depends == ["exemplar-guides", "guides 9-16"]
    assert tasks[-1].depends == [t.name for t in stylize]
    assert "--no-video" in stylize[0].command and "--no-video" not in tasks[-1].command
    # every dependency comes earlier
    seen = set()
    for task in tasks:
        assert set(task.depends) <= seen, task.name
        seen.add(task.name)


def test_temporal_shot_is_one_chain():
    tasks = farm.plan(**dict(SHOT, temporal=0.5))
    stylize = [t for t in tasks if t.kind == "stylize"]
    assert len(stylize) == 1 and stylize[0].frames == list(range(1, 49))
    assert stylize[0].command[stylize[0].command.index("--temporal") + 1] == "0.5"


TCIA = ["--method", "tcia", "--key", "12=/shared/k12.png", "--key=24=/shared/k24.png,/shared/m24.png"]


def test_coherent_shot_is_one_task_per_segment_between_keys():
    tasks = farm.plan(**dict(SHOT, stylize_args=TCIA))
    stylize = [t for t in tasks if t.kind == "stylize"]
    assert [(t.frames[0], t.frames[-1]) for t in stylize] == [(1, 12), (12, 24), (24, 48)]
    for t in stylize:  # the whole shot's frames and keys, one segment solved
        c = t.command
        assert c[c.index("--frames") + 1] == "1-48" and "--temporal" not in c
        assert c[c.index("--segment") + 1] == f"{t.frames[0]}-{t.frames[-1]}"
    assert stylize[1].depends == ["exemplar-guides", "guides 9-16", "guides 17-24"]
    assert "--segment" not in tasks[-1].command and tasks[-1].depends == [t.name for t in stylize]
    keyless = farm.plan(**dict(SHOT, stylize_args=["--method", "tcia"], temporal=0.7))
    one = [t for t in keyless if t.kind == "stylize"]
    assert len(one) == 1 and one[0].command[one[0].command.index("--temporal") + 1] == "0.7"
    with pytest.raises(farm.FarmError, match="--key expects"):
        farm.plan(**dict(SHOT, stylize_args=["--method", "tcia", "--key", "x.png"]))


def _flamenco_argv(stylize_args):
    """The commands the Flamenco job type compiles for a tcia shot with these stylize options."""
    settings = dict(FLAMENCO_SETTINGS, temporal=0.5, stylize_args=" ".join(stylize_args))
    script = ("const {compile, summary} = require(process.argv[1]);"
              "console.log(JSON.stringify(summary(compile(JSON.parse(process.argv[2])).job)));")
    result = subprocess.run(["node", "-e", script, str(ROOT / "farm" / "flamenco" / "standin.js"),
                             json.dumps(settings)], capture_output=True, text=True, check=True)
    return [t["argv"] for t in json.loads(result.stdout)]


@pytest.mark.skipif(shutil.which("node") is None, reason="node not installed")
def test_flamenco_plans_the_same_segments():
    assert _flamenco_argv(TCIA) == [t.command for t in farm.plan(**dict(SHOT, stylize_args=TCIA))]


LAYERED = ["--method", "tcia", "--key", "12=/shared/k12.png", "--layer", "suit=mask.CO_Suit",
           "--layer-key", "suit:30=/shared/suit30.png", "--layer-key=suit:40=/shared/suit40.png,/shared/m40.png"]


def test_layer_keys_bound_segments_as_in_the_job():
    """The farm's copy of the segment rule ignored --layer-key, so its --segment
    values were not the job's segments and the CLI refused them. Now it uses the
    job core's rule (_native.key_segments), as ShotJob does."""
    stylize = [t for t in farm.plan(**dict(SHOT, stylize_args=LAYERED)) if t.kind == "stylize"]
    assert [(t.frames[0], t.frames[-1]) for t in stylize] == [(1, 12), (12, 30), (30, 40), (40, 48)]
    assert [(t.frames[0], t.frames[-1]) for t in stylize] == tcia.segments(range(1, 49), [12, 30, 40])
    with pytest.raises(farm.FarmError, match="--layer-key expects NAME:FRAME"):
        farm.plan(**dict(SHOT, stylize_args=["--method", "tcia", "--layer-key", "30=/k.png"]))


@pytest.mark.skipif(shutil.which("node") is None, reason="node not installed")
def test_flamenco_plans_the_same_layered_segments():
    assert _flamenco_argv(LAYERED) == [t.command for t in farm.plan(**dict(SHOT, stylize_args=LAYERED))]


def test_plan_refuses_incomplete_shots():
    with pytest.raises(farm.FarmError, match="exactly one of exemplar_guides"):
        farm.plan("1-4", "/o", "/s.png", guides="/g")
    with pytest.raises(farm.FarmError, match="scene .*or as a guide cache"):
        farm.plan("1-4", "/o", "/s.png", exemplar_guides="/eg")


def test_dry_run_prints_the_tasks(capsys):
    code = farm.main(["--guides", "/g", "--exemplar", "/s.png", "--exemplar-guides", "/eg", "--frames", "1-20",
                      "--out", "/o", "--chunk-size", "10", "--tempera", "tempera", "--weights", "LDE=3",
                      "--samples", "8", "--dry-run"])
    lines = capsys.readouterr().out.splitlines()
    assert code == 0 and [line.split(":")[0] for line in lines] == ["stylize 1-10", "stylize 11-20", "finish"]
    assert "--weights LDE=3" in lines[0] and "--samples" not in lines[0]  # --samples is a guide option
    assert lines[2].endswith("(after stylize 1-10, stylize 11-20)")


def test_console_script_routes_scheduler_to_the_farm():
    result = subprocess.run([sys.executable, "-m", "tempera", "stylize", "--scheduler", "tcp://127.0.0.1:1",
                             "--exemplar", "/s.png", "--frames", "1-x", "--out", "/o", "--guides", "/g",
                             "--exemplar-guides", "/eg"], capture_output=True, text=True, cwd=ROOT / "addon")
    assert result.returncode == 1 and "bad frame range '1-x'" in result.stderr


FLAMENCO_SETTINGS = {"frames": "1-48", "chunk_size": 8, "scene": "/shared/shot010.blend",
                     "exemplar": "/shared/style.png", "exemplar_scene": "/shared/sphere.blend", "out": "/shared/out",
                     "guide_args": "--samples 32", "stylize_args": "--quality preview", "tempera": "tempera"}


@pytest.mark.skipif(shutil.which("node") is None, reason="node not installed")
@pytest.mark.parametrize("temporal", [0, 0.5])
def test_flamenco_job_type_makes_the_same_tasks(temporal):
    settings = dict(FLAMENCO_SETTINGS, temporal=temporal)
    script = ("const {compile, summary} = require(process.argv[1]);"
              "console.log(JSON.stringify(summary(compile(JSON.parse(process.argv[2])).job)));")
    result = subprocess.run(["node", "-e", script, str(ROOT / "farm" / "flamenco" / "standin.js"),
                             json.dumps(settings)], capture_output=True, text=True, check=True)
    flamenco = json.loads(result.stdout)
    ours = farm.plan(**dict(SHOT, temporal=temporal))
    assert [t["name"] for t in flamenco] == [t.name for t in ours]
    assert [t["argv"] for t in flamenco] == [t.command for t in ours]
    assert [t["depends"] for t in flamenco] == [t.depends for t in ours]


def test_flamenco_default_temporal_weight_is_temperas():
    from pathlib import Path

    from tempera.app.settings import DEFAULT_TEMPORAL_WEIGHT

    js = (Path(__file__).resolve().parents[2] / "farm" / "flamenco" / "tempera.js").read_text()
    assert f'key: "temporal", type: "float", default: {DEFAULT_TEMPORAL_WEIGHT:.1f}' in js


SHOT_CACHE = dict(frames="1-24", out="/o", exemplar="/ex", guides="/g", chunk_size=8)


def test_the_farm_plans_every_method_with_its_own_inputs():
    """Methods not guided by light paths (the registry's light_path_guides) get no exemplar
    guides, no --temporal and no --no-video, which their commands would refuse."""
    for m in registry.METHODS:
        if m["light_path_guides"]:
            continue
        tasks = farm.plan(**SHOT_CACHE, stylize_args=["--method", m["name"]])
        for t in tasks:
            assert not {"--exemplar-guides", "--temporal", "--no-video"} & set(t.command), t.command
        stylize = [t for t in tasks if t.kind == "stylize"]
        assert len(stylize) == (1 if m["unit"] == "chained frame" else 3), [t.name for t in stylize]
        with pytest.raises(farm.FarmError, match="takes its exemplar as it is"):
            farm.plan(**SHOT_CACHE, exemplar_guides="/eg", stylize_args=["--method", m["name"]])


def test_a_planned_lazyfluids_shot_equals_one_run(cli_path, tmp_path):
    """The farm's commands for a chained-frame method, run in their order, make the frames of one
    `tempera stylize` run, byte for byte."""
    from test_lazyfluids import disc, flow, smoke
    import tempera
    from tempera.app import guide_cache

    for f in range(1, 5):
        guide_cache.write_frame(tmp_path / "cache", f, {"alpha": disc(14 + 2 * f), "fluid_velocity": flow()})
    tempera.write_image(str(tmp_path / "smoke.png"), smoke())
    args = ["--method", "lazyfluids", "--em-iters", "2", "--threads", "2"]
    tasks = farm.plan("1-4", tmp_path / "farm", tmp_path / "smoke.png", guides=tmp_path / "cache", chunk_size=2,
                      tempera=[str(cli_path)], stylize_args=args)
    for t in tasks:
        assert subprocess.run(t.command, capture_output=True, text=True, timeout=300).returncode == 0, t.command
    one = subprocess.run([str(cli_path), "stylize", "--guides", str(tmp_path / "cache"), "--exemplar",
                          str(tmp_path / "smoke.png"), "--frames", "1-4", "--out", str(tmp_path / "one"), *args],
                         capture_output=True, text=True, timeout=300)
    assert one.returncode == 0, one.stderr
    for f in range(1, 5):
        name = f"frames/frame_{f:04d}.png"
        assert (tmp_path / "farm" / name).read_bytes() == (tmp_path / "one" / name).read_bytes(), name


@pytest.mark.skipif(shutil.which("node") is None, reason="node not installed")
def test_flamenco_refuses_methods_it_cannot_plan():
    settings = dict(FLAMENCO_SETTINGS, stylize_args="--method lazyfluids")
    script = ("const {compile} = require(process.argv[1]);"
              "try { compile(JSON.parse(process.argv[2])); console.log('planned'); } "
              "catch (e) { console.log(String(e)); }")
    result = subprocess.run(["node", "-e", script, str(ROOT / "farm" / "flamenco" / "standin.js"),
                             json.dumps(settings)], capture_output=True, text=True, check=True)
    assert "plans stylit and tcia shots; run --method lazyfluids" in result.stdout
