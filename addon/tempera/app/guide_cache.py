"""The guide cache: one multilayer EXR per frame plus a JSON manifest, with no bpy.

Layout of a cache folder (documented in docs/guide_cache.md):

    <cache>/manifest.json        what was rendered, how, and a key per frame
    <cache>/frame_0001.exr       every guide of frame 1, one EXR channel per component
    ...

Channel names are "<guide>.<component>" (GUIDES below); masks are
"mask.<OB_|CO_><name>.V"; light path expression guides are "lpe_<name>.R/G/B"
(lpe_guide below). All values are float32 and linear (light-path
guides are radiance, not tone-mapped: apply tempera.engine.guides.tonemap).
Images are rows top-down; x runs right and y down, velocities are in pixels
with the conventions of tempera.engine.guides.

Also here, because they need only numpy: converting Blender's Vector pass to
the two velocity fields, and the line guide from depth and normal
discontinuities. The Blender side is tempera.blender.guide_render.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import secrets
import tempfile
import warnings
from pathlib import Path

import numpy as np

from .. import _native

MANIFEST_NAME = "manifest.json"
FORMAT_VERSION = 1

# guide name -> channel components, in the order they are written: StyLit's
# light paths (RGB radiance; how each is made from Cycles' passes:
# tempera.blender.guide_render.light_path_guides), then the native job core's
# table of the others (native/include/tempera/app/guide_cache.hpp, with what
# each holds: _native.cache_guides()).
GUIDES = {
    **{g["name"]: "RGB" for g in _native.light_path_guides()},
    **{g["name"]: tuple(g["components"]) for g in _native.cache_guides()},
}

# Defaults of the parameters that change the guides; they are part of each frame's key.
DEFAULT_PARAMS = {
    "samples": 16,  # Cycles samples of the main render
    "ld12e_samples": 16,  # Cycles samples of the second (LD{1,2}E) render
    "seed": 0,
    "occlusion_epsilon": 2.0,  # squared pixels, Bénard 2013 §3.1
    "tensor_sigma": 2.0,  # Gaussian of the structure tensor, pixels
    "line_depth_threshold": 0.05,  # relative depth jump that makes a line
    "line_normal_angle": 40.0,  # degrees between neighbouring normals that makes a line
    "line_d_max": 10.0,  # bound of the line distance, pixels (Bénard 2013 §3.2)
    "masks": "objects+collections",  # or "objects", "collections", "none"
    # A Color shader AOV of the view layer in which the artist's materials
    # write the stroke direction in screen space (R = x right, G = y up);
    # "" computes the orientation from the render instead.
    "orientation_aov": "",
    # Light path expressions (docs/lpe_guides.md) traced by Tempera's own path
    # tracer, each written as an RGB guide named by lpe_guide(); [] for none.
    "lpe": [],
    "lpe_samples": 64,  # tracer samples per pixel of every expression
}

LPE_PREFIX = "lpe_"


def channel_names(guide):
    """EXR channel names of one guide, e.g. ['velocity_forward.X', 'velocity_forward.Y']."""
    if guide.startswith("mask."):
        return [f"{guide}.V"]
    if guide.startswith(LPE_PREFIX):
        return [f"{guide}.{c}" for c in "RGB"]
    try:
        return [f"{guide}.{c}" for c in GUIDES[guide]]
    except KeyError:
        raise ValueError(f"unknown guide {guide!r}; known guides: {', '.join(GUIDES)} and mask.<name>") from None


def mask_guide(kind, name):
    """Guide name of an object ('OB') or collection ('CO') mask. Dots would
    split the EXR layer name, so they become '_' (the manifest keeps the real name)."""
    if kind not in ("OB", "CO"):
        raise ValueError(f"mask kind must be 'OB' or 'CO', got {kind!r}")
    return f"mask.{kind}_{name.replace('.', '_')}"


def masks_including(mode, kind):
    """The "masks" parameter that renders the masks `mode` renders and those
    of `kind` ('OB' objects, 'CO' collections) too: a method whose target is
    an object's or a collection's mask widens the guides' masks to include it."""
    wanted = {"OB": "objects", "CO": "collections"}[kind]
    kinds = ({"objects", "collections"} if mode == "objects+collections" else {mode}) - {"none"} | {wanted}
    return "objects+collections" if len(kinds) == 2 else wanted


def lpe_guide(expression):
    """Guide name of a light path expression: "lpe_" and the expression if it
    is only letters and digits ("LDE" -> "lpe_LDE"); otherwise every run of
    other characters becomes "_" and 8 hex digits of the expression's SHA-1
    follow ("L.*DDE" -> "lpe_L_DDE_<hash>"), so no two expressions share a name
    and no dot splits the EXR layer. The manifest maps names to expressions."""
    safe = re.sub(r"[^A-Za-z0-9]+", "_", expression).strip("_")
    if safe == expression:
        return LPE_PREFIX + expression
    digest = hashlib.sha1(expression.encode()).hexdigest()[:8]
    return f"{LPE_PREFIX}{safe}_{digest}" if safe else f"{LPE_PREFIX}{digest}"


