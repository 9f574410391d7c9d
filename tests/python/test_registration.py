"""Painting template (tempera.methods.stylit.painting_template) and registration of a photo
of the painted template (tempera.methods.stylit.registration, tempera.methods.stylit.register_painting)."""
import re
import subprocess
import sys
import zlib

import numpy as np
import pytest

import tempera
from tempera.methods.stylit.painting_template import make_template, place_picture, write_kit_json, write_pdf
from tempera.methods.stylit.registration import (apply_homography, estimate_homography, find_marks, label_components,
                                  register_painting, simulate_photo)

W, H = 64, 48  # guide resolution of the synthetic exemplar
DPI = 60  # small pages keep the tests quick


def synthetic_render():
    """A stand-in for the exemplar render: a shaded disk on a gradient."""
    y, x = np.mgrid[:H, :W] + 0.5
    disk = np.hypot(x - 32, y - 26) < 14
    rgb = np.stack([0.3 + 0.4 * y / H] * 3, axis=2)
    rgb[disk] = [0.8, 0.15, 0.1]
    return rgb


def known_painting():
    """What the 'artist' paints, at the guide resolution: smooth colour waves."""
    y, x = np.mgrid[:H, :W] + 0.5
    return np.stack([0.5 + 0.4 * np.sin(2 * np.pi * x / 20), 0.5 + 0.35 * np.cos(2 * np.pi * y / 16),
                     0.3 + 0.5 * (x + y) / (W + H)], axis=2)


def painted_page(template, painting):
    """The template with `painting` laid opaquely over its picture area."""
    return place_picture(template.image.astype(np.float64), template.picture, painting)


def photograph(page, page_to_photo, size, rng, noise=0.01):
    return simulate_photo(page, page_to_photo, size, seed=int(rng.integers(1 << 30)), noise=noise)


def homography_onto(page_shape, quad):
    """Page corners (TL, TR, BR, BL) -> `quad` in the photo."""
    h, w = page_shape[:2]
    return estimate_homography(np.array([[0, 0], [w, 0], [w, h], [0, h]], dtype=float), np.array(quad, dtype=float))


def psnr(a, b):
    return 10 * np.log10(1.0 / np.mean((np.asarray(a, float) - np.asarray(b, float)) ** 2))


@pytest.fixture(scope="module")
def template():
    return make_template(synthetic_render(), dpi=DPI)


# --------------------------------------------------------------------------- template

def test_template_page_layout(template):
    page = template.image
    assert template.page_mm == [297.0, 210.0]  # A4 landscape for a landscape render
    assert page.shape == (round(210 * DPI / 25.4), round(297 * DPI / 25.4), 3)
    x0, y0, x1, y1 = template.picture
    assert (x1 - x0) / (y1 - y0) == pytest.approx(W / H, rel=0.02)
    picture = page[y0:y1, x0:x1]
    assert picture.min() >= 0.75 - 1e-6 and picture.max() <= 1.0  # low contrast
    assert picture.max() - picture.min() > 0.1  # but visible
    side = template.mark_size
    for i, (mx, my) in enumerate(template.marks):
        # Outside the picture area, black with a white centre.
        assert mx < x0 - side / 2 or mx > x1 + side / 2
        assert page[int(my), int(mx)].max() == 1.0
        assert page[int(my - 0.4 * side), int(mx - 0.4 * side)].max() == 0.0
        # Only the key mark (top-left) has its hole reach 40 % of the way out.
        assert (page[int(my), int(mx + 0.4 * side * 0.6)].max() == 1.0) == (i == 0)
    assert template.marks[0][0] < template.marks[1][0] and template.marks[0][1] < template.marks[3][1]


def test_template_rejects_bad_input():
    with pytest.raises(ValueError, match="render"):
        make_template(np.zeros(5))
    with pytest.raises(ValueError, match="contrast"):
        make_template(np.zeros((4, 4, 3)), contrast=0.0)


