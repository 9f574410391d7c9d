"""The printable painting template of StyLit's workflow (Fišer et al. 2016,
thesis §8.3.1), with no bpy: the exemplar render "printed on paper in low
contrast with special alignment marks", for the artist to paint over.

    template = make_template(render_srgb)          # one page, as an image
    tempera.write_image("template.png", template.image)
    write_pdf("template.pdf", template.image, template.page_mm, caption="...")

The page (A4, landscape for a landscape render) holds the render, faded to
`contrast` so that paint covers it, as large as fits, and four black square
marks just outside the picture's corners. Each mark has a white hole; the
top-left one (the *key* mark) has a large square hole, the others a small
round dot, so that registration (tempera.methods.stylit.registration) can tell a photo's
orientation even when it is upside down. Nothing else on the page is black.
"""
import json
import zlib
from dataclasses import asdict, dataclass

import numpy as np

A4_MM = (210.0, 297.0)
MM_PER_INCH = 25.4
# Layout in millimetres. MARGIN keeps the marks clear of printers' unprintable
# borders; GAP keeps paint that strays over the picture's edge off the marks.
MARK_MM, GAP_MM, MARGIN_MM = 12.0, 5.0, 12.0
DOT_FRACTION = 0.3  # diameter of a mark's round dot / mark side
KEY_HOLE_FRACTION = 0.55  # side of the key mark's square hole / mark side
MARK_ORDER = ("top-left", "top-right", "bottom-right", "bottom-left")  # clockwise; the first is the key


@dataclass
class Template:
    """A template page. Coordinates are page pixels, x right, y down, with
    pixel (row i, column j) covering [j, j+1] x [i, i+1]."""

    image: np.ndarray  # (page height, page width, 3) float32 sRGB in [0, 1]
    marks: list  # 4 mark centres [x, y] in MARK_ORDER
    picture: list  # [x0, y0, x1, y1] of the picture rectangle
    mark_size: float  # mark side in pixels
    resolution: list  # [width, height] of the render (= the guides)
    dpi: float
    page_mm: list  # [width, height]

    def geometry(self):
        """Everything but the image, as plain JSON-able values (kit.json)."""
        info = asdict(self)
        del info["image"]
        info["mark_order"] = list(MARK_ORDER)
        return info


def sample_bilinear(image, xs, ys):
    """`image` (H, W, C) sampled at continuous pixel coordinates (xs, ys) of
    any shape (pixel centres at +0.5), edges clamped; returns (..., C)."""
    h, w = image.shape[:2]
    x = np.clip(np.asarray(xs, dtype=np.float64) - 0.5, 0.0, w - 1.0)
    y = np.clip(np.asarray(ys, dtype=np.float64) - 0.5, 0.0, h - 1.0)
    # The upper-left neighbour of each sample, kept one pixel from the far edge (fx, fy then reach 1).
    x0, y0 = np.minimum(x.astype(np.int64), max(w - 2, 0)), np.minimum(y.astype(np.int64), max(h - 2, 0))
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def picture_grid(picture, width, height, supersample=1):
    """Page coordinates (xs, ys), each (height, width, s*s), of s x s sample
    points spread over each of the width x height pixels of `picture`."""
    x0, y0, x1, y1 = picture
    offsets = (np.arange(supersample) + 0.5) / supersample
    sx = (np.arange(width)[:, None] + offsets[None, :]).ravel() * (x1 - x0) / width + x0
    sy = (np.arange(height)[:, None] + offsets[None, :]).ravel() * (y1 - y0) / height + y0
    xs, ys = np.meshgrid(sx, sy)  # (height*s, width*s)
    s = supersample
    to_cells = lambda a: a.reshape(height, s, width, s).transpose(0, 2, 1, 3).reshape(height, width, s * s)
    return to_cells(xs), to_cells(ys)


def place_picture(page, picture, image):
    """Draws `image` ((h, w, 3), any size) into the rectangle `picture` of
    `page` in place, bilinearly scaled; returns page. (The template's render,
    or in tests and docs a stand-in for the artist's paint.)"""
    x0, y0, x1, y1 = picture
    height, width = image.shape[:2]
    xs, ys = picture_grid(picture, x1 - x0, y1 - y0)  # one sample per page pixel
    page[y0:y1, x0:x1] = sample_bilinear(image, (xs[..., 0] - x0) * width / (x1 - x0),
                                         (ys[..., 0] - y0) * height / (y1 - y0))
    return page


def _layout(width, height, dpi):
    """(page size in mm, picture rectangle in px, mark centres in px, mark side in px)."""
    page_mm = (A4_MM[1], A4_MM[0]) if width >= height else A4_MM
    px = dpi / MM_PER_INCH
    border = MARGIN_MM + MARK_MM + GAP_MM
    scale = min((page_mm[0] - 2 * border) / width, (page_mm[1] - 2 * border) / height)  # mm per render pixel
    pic_w, pic_h = round(width * scale * px), round(height * scale * px)
    page_w, page_h = round(page_mm[0] * px), round(page_mm[1] * px)
    x0, y0 = (page_w - pic_w) // 2, (page_h - pic_h) // 2
    picture = [x0, y0, x0 + pic_w, y0 + pic_h]
    off = (GAP_MM + MARK_MM / 2) * px  # from a picture corner to the nearest mark centre, along x and y
    marks = [[x0 - off, y0 - off], [x0 + pic_w + off, y0 - off], [x0 + pic_w + off, y0 + pic_h + off],
             [x0 - off, y0 + pic_h + off]]
    return list(page_mm), (page_w, page_h), picture, marks, MARK_MM * px


