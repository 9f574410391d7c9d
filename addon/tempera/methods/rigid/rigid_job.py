"""The rigid-body method (tempera.methods.rigid.rigid) as a job of steps, for the panel's
"Rigid Bodies (hand-drawn)" method; no bpy. OUT is the method's own folder
(the panel's Output Folder/rigid).

    job = RigidJob(cache, examples, out, frames, objects=None, shape="circle", paper=False, strokes=None,
                   **rigid_options)
    for i in range(job.total): job.run_step(i, progress)

CACHE is a guide cache with tracks.json (rendering the guides of a scene with
a rigid-body world writes it); EXAMPLES is one exemplar folder as `tempera
rigid --exemplar` takes it (tracks.json and drawn/NNNN.png) or a folder of
such folders; STROKES a stroke exemplar to re-synthesize the lines from
(tempera.methods.rigid.rigid_strokes; None: the drawn lines as they are); rigid_options are
RigidOptions keywords (k, augment, damp, stroke_weight...). The steps: one per target object and chunk of CHUNK frames
(the object's layer, OUT/layers/<object>/frame_NNNN.png, RGBA), then one per
chunk compositing the layers by depth, far to near, into OUT/frames (RGBA
to lay over the render, or opaque on paper). Every file is written to a
temporary name and renamed, then the step's record (the job core's format,
OUT/tempera_rigid/): a step whose record is current (same settings, files
unchanged) is kept, so a rerun resumes where a stopped run ended, and a step
stopped by its progress callback writes nothing. Files of other settings are
never deleted; a step of these settings replaces them.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ... import _native
from . import rigid, rigid_cli, rigid_strokes, rigid_tracks
from ...app import record

CHUNK = rigid_cli.CHUNK
LAYERS_DIR = "layers"
FRAMES_DIR = "frames"
def exemplar_folders(examples):
    """The exemplar folders of EXAMPLES: itself when it holds tracks.json,
    else its subfolders that do (sorted); none is an error naming the folder."""
    root = Path(examples)
    if not root.is_dir():
        raise FileNotFoundError(f"The rigid-body examples folder '{root}' does not exist.")
    if (root / rigid_tracks.TRACKS_NAME).is_file():
        return [root]
    found = sorted(d for d in root.iterdir() if (d / rigid_tracks.TRACKS_NAME).is_file())
    if not found:
        raise ValueError(f"'{root}' holds no example: an example is a folder with the source simulation's "
                         f"{rigid_tracks.TRACKS_NAME} and its drawn frames drawn/NNNN.png")
    return found


def _over(below, rgba):
    """Straight-alpha RGBA `rgba` over straight-alpha `below`."""
    a, b = rgba[:, :, 3:4], below[:, :, 3:4]
    alpha = a + b * (1 - a)
    colour = rgba[:, :, :3] * a + below[:, :, :3] * b * (1 - a)
    return np.concatenate([colour / np.maximum(alpha, 1e-6), alpha], axis=2)


class RigidJob:
    def __init__(self, cache, examples, out, frames, objects=None, shape="circle", paper=False, chunk=CHUNK,
                 strokes=None, **values):
        if shape not in rigid.SYMMETRY:
            raise ValueError(f"unknown proxy shape '{shape}' (circle or box)")
        self.cache, self.out, self.shape, self.paper = Path(cache), Path(out), shape, bool(paper)
        self.tracks = rigid_tracks.read_tracks(cache)
        names = sorted(self.tracks["objects"])
        self.objects = names if objects is None else list(objects)
        unknown = [n for n in self.objects if n not in self.tracks["objects"]]
        if unknown or not self.objects:
            raise ValueError(f"no rigid-body track of {', '.join(unknown) or 'any target object'} in "
                             f"{self.cache / rigid_tracks.TRACKS_NAME} (it tracks {', '.join(names) or 'none'})")
        self.width, self.height = rigid_tracks.frame_size(self.cache)
        start, count = self.tracks["frame_start"], len(self.tracks["objects"][self.objects[0]]["centre"])
        self.frames = list(frames)
        outside = [f for f in self.frames if not start <= f < start + count]
        if outside:
            raise ValueError(f"frames {outside[0]}.. are outside the tracked range {start}-{start + count - 1}: "
                             "render the guides of the whole simulation")
        self.examples = exemplar_folders(examples)
        self.values = {"symmetry": rigid.SYMMETRY[shape], **values}
        rigid.RigidOptions(**self.values)  # a named error now, not in the first step
        self.strokes = strokes or None
        self._stroke_exemplar = rigid_strokes.load_stroke_exemplar(strokes) if self.strokes else None
        self.key = self._settings_key()
        self.steps = [(name, c) for name in self.objects for c in rigid_cli.chunks(self.frames, chunk)]
        self.steps += [(None, c) for c in rigid_cli.chunks(self.frames, chunk)]  # None: composite
        self._exemplars = None  # fitted once, by the first step that needs them
        outputs = [p for step in range(len(self.steps)) for p in (*self._paths(step), self.record_path(step))]
        _native.refuse_writing_on_inputs([str(p) for p in outputs],
                                         rigid_cli.input_files(self.cache, self.examples, self.strokes))

    @property
    def total(self):
        return len(self.steps)

    def layer_path(self, name, frame):
        return self.out / LAYERS_DIR / name / f"frame_{frame:04d}.png"

    def output_path(self, frame):
        return self.out / FRAMES_DIR / f"frame_{frame:04d}.png"

    def _settings_key(self):
        # The tracks by content: rendering the guides rewrites tracks.json each time, unchanged.
        tracks = hashlib.sha256((self.cache / rigid_tracks.TRACKS_NAME).read_bytes()).hexdigest()
        parts = [tracks, self.shape, str(self.paper),
                 json.dumps(self.values, sort_keys=True), ",".join(self.objects),
                 rigid_cli.strokes_stamp(self.strokes) or ""]
        for d in self.examples:
            parts += [rigid_cli._stamp(d / rigid_tracks.TRACKS_NAME)]
            parts += sorted(rigid_cli._stamp(p) for p in (d / "drawn").glob("*.png"))
        return hashlib.sha256("\n".join(parts).encode()).hexdigest()

    def record_path(self, step):
        name, frames = self.steps[step]
        unit = "composite" if name is None else "layer_" + name.replace("/", "_")
        return self.out / rigid_cli.RECORDS_DIR / f"{unit}_{frames[0]:04d}-{frames[-1]:04d}.txt"

    def _step_key(self, step):
        name, frames = self.steps[step]
        return record.unit_key(self.key, name, frames)

    def _paths(self, step):
        name, frames = self.steps[step]
        return [self.layer_path(name, f) if name else self.output_path(f) for f in frames]

    def run_step(self, step, progress=None):
        """Does step `step`: {"status": "stylized" | "composited" | "kept",
        "object", "frames"}. progress(fraction) returning False cancels
        (tempera.Cancelled) and nothing of the step is written."""
        name, frames = self.steps[step]
        paths = self._paths(step)
        result = {"object": name, "frames": frames, "status": "kept"}
        if record.is_current(self.record_path(step), rigid_cli.RECORD_FORMAT, self._step_key(step), paths):
            return result
        if name is None:
            self._composite(frames, paths)
            result["status"] = "composited"
        else:
            self._stylize(name, frames, paths, progress)
            result["status"] = "stylized"
        record.write(self.record_path(step), rigid_cli.RECORD_FORMAT, self._step_key(step), paths)
        return result

    def _fitted(self):
        if self._exemplars is None:
            self._exemplars = [rigid_cli._read_exemplar(d, self.shape, {})[0] for d in self.examples]
        return self._exemplars

    def _stylize(self, name, frames, paths, progress):
        start = self.tracks["frame_start"]
        only = [f - start for f in frames]
        done = [0]

        def step_progress(_frame):
            done[0] += 1
            return progress is None or progress(done[0] / (len(only) + 1)) is not False

        images = rigid.stylize(self._fitted(), self.tracks["objects"][name], self.width, self.height,
                               progress=step_progress, only=only, **self.values)
        layers = [images[i][0] for i in only]
        if self._stroke_exemplar is not None:  # before any write: Esc here too writes nothing of the step
            def keep_going(_fraction):
                return progress is None or progress(len(only) / (len(only) + 1)) is not False

            layers = [rigid_strokes.restyle(rgba, self._stroke_exemplar, self.values, keep_going)
                      for rgba in layers]
        paths[0].parent.mkdir(parents=True, exist_ok=True)
        for layer, path in zip(layers, paths):
            rgba = np.ascontiguousarray(layer, np.float32)
            _native.write_image(str(path), rgba, [])

    def depth_order(self, frame):
        """The objects far to near at `frame` (the tracks' camera depth;
        tracks without it keep the objects' order)."""
        i = frame - self.tracks["frame_start"]
        track = self.tracks["objects"]
        return sorted(self.objects, key=lambda n: -track[n]["depth"][i] if "depth" in track[n] else 0.0)

    def _composite(self, frames, paths):
        paths[0].parent.mkdir(parents=True, exist_ok=True)
        for frame, path in zip(frames, paths):
            img = np.zeros((self.height, self.width, 4), np.float32)
            if self.paper:
                img[:] = (*rigid_cli.PAPER, 1.0)
            for name in self.depth_order(frame):
                layer = _native.read_image(str(self.layer_path(name, frame)), None)
                img = _over(img, np.asarray(layer, np.float32))
            _native.write_image(str(path), np.ascontiguousarray(img), [])
