"""`tempera rigid`: the rigid-body method (tempera.methods.rigid.rigid) on a guide cache's
tracks, with no Blender.

    tempera rigid --cache CACHE [--exemplar EXEMPLAR|generated ...] --out OUT
                  [--object NAME] [--frames A-B] [--shape circle|box] [--paper]
                  [--strokes IMAGE|generated] [method options]

`tempera stylize --method rigid` is the registry's native job of the method
(native/src/methods/rigid/rigid_job.cpp): the same frames, byte for byte, in
OUT/frames, with the core's records, progress and resume.

CACHE holds tracks.json (tempera.methods.rigid.rigid_tracks) of the target simulation and
its manifest (the frame size). Each EXEMPLAR folder holds the source
simulation's tracks.json and its drawn frames, drawn/0001.png ... (RGBA ink,
numbered from the tracks' frame_start; every frame drawn). OUT receives
frame_0001.png ... (RGBA, straight alpha; --paper: opaque, on paper), each
written as soon as it is drawn (to a temporary file, then renamed), then its
record (the job core's format, OUT/tempera_rigid/frame_0001.txt: the key of
the inputs and options, the file's size and checksum). A rerun keeps every
frame whose record is current (resume, also after kill -9) and makes the
others; Ctrl-C stops between frames. No file is ever deleted: frames of other
settings are replaced only when their frame is made again.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

from ... import _native
from . import rigid, rigid_strokes, rigid_tracks
from ...app import record
from ...app.command import run_command
from ...app.frames import parse_frames

PAPER = (0.97, 0.96, 0.92)
CHUNK = 8  # frames drawn at once: memory holds this many, and Esc or kill -9 loses at most these
RECORDS_DIR = "tempera_rigid"
RECORD_FORMAT = "tempera-rigid 1"
OPTION_TABLES = (rigid.RigidOptions.table(), rigid.QuadraticFitOptions.table())


def _parser(prog="tempera rigid"):
    p = argparse.ArgumentParser(prog=prog, description=__doc__.split("\n\n")[0])
    p.add_argument("--cache", "--guides", dest="cache", required=True,
                   help="guide cache with the target's tracks.json")
    p.add_argument("--exemplar", action="append",
                   help="folder with a source tracks.json and drawn/NNNN.png (repeatable); default "
                   f"'{rigid.GENERATED}': the project's own drawn bouncing ball (box with --shape box), "
                   "written once into OUT/exemplar_generated_SHAPE")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--object", help="the target object (needed when the cache tracks several)")
    p.add_argument("--frames", help="frames to draw, e.g. 1-24 (default: every tracked frame)")
    p.add_argument("--shape", default="circle", choices=["circle", "box"], help="the objects' proxy (circle)")
    p.add_argument("--paper", action="store_true", help="opaque frames on paper instead of RGBA")
    p.add_argument("--strokes", help="re-synthesize the lines from this stroke exemplar (an RGBA image of strokes, "
                   f"or '{rigid_strokes.GENERATED}': the project's blue brush pen) on a stroke-position guide")
    for table in OPTION_TABLES:
        for row in table:
            kind = type(row["default"])
            if kind is bool:
                p.add_argument(f"--{row['flag']}", dest=row["name"], choices=["true", "false"], help=row["help"])
            elif kind is list:
                p.add_argument(f"--{row['flag']}", dest=row["name"], help=row["help"] + " (comma-separated)")
            else:
                p.add_argument(f"--{row['flag']}", dest=row["name"], type=kind, help=row["help"])
    return p


def _values(args, table):
    out = {}
    for row in table:
        v = getattr(args, row["name"])
        if v is None:
            continue
        if isinstance(row["default"], bool):
            v = v == "true"
        elif isinstance(row["default"], list):
            try:
                v = [float(x) for x in v.split(",")]
            except ValueError:
                raise ValueError(f"--{row['flag']} expects comma-separated numbers, got '{v}'") from None
        out[row["name"]] = v
    return out


def _one_object(tracks, name, where):
    objects = tracks["objects"]
    if name is None:
        if len(objects) != 1:
            raise ValueError(f"{where} tracks {len(objects)} objects ({', '.join(sorted(objects))}): name one with --object")
        name = next(iter(objects))
    if name not in objects:
        raise ValueError(f"{where} has no object '{name}' (it has {', '.join(sorted(objects)) or 'none'})")
    return name, objects[name]


def _read_exemplar(folder, shape, fit_values):
    folder = Path(folder)
    tracks = rigid_tracks.read_tracks(folder)
    _, track = _one_object(tracks, None, f"exemplar {folder}")
    drawings = []
    for i in range(len(track["centre"])):
        path = folder / "drawn" / f"{tracks['frame_start'] + i:04d}.png"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: drawn frame missing (every frame of the exemplar must be drawn)")
        image = _native.read_image(str(path), None)
        if image.ndim != 3 or image.shape[2] != 4:
            raise ValueError(f"{path}: a drawn frame must be RGBA (ink in alpha)")
        drawings.append(image)
    return rigid.fit_exemplar(track, drawings, shape=shape, **fit_values), folder


def generated_exemplar_folder(out, shape):
    """The project's own exemplar for `shape` as an exemplar folder in OUT
    (tracks.json and drawn/NNNN.png), written once: the tracks last, so a
    folder with tracks is whole, and a rerun finds it unchanged (resume)."""
    folder = Path(out) / f"exemplar_generated_{shape}"
    if not (folder / rigid_tracks.TRACKS_NAME).is_file():
        track = rigid.generated_track(shape)
        (folder / "drawn").mkdir(parents=True, exist_ok=True)
        for i, drawing in enumerate(rigid.generated_exemplar(track, *rigid.GENERATED_SIZE, shape=shape)):
            _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), drawing, [])
        rigid_tracks.write_tracks(folder, {"Generated": track}, 1, (0, 1.0))
    return folder


def _stamp(path):
    st = Path(path).stat()
    return f"{path}:{st.st_size}:{st.st_mtime_ns}"


def _settings_key(args, exemplar_dirs, values):
    parts = [_stamp(Path(args.cache) / rigid_tracks.TRACKS_NAME), args.object or "", args.shape, str(args.paper),
             json.dumps(values, sort_keys=True), strokes_stamp(args.strokes) or ""]
    for d in exemplar_dirs:
        parts += [_stamp(d / rigid_tracks.TRACKS_NAME)] + sorted(_stamp(p) for p in (d / "drawn").glob("*.png"))
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def input_files(cache, exemplar_dirs, strokes):
    """Every file the method reads, as (path, what): no output may replace one
    (the job core's rule, docs/cli.md "Inputs are never written")."""
    files = [(Path(cache) / rigid_tracks.TRACKS_NAME, "target tracks"), (Path(cache) / "manifest.json", "manifest")]
    for d in map(Path, exemplar_dirs):
        files.append((d / rigid_tracks.TRACKS_NAME, "exemplar tracks"))
        files += [(p, "drawn exemplar frame") for p in sorted((d / "drawn").glob("*.png"))]
    if strokes not in (None, "", rigid_strokes.GENERATED):
        files.append((Path(strokes), "stroke exemplar"))
    return [(str(p), what) for p, what in files]


def strokes_stamp(spec):
    """The stroke exemplar in a settings key ('' for none)."""
    return spec if spec in (None, "", rigid_strokes.GENERATED) else _stamp(spec)


def chunks(items, size):
    return [items[i:i + size] for i in range(0, len(items), size)]


def _frame_indices(text, start, count):
    """Track indices of the frames of --frames (all when None); a frame
    outside the tracks is an error naming the tracked range."""
    if text is None:
        return list(range(count))
    frames = parse_frames(text)
    outside = [f for f in frames if not start <= f < start + count]
    if outside:
        raise ValueError(f"--frames {text}: frame {outside[0]} is outside the tracked frames "
                         f"{start}-{start + count - 1}")
    return [f - start for f in frames]


def run(args):
    """Draws the frames into OUT (with their records), the generated exemplar too."""
    tracks = rigid_tracks.read_tracks(args.cache)
    name, target = _one_object(tracks, args.object, f"guide cache {args.cache}")
    width, height = rigid_tracks.frame_size(args.cache)
    rigid_values, fit_values = (_values(args, t) for t in OPTION_TABLES)
    rigid_values = {"symmetry": rigid.SYMMETRY[args.shape], **rigid_values}  # --symmetry overrides the shape's
    rigid.RigidOptions(**rigid_values), rigid.QuadraticFitOptions(**fit_values)  # named errors before any work
    strokes = rigid_strokes.load_stroke_exemplar(args.strokes) if args.strokes else None
    folders = [generated_exemplar_folder(args.out, args.shape) if d == rigid.GENERATED else d
               for d in (args.exemplar or [rigid.GENERATED])]
    exemplars = [_read_exemplar(d, args.shape, fit_values) for d in folders]
    out = Path(args.out)
    settings = _settings_key(args, [d for _, d in exemplars], {**rigid_values, **fit_values})
    wanted = _frame_indices(args.frames, tracks["frame_start"], len(target["centre"]))
    frame_of = {i: tracks["frame_start"] + i for i in wanted}
    paths = {i: out / f"frame_{frame_of[i]:04d}.png" for i in wanted}
    records = {i: out / RECORDS_DIR / f"frame_{frame_of[i]:04d}.txt" for i in wanted}
    keys = {i: record.unit_key(settings, name, frame_of[i]) for i in wanted}
    _native.refuse_writing_on_inputs([str(p) for p in [*paths.values(), *records.values()]],
                                     input_files(args.cache, [d for _, d in exemplars], args.strokes))
    todo = [i for i in wanted if not record.is_current(records[i], RECORD_FORMAT, keys[i], [paths[i]])]
    out.mkdir(parents=True, exist_ok=True)

    def progress(f):
        print(f"tempera rigid: frame {tracks['frame_start'] + f}", file=sys.stderr, flush=True)
        return True

    # A chunk at a time: memory holds a few frames, and each is on disk (and
    # recorded) as soon as it is drawn. A chunk's frames equal an unchunked run's.
    for chunk in chunks(todo, CHUNK):
        frames = rigid.stylize([e for e, _ in exemplars], target, width, height, progress=progress, only=chunk,
                               **rigid_values)
        for i in chunk:
            rgba = frames[i][0] if strokes is None else rigid_strokes.restyle(frames[i][0], strokes, rigid_values)
            if args.paper:
                a = rgba[:, :, 3:4]
                rgba = np.concatenate([rgba[:, :, :3] * a + np.asarray(PAPER, np.float32) * (1 - a),
                                       np.ones_like(a)], axis=2)
            _native.write_image(str(paths[i]), np.ascontiguousarray(rgba, np.float32), [])
            record.write(records[i], RECORD_FORMAT, keys[i], [paths[i]])
    print(f"tempera rigid: {len(todo)} frames written, {len(paths) - len(todo)} kept, in {out}")
    return 0


def main(argv=None, prog="tempera rigid"):
    args = _parser(prog).parse_args(argv)
    return run_command(prog, lambda: run(args), "cancelled; rerun the same command to resume")