def test_pdf_holds_one_page_sized_image(template, tmp_path):
    path = tmp_path / "template.pdf"
    write_pdf(path, template.image, template.page_mm, caption="Tempera exemplar kit (test)")
    data = path.read_bytes()
    assert data.startswith(b"%PDF-1.4") and data.rstrip().endswith(b"%%EOF")
    assert data.count(b"/Subtype /Image") == 1 and data.count(b"/Type /Page ") == 1
    h, w = template.image.shape[:2]
    assert f"/Width {w} /Height {h}".encode() in data
    length = int(re.search(rb"/Subtype /Image.*?/Length (\d+) >>\nstream\n", data).group(1))
    start = data.index(b"stream\n", data.index(b"/Subtype /Image")) + len(b"stream\n")
    assert len(zlib.decompress(data[start:start + length])) == w * h * 3
    assert b"/MediaBox [0 0 841.89 595.28]" in data  # A4 landscape in points
    # The cross-reference table points at every object.
    xref = int(data.rsplit(b"startxref\n", 1)[1].split()[0])
    offsets = [int(line[:10]) for line in data[xref:].split(b"\n")[3:9]]
    assert all(data[o:].startswith(f"{i} 0 obj".encode()) for i, o in enumerate(offsets, 1))


# --------------------------------------------------------------------------- homography

def test_homography_recovers_a_known_matrix():
    known = np.array([[1.2, 0.1, 30.0], [-0.05, 0.9, 12.0], [2e-4, -1e-4, 1.0]])
    rng = np.random.default_rng(1)
    src = rng.uniform(0, 800, (4, 2))
    assert np.allclose(estimate_homography(src, apply_homography(known, src)), known, rtol=1e-6, atol=1e-9)
    # More points with noise: least squares, still close.
    src = rng.uniform(0, 800, (30, 2))
    dst = apply_homography(known, src) + rng.normal(0, 0.2, (30, 2))
    est = estimate_homography(src, dst)
    assert np.abs(apply_homography(est, src) - apply_homography(known, src)).max() < 1.0
    with pytest.raises(ValueError):
        estimate_homography(src[:3], dst[:3])


def test_label_components():
    mask = np.array([[1, 1, 0, 1],
                     [0, 1, 0, 1],
                     [1, 1, 0, 0],
                     [0, 0, 1, 1]], dtype=bool)
    labels = label_components(mask)
    assert labels[0, 0] == labels[2, 0] == labels[1, 1] and labels[0, 3] == labels[1, 3] == 3
    assert labels[3, 2] == labels[3, 3] == 14 and labels[0, 2] == -1
    assert len(np.unique(labels[mask])) == 3
    spiral = np.ones((40, 40), dtype=bool)
    spiral[1::4, :-2] = False
    spiral[3::4, 2:] = False
    assert len(np.unique(label_components(spiral)[spiral])) == 1  # one long winding component


# --------------------------------------------------------------------------- registration

# Page corners (TL, TR, BR, BL) in the photo: turned 90 degrees clockwise
# with perspective, and upside down (180 degrees) with a milder one.
TURNED_90 = [(780, 40), (740, 630), (60, 600), (90, 70)]
TURNED_180 = [(770, 620), (60, 580), (80, 60), (800, 90)]


@pytest.mark.parametrize("quad", [TURNED_90, TURNED_180], ids=["90deg", "180deg"])
def test_registration_recovers_the_painting(template, quad):
    rng = np.random.default_rng(3)
    painting = known_painting()
    page = painted_page(template, painting)
    to_photo = homography_onto(page.shape, quad)
    photo = photograph(page, to_photo, (860, 680), rng)

    found = find_marks(photo)
    expected = apply_homography(to_photo, np.array(template.marks))
    assert np.abs(found - expected).max() < 1.5  # photo pixels, in MARK_ORDER

    style = register_painting(photo, template.geometry())
    assert style.shape == (H, W, 3) and style.dtype == np.float32
    interior = (slice(2, -2), slice(2, -2))
    assert psnr(style[interior], painting[interior]) >= 25.0
    # Without flattening, the photo's uneven light stays in.
    dim = register_painting(photo, template.geometry(), flatten=False)
    assert psnr(dim[interior], painting[interior]) < psnr(style[interior], painting[interior]) - 3