def split_expressions(text):
    """Light path expressions of a ';' or ',' separated list, e.g. the
    add-on's text field: "L.*SDE; LD{1,2}E" -> ["L.*SDE", "LD{1,2}E"]. Commas
    inside braces belong to a repeat count, not the list."""
    out, depth, current = [], 0, ""
    for char in text:
        depth += {"{": 1, "}": -1}.get(char, 0)
        if char == ";" or (char == "," and depth <= 0):
            out.append(current)
            current = ""
        else:
            current += char
    out.append(current)
    return [e.strip() for e in out if e.strip()]


def frame_path(cache_dir, frame):
    return Path(cache_dir) / f"frame_{frame:04d}.exr"


# --------------------------------------------------------------------------- manifest

def frame_key(params, fingerprint):
    """A hash of everything a frame's guides depend on: the parameters and a
    description of the scene at that frame (any JSON-able value)."""
    text = json.dumps({"format": FORMAT_VERSION, "params": params, "scene": fingerprint},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _manifest_problem(manifest):
    """What makes a parsed manifest unusable, or None."""
    if not isinstance(manifest, dict):
        return f"it holds a {type(manifest).__name__}, not an object"
    frames = manifest.get("frames", {})
    if not isinstance(frames, dict):
        return "its 'frames' is not an object"
    for number, entry in frames.items():
        if not (isinstance(number, str) and number.isdigit() and isinstance(entry, dict)
                and isinstance(entry.get("key"), str)):
            return f"its entry for frame {number!r} is malformed"
    if not isinstance(manifest.get("params", {}), dict):
        return "its 'params' is not an object"
    return None


def read_manifest(cache_dir, on_warning=None, set_aside=True):
    """The manifest dict, or None if the folder has none (or one of another
    format version, which a rerun then overwrites).

    A damaged manifest (not JSON, not UTF-8, the wrong structure) is renamed
    aside to manifest.json.corrupt-<random> and None is returned, so that the
    frames are rendered again instead of the run being blocked; the warning
    naming both files goes to `on_warning(text)` (default: warnings.warn).
    set_aside=False only returns None (for readers such as a panel's status
    line, which must not move files)."""
    path = Path(cache_dir) / MANIFEST_NAME
    try:
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
        problem = _manifest_problem(manifest)
    except FileNotFoundError:
        return None
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as exc:
        problem = f"it is not valid JSON ({exc})"
    if problem is None:
        return manifest if manifest.get("format") == FORMAT_VERSION else None
    if not set_aside:
        return None
    aside = path.with_name(f"{MANIFEST_NAME}.corrupt-{secrets.token_hex(4)}")
    try:
        os.replace(path, aside)
        where = f"set aside as {aside.name}"
    except OSError as exc:
        where = f"left in place ({exc.strerror})"
    text = f"the guide cache manifest {path} is damaged: {problem}; {where}, its frames are rendered again"
    (on_warning or (lambda t: warnings.warn(t, stacklevel=3)))(text)
    return None


def write_manifest(cache_dir, manifest):
    """Writes manifest.json atomically (temporary file with a random name,
    then rename), readable by all like the frames (mode 0666 minus umask)."""
    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".manifest.", suffix=".partial", dir=cache_dir)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)  # mkstemp makes 0600
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(dict(manifest, format=FORMAT_VERSION), f, indent=2, sort_keys=True)
        os.replace(tmp, cache_dir / MANIFEST_NAME)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def manifest_lock(cache_dir):
    """Holds an exclusive lock on the cache folder (flock on the folder
    itself, so no lock file is left) so that processes sharing it, e.g.
    render-farm jobs, merge their frames into the manifest instead of
    overwriting each other's."""
    import fcntl

    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    fd = os.open(cache_dir, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def update_manifest(cache_dir, update, on_warning=None):
    """Re-reads the manifest under the lock, calls update(manifest) (a dict,
    {} if there is none; it changes it in place) and writes it back.
    Returns the manifest written."""
    with manifest_lock(cache_dir):
        manifest = read_manifest(cache_dir, on_warning) or {}
        update(manifest)
        write_manifest(cache_dir, manifest)
        return manifest


def file_digest(path):
    """(size in bytes, SHA-256 hex) of a file, read in 1 MiB chunks."""
    digest = hashlib.sha256()
    size = 0
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
            size += len(chunk)
    return size, digest.hexdigest()


def frame_entry(cache_dir, frame, key):
    """The manifest entry of a frame just written: its key, file, and the
    size and checksum that is_frame_current() checks."""
    path = frame_path(cache_dir, frame)
    size, sha256 = file_digest(path)
    return {"key": key, "file": path.name, "size": size, "sha256": sha256}


def is_frame_current(cache_dir, manifest, frame, key, verify=True):
    """True if the cache holds frame `frame` rendered with this key, intact:
    the file has the size recorded and (with `verify`) the recorded SHA-256,
    so a truncated or overwritten EXR is rendered again. verify=False checks
    the size only (cheap enough for a panel's status line)."""
    if not manifest:
        return False
    entry = manifest.get("frames", {}).get(str(frame))
    if not entry or entry.get("key") != key:
        return False
    path = frame_path(cache_dir, frame)
    try:
        if path.stat().st_size != entry.get("size"):
            return False
        return not verify or file_digest(path)[1] == entry.get("sha256")
    except OSError:
        return False


def read_frame(cache_dir, frame, guides=None):
    """Guides of one cached frame as {name: float32 (H, W, C) array} (C = 1
    for single-channel guides, which come back as (H, W)). `guides` defaults
    to every guide listed in the manifest."""
    from .. import read_image

    if guides is None:
        manifest = read_manifest(cache_dir)
        if manifest is None:
            raise FileNotFoundError(f"no guide cache manifest in {cache_dir}")
        guides = manifest["guides"]
    path = str(frame_path(cache_dir, frame))
    out = {}
    for guide in guides:
        array = read_image(path, channel_names(guide))
        out[guide] = array[:, :, 0] if array.shape[2] == 1 else array
    return out


def write_frame(cache_dir, frame, guides):
    """Writes {guide name: (H, W) or (H, W, C) array} as frame `frame`'s EXR,
    atomically (tempera.write_image). Returns the path."""
    from .. import write_image

    arrays, names = [], []
    for guide, array in guides.items():
        a = np.asarray(array, np.float32)
        a = a[:, :, None] if a.ndim == 2 else a
        expected = channel_names(guide)
        if a.shape[2] != len(expected):
            raise ValueError(f"guide {guide!r} has {a.shape[2]} channels, its layout has {len(expected)}")
        arrays.append(a)
        names += expected
    path = frame_path(cache_dir, frame)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_image(str(path), np.ascontiguousarray(np.concatenate(arrays, axis=2)), names)
    return path


# --------------------------------------------------------------------------- conversions

def velocities_from_vector_pass(vector):
    """Blender's Vector pass (H, W, 4), rows top-down -> (velocity_backward,
    velocity_forward), each (H, W, 2) in pixels, x right, y down.

    Blender stores, with y up and p(f) the pixel position of the surface point
    in frame f: XY = p(f-1) - p(f) and ZW = p(f) - p(f+1).
    tempera.engine.guides wants V-_t = p(t) - p(t-1) (the point came from p - V-) and
    V+_t = p(t+1) - p(t) (it goes to p + V+), i.e. V- = -XY and V+ = -ZW with
    y up. Turning y down negates the y components: V- = (-X, +Y), V+ = (-Z, +W).
    """
    v = np.asarray(vector, np.float32)
    if v.ndim != 3 or v.shape[2] != 4:
        raise ValueError(f"Vector pass must be (H, W, 4), got shape {v.shape}")
    backward = np.stack([-v[:, :, 0], v[:, :, 1]], axis=2)
    forward = np.stack([-v[:, :, 2], v[:, :, 3]], axis=2)
    return backward, forward


def line_guide(depth, normal, depth_threshold=0.05, normal_angle=40.0):
    """1 on pixels at a depth or normal discontinuity, else 0 ((H, W) float32).

    Between each pixel and its right and lower neighbour: a depth jump larger
    than `depth_threshold` times the nearer depth (a silhouette or an
    occluding contour; the background's huge depth counts as far away) marks
    the nearer pixel, so lines lie on the occluding object; normals more than
    `normal_angle` degrees apart (a crease) mark the upper / left pixel.
    """
    z = np.asarray(depth, np.float64)
    z = z[:, :, 0] if z.ndim == 3 else z
    n = np.asarray(normal, np.float64)[:, :, :3]
    if z.shape != n.shape[:2]:
        raise ValueError(f"depth {z.shape} and normal {n.shape[:2]} differ in size")
    z = np.where(np.isfinite(z), z, 1e10)
    norm = np.linalg.norm(n, axis=2, keepdims=True)
    unit = np.divide(n, norm, out=np.zeros_like(n), where=norm > 1e-6)
    has_normal = norm[:, :, 0] > 1e-6
    cos_max = np.cos(np.radians(normal_angle))
    lines = np.zeros(z.shape, bool)
    for axis in (0, 1):  # neighbour below, neighbour to the right
        a = [slice(None)] * 2
        b = [slice(None)] * 2
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        a, b = tuple(a), tuple(b)
        za, zb = z[a], z[b]
        jump = np.abs(za - zb) > depth_threshold * np.minimum(za, zb)
        lines[a] |= jump & (za <= zb)
        lines[b] |= jump & (zb < za)
        crease = (np.sum(unit[a] * unit[b], axis=2) < cos_max) & has_normal[a] & has_normal[b] & ~jump
        lines[a] |= crease
    return lines.astype(np.float32)