def _draw_mark(page, centre, side, key):
    """A black square of `side` px with a white hole: a small disk, or for the
    key mark a large square."""
    cx, cy = centre
    r = side / 2
    top, left = int(cy - r) - 1, int(cx - r) - 1
    region = page[top:int(cy + r) + 2, left:int(cx + r) + 2]
    ys, xs = np.mgrid[:region.shape[0], :region.shape[1]]
    dx, dy = left + xs + 0.5 - cx, top + ys + 0.5 - cy  # pixel centres relative to the mark centre
    black = (np.abs(dx) <= r) & (np.abs(dy) <= r)
    if key:
        hole = (np.abs(dx) <= r * KEY_HOLE_FRACTION) & (np.abs(dy) <= r * KEY_HOLE_FRACTION)
    else:
        hole = np.hypot(dx, dy) <= r * DOT_FRACTION
    region[black] = 0.0
    region[hole] = 1.0


def make_template(render, *, dpi=150.0, contrast=0.25):
    """The template page of `render` ((H, W[, C]) sRGB-encoded, e.g. the
    exemplar's Combined pass through tempera.engine.color.linear_to_srgb).

    dpi       print resolution of the page image (A4 at 150 dpi: 1754 x 1240 px).
    contrast  the picture spans [1 - contrast, 1]: light enough for paint to
              cover, and far lighter than the marks, which stay the only black.
    """
    rgb = np.asarray(render, dtype=np.float64)
    if rgb.ndim == 2:
        rgb = rgb[:, :, None]
    if rgb.ndim != 3 or rgb.shape[0] < 2 or rgb.shape[1] < 2:
        raise ValueError(f"make_template: render must be an (H, W[, C]) array of at least 2x2, got {np.shape(render)}")
    rgb = np.repeat(rgb[:, :, :1], 3, axis=2) if rgb.shape[2] < 3 else rgb[:, :, :3]
    if not 0.0 < contrast <= 1.0:
        raise ValueError(f"make_template: contrast must be in (0, 1], got {contrast}")
    height, width = rgb.shape[:2]
    page_mm, (page_w, page_h), picture, marks, side = _layout(width, height, dpi)

    page = np.ones((page_h, page_w, 3))
    place_picture(page, picture, 1.0 - contrast * (1.0 - np.clip(rgb, 0.0, 1.0)))  # faded towards white
    for i, centre in enumerate(marks):
        _draw_mark(page, centre, side, key=(i == 0))
    return Template(page.astype(np.float32), marks, picture, side, [width, height], float(dpi), page_mm)


def write_kit_json(path, template, **extra):
    with open(path, "w") as f:
        json.dump({**extra, **template.geometry()}, f, indent=2)


def read_kit_json(path):
    with open(path) as f:
        return json.load(f)


# --------------------------------------------------------------------------- PDF

def write_pdf(path, image, page_mm, caption=None):
    """A one-page PDF of `page_mm` (width, height) showing `image` ((H, W, 3)
    in [0, 1]) over the whole page, 8-bit RGB, Flate-compressed; `caption`
    (ASCII) is set small in Helvetica at the bottom left. Self-written (PDF
    1.4, five objects) to need no PDF library."""
    rgb = (np.clip(np.asarray(image, dtype=np.float64)[:, :, :3], 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    h, w = rgb.shape[:2]
    pt_w, pt_h = (v * 72.0 / MM_PER_INCH for v in page_mm)
    content = f"q {pt_w:.2f} 0 0 {pt_h:.2f} 0 0 cm /Im0 Do Q\n"
    if caption:
        text = caption.encode("ascii", "replace").decode().replace("\\", "\\\\").replace("(", "\\(").replace(")", "\\)")
        content += f"BT /F1 8 Tf 0.45 g {MARGIN_MM * 72 / MM_PER_INCH:.2f} 14 Td ({text}) Tj ET\n"
    pixels = zlib.compress(rgb.tobytes(), 6)
    objects = [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
        (f"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {pt_w:.2f} {pt_h:.2f}] /Contents 4 0 R "
         f"/Resources << /XObject << /Im0 5 0 R >> /Font << /F1 6 0 R >> >> >>").encode(),
        f"<< /Length {len(content)} >>\nstream\n{content}endstream".encode(),
        (f"<< /Type /XObject /Subtype /Image /Width {w} /Height {h} /ColorSpace /DeviceRGB "
         f"/BitsPerComponent 8 /Filter /FlateDecode /Length {len(pixels)} >>\nstream\n").encode()
        + pixels + b"\nendstream",
        b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>",
    ]
    out = bytearray(b"%PDF-1.4\n%\xe2\xe3\xcf\xd3\n")
    offsets = []
    for number, body in enumerate(objects, 1):
        offsets.append(len(out))
        out += f"{number} 0 obj\n".encode() + body + b"\nendobj\n"
    xref = len(out)
    out += f"xref\n0 {len(objects) + 1}\n0000000000 65535 f \n".encode()
    out += b"".join(f"{o:010d} 00000 n \n".encode() for o in offsets)
    out += f"trailer\n<< /Size {len(objects) + 1} /Root 1 0 R >>\nstartxref\n{xref}\n%%EOF\n".encode()
    with open(path, "wb") as f:
        f.write(out)