def test_registration_survives_jpeg(template, tmp_path):
    rng = np.random.default_rng(4)
    painting = known_painting()
    photo = photograph(painted_page(template, painting), homography_onto(template.image.shape, TURNED_180),
                       (860, 680), rng, noise=0.02)
    tempera.write_image(str(tmp_path / "photo.jpg"), photo)
    style = register_painting(tempera.read_image(str(tmp_path / "photo.jpg")), template.geometry())
    assert psnr(style[2:-2, 2:-2], painting[2:-2, 2:-2]) >= 25.0


def test_covered_mark_is_reported(template):
    page = painted_page(template, known_painting())
    mx, my = template.marks[2]
    r = int(template.mark_size)
    page[int(my) - r:int(my) + r, int(mx) - r:int(mx) + r] = [0.2, 0.5, 0.3]  # a blob of paint over it
    photo = photograph(page, homography_onto(page.shape, TURNED_180), (860, 680), np.random.default_rng(5))
    with pytest.raises(ValueError, match="found 3 of 4 alignment marks; make sure all four corner marks"):
        register_painting(photo, template.geometry())


def test_key_mark_must_be_recognisable(template):
    page = painted_page(template, known_painting())
    mx, my = template.marks[0]
    r = template.mark_size / 2
    page[int(my - 0.9 * r):int(my + 0.9 * r), int(mx - 0.9 * r):int(mx + 0.9 * r)] = 0.0  # key hole painted shut ...
    page[int(my - 0.2 * r):int(my + 0.2 * r), int(mx - 0.2 * r):int(mx + 0.2 * r)] = 1.0  # ... but for a dot
    photo = photograph(page, homography_onto(page.shape, TURNED_90), (860, 680), np.random.default_rng(6))
    with pytest.raises(ValueError, match="top-left"):
        find_marks(photo)


def test_register_painting_command(template, tmp_path):
    kit = tmp_path / "kit"
    kit.mkdir()
    write_kit_json(kit / "kit.json", template, variant="test")
    photo = photograph(painted_page(template, known_painting()), homography_onto(template.image.shape, TURNED_90),
                       (860, 680), np.random.default_rng(7))
    tempera.write_image(str(tmp_path / "photo.png"), photo)
    command = [sys.executable, "-m", "tempera.methods.stylit.register_painting", str(tmp_path / "photo.png"),
               "--kit", str(kit)]
    result = subprocess.run(command + ["--out", str(tmp_path / "style.png")], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert tempera.read_image(str(tmp_path / "style.png")).shape[:2] == (H, W)

    tempera.write_image(str(tmp_path / "blank.png"), np.ones((300, 400, 3), np.float32))
    result = subprocess.run([sys.executable, "-m", "tempera.methods.stylit.register_painting", str(tmp_path / "blank.png"),
                             "--kit", str(kit), "--out", str(tmp_path / "x.png")], capture_output=True, text=True)
    assert result.returncode != 0 and "found 0 of 4 alignment marks" in result.stderr
    result = subprocess.run(command[:-1] + [str(tmp_path), "--out", str(tmp_path / "x.png")],
                            capture_output=True, text=True)
    assert result.returncode != 0 and "kit.json" in result.stderr


def test_dark_paint_and_a_look_alike_do_not_confuse_it(template):
    """Dark strokes over the picture and, inside it, a doodle shaped like a
    mark but smaller: the four real marks are still the ones found."""
    page = painted_page(template, known_painting())
    x0, y0, x1, y1 = template.picture
    rng = np.random.default_rng(8)
    for _ in range(60):  # short dark strokes
        x, y = rng.integers(x0, x1 - 12), rng.integers(y0, y1 - 3)
        page[y:y + 2, x:x + 12] = 0.05
    s = int(template.mark_size * 0.6)
    cx, cy = (x0 + x1) // 2, (y0 + y1) // 2
    page[cy - s // 2:cy + s // 2, cx - s // 2:cx + s // 2] = 0.0
    page[cy - 2:cy + 2, cx - 2:cx + 2] = 1.0
    to_photo = homography_onto(page.shape, TURNED_90)
    photo = photograph(page, to_photo, (860, 680), rng)
    expected = apply_homography(to_photo, np.array(template.marks))
    assert np.abs(find_marks(photo) - expected).max() < 1.5
