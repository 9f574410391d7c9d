"""A tiny synthetic guide cache for the stylization tests: a shaded gradient
with a bright blob moving right by `speed` pixels per frame, written with
tempera.app.guide_cache like the Blender renderer writes it."""
import numpy as np

from tempera.app import guide_cache
from tempera import write_image

H, W = 48, 64


def light_paths(blob_x, h=H, w=W):
    """Linear FULL, LDE, LSE, LDDE of a frame with the blob centred at blob_x."""
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    blob = np.exp(-((xx - blob_x) ** 2 + (yy - h / 2) ** 2) / (2 * (h / 6) ** 2))
    diffuse = 0.15 + 0.6 * xx / w + 1.5 * blob
    tint = np.stack([diffuse, 0.8 * diffuse, 0.5 * diffuse + 0.2 * yy / h], -1)
    spec = np.stack([blob**8] * 3, -1) * 2
    indirect = 0.1 * np.stack([1 - yy / h, 0.5 * np.ones_like(yy), yy / h], -1)
    return {"FULL": tint + spec + indirect, "LDE": tint, "LSE": spec, "LDDE": indirect}


def layer_masks(blob_x, h=H, w=W):
    """Collection masks of the blob (a disk) and the rest, and a depth with the blob in front."""
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    blob = (np.hypot(xx - blob_x, yy - h / 2) < h / 5).astype(np.float32)
    return {"mask.CO_Blob": blob, "mask.CO_Rest": 1 - blob, "depth": np.where(blob > 0, 2.0, 10.0).astype(np.float32)}


def write_frame(cache, frame, blob_x, speed, forward=False, masks=False, size=(W, H)):
    w, h = size
    guides = light_paths(blob_x, h, w)
    guides["velocity_backward"] = np.stack([np.full((h, w), speed, np.float32), np.zeros((h, w), np.float32)], -1)
    visible = np.ones((h, w), np.float32)
    visible[:, : int(np.ceil(speed))] = 0  # entered from outside the frame
    guides["occlusion_backward"] = visible
    if forward:  # V+ and χ+ (the coherent method's backward sweeps), and lines around the blob (eq. 9)
        from tempera.engine.guides import line_distance

        guides["velocity_forward"] = guides["velocity_backward"]
        leaving = np.ones((h, w), np.float32)
        leaving[:, w - int(np.ceil(speed)):] = 0  # about to leave the frame
        guides["occlusion_forward"] = leaving
        yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
        guides["lines"] = (np.abs(np.hypot(xx - blob_x, yy - h / 2) - h / 4) < 0.75).astype(np.float32)
        guides["line_distance"] = line_distance(guides["lines"], 10.0)
    guides["alpha"] = np.ones((h, w), np.float32)
    if masks:  # layers of the coherent method
        guides.update(layer_masks(blob_x, h, w))
    return guide_cache.write_frame(cache, frame, guides)


def make_cache(cache, frames=(1, 2, 3), speed=2.0, start=20.0, forward=False, masks=False, size=(W, H)):
    for i, frame in enumerate(frames):
        write_frame(cache, frame, start + speed * i, speed, forward, masks, size)
    guide_cache.write_manifest(cache, {"frames": {str(f): {"key": "synthetic"} for f in frames},
                                       "guides": ["FULL", "LDE", "LSE", "LDDE", "velocity_backward",
                                                  "occlusion_backward", "alpha"]})
    return cache


def make_exemplar(folder, painting_path, size=(W, H), frame=1):
    """Exemplar cache (blob centred) and a painting of it: coloured noise whose
    brightness follows the shading, at `size` (w, h)."""
    w, h = size
    write_frame(folder, frame, w / 2, 0.0, size=size)
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    shade = np.clip(0.2 + 0.6 * xx / w + 0.8 * np.exp(-((xx - w / 2) ** 2 + (yy - h / 2) ** 2) / (2 * (h / 6) ** 2)), 0, 1)
    paint = shade[..., None] * np.array([0.9, 0.6, 0.3], np.float32) + 0.25 * rng.random((h, w, 3), dtype=np.float32)
    write_image(str(painting_path), np.clip(paint, 0, 1).astype(np.float32))
    return folder, painting_path
