"""Pictures of docs/user_guide.md, from the demo's output and the exemplar kit
(no Blender; run `make demo` first):

    PYTHONPATH=addon /usr/bin/python3 docs/make_user_guide_figures.py \
        --demo out/demo --kit build/kit/sphere_on_table

writes docs/images/user_guide_{exemplar,result,temporal}.png and prints the
flicker and detail of the temporal-weight comparison (quoted in the guide).
"""
import argparse
import tempfile
from pathlib import Path

import numpy as np

import tempera
from tempera.app import guide_cache
from tempera.engine.guides import tonemap
from tempera.methods.stylit.stylize import StylizeJob

IMAGES = Path(__file__).resolve().parent / "images"
LIGHT_PATHS = ("FULL", "LDE", "LSE", "LDDE", "LD12E")
TEMPORAL_WEIGHTS = (0.0, 0.5, 1.0)
COMPARED_FRAMES = range(1, 13)
SHOWN_FRAMES = (3, 6, 9, 12)
CROP = (slice(60, 200), slice(60, 300))  # rows, columns of 320 x 240 frames: sphere, box, table


def rgb(path):
    return tempera.read_image(str(path))[:, :, :3]


def detail(image):
    """Mean absolute difference of neighbouring grey values: the strokes' crispness."""
    g = image.mean(axis=2)
    return float(np.abs(np.diff(g, axis=0)).mean() + np.abs(np.diff(g, axis=1)).mean())


def exemplar_figure(kit):
    guides = guide_cache.read_frame(kit / "guides", 1, list(LIGHT_PATHS))
    cells = [rgb(kit / "render.png"), rgb(kit / "style.png")] + [tonemap(guides[g]) for g in LIGHT_PATHS]
    sheet = tempera.contact_sheet(cells[:2] + [np.ones_like(cells[0])] + cells[2:], columns=4, gap=4, margin=4,
                                  background=1.0)
    tempera.write_image(str(IMAGES / "user_guide_exemplar.png"), sheet)


def temporal_figure(demo, kit, work):
    rows, report = [], []
    for weight in TEMPORAL_WEIGHTS:
        job = StylizeJob(kit / "style.png", kit / "guides", demo / "guides", list(COMPARED_FRAMES),
                         work / f"temporal_{weight}", temporal_weight=weight, seed=0)
        results = [job.run_frame(i) for i in range(len(job.frames))]
        flicker = np.nanmean([r["flicker"] for r in results[1:]])
        images = {f: rgb(job.output_path(f)) for f in COMPARED_FRAMES}
        report.append((weight, flicker, detail(images[COMPARED_FRAMES[-1]])))
        rows += [images[f][CROP] for f in SHOWN_FRAMES]
    tempera.write_image(str(IMAGES / "user_guide_temporal.png"),
                        tempera.contact_sheet(rows, columns=len(SHOWN_FRAMES), gap=4, margin=4, background=1.0))
    style_detail = detail(rgb(kit / "style.png"))
    print(f"painting detail {style_detail:.4f}")
    for weight, flicker, last_detail in report:
        print(f"temporal weight {weight}: mean flicker {flicker:.4f}, detail of frame "
              f"{COMPARED_FRAMES[-1]} {last_detail:.4f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--demo", default="out/demo", type=Path)
    parser.add_argument("--kit", default="build/kit/sphere_on_table", type=Path)
    args = parser.parse_args()
    IMAGES.mkdir(exist_ok=True)
    exemplar_figure(args.kit)
    result = rgb(args.demo / "comparison_sheet.png")
    tempera.write_image(str(IMAGES / "user_guide_result.png"), result[::2, ::2])
    with tempfile.TemporaryDirectory() as work:
        temporal_figure(args.demo, args.kit, Path(work))


if __name__ == "__main__":
    main()
