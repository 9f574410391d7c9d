"""Exemplars of the fluid and natural-media methods as the jobs take them:
a still image, or a folder holding only the frames of a video exemplar.

The artist picks a still, an image sequence (its folder, or the first file
of a numbered sequence such as ink_0001.png) or a movie file. A movie is
decoded by ffmpeg into PNG frames once, into a cache folder; a later run
reuses them while the movie's size and modification time are unchanged. A
numbered sequence picked by its first file, in a folder that holds more
than that sequence, is linked into a cache folder of its own, so that the
job reads exactly its frames.
"""
import json
import os
import re
import shutil
import subprocess
import tempfile

IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".bmp", ".tga")
MOVIE_EXTENSIONS = (".mp4", ".mov", ".avi", ".mkv", ".webm", ".m4v", ".mpg", ".mpeg", ".ogv", ".gif")
STAMP = "source.json"  # in a decoded or linked folder: what it was made from
_NUMBERED = re.compile(r"^(.*?)(\d+)(\.[^.]+)$")  # prefix, frame number, extension


class MediaError(ValueError):
    """An exemplar that cannot be used, with what to change."""


def is_image(path):
    return os.path.splitext(path)[1].lower() in IMAGE_EXTENSIONS


def is_movie(path):
    return os.path.splitext(path)[1].lower() in MOVIE_EXTENSIONS


def image_files(folder):
    """The image files of `folder`, sorted by name (hidden files left out)."""
    return sorted(os.path.join(folder, n) for n in os.listdir(folder) if not n.startswith(".") and is_image(n))


def numbered_sequence(first):
    """The files of the numbered sequence `first` starts (same prefix, number
    width and extension; numbers from first's up, gaps allowed), by number."""
    folder, name = os.path.split(os.path.abspath(first))
    match = _NUMBERED.match(name)
    if match is None:
        return [os.path.join(folder, name)]
    prefix, digits, ext = match.groups()
    pattern = re.compile(re.escape(prefix) + r"(\d{%d})" % len(digits) + re.escape(ext) + "$")
    numbered = []
    for other in os.listdir(folder):
        m = pattern.match(other)
        if m and int(m.group(1)) >= int(digits):
            numbered.append((int(m.group(1)), os.path.join(folder, other)))
    return [path for _, path in sorted(numbered)]


def _stamp_of(source):
    stat = os.stat(source)
    return {"source": os.path.abspath(source), "size": stat.st_size, "mtime_ns": stat.st_mtime_ns}


def _is_current(folder, stamp):
    try:
        with open(os.path.join(folder, STAMP), encoding="utf-8") as f:
            return json.load(f) == stamp
    except (OSError, ValueError):
        return False


def _publish(build, folder, stamp):
    """Moves the finished folder `build` to `folder` (replacing an old one),
    with its stamp written last inside: a folder without a current stamp is
    never taken for a finished one."""
    with open(os.path.join(build, STAMP), "w", encoding="utf-8") as f:
        json.dump(stamp, f)
    if os.path.isdir(folder):
        shutil.rmtree(folder)
    os.replace(build, folder)


def _cache_folder(cache_dir, source):
    os.makedirs(cache_dir, exist_ok=True)
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", os.path.splitext(os.path.basename(source))[0]) or "exemplar"
    return os.path.join(cache_dir, stem)


def decode_movie(movie, cache_dir, ffmpeg=None):
    """The folder of the movie's frames as frame_0001.png ... in `cache_dir`;
    decoded by ffmpeg only when the folder is missing or older than the movie.
    MediaError when ffmpeg is not on PATH or cannot read the movie."""
    folder = _cache_folder(cache_dir, movie)
    stamp = _stamp_of(movie)
    if _is_current(folder, stamp):
        return folder
    ffmpeg = ffmpeg or shutil.which("ffmpeg")
    if ffmpeg is None:
        raise MediaError(f"Decoding the movie '{movie}' needs ffmpeg on PATH (install ffmpeg), "
                         "or pick its frames as an image sequence.")
    build = tempfile.mkdtemp(prefix=".decoding-", dir=cache_dir)
    try:
        # RGBA keeps a movie's alpha channel where it has one (ProRes 4444, PNG, WebM).
        # Absolute paths: ffmpeg reads a relative '-y' as an option and 'shot:01' as a URL;
        # '%' in the folder is doubled, or ffmpeg takes it for a frame number.
        pattern = os.path.join(os.path.abspath(build).replace("%", "%%"), "frame_%04d.png")
        done = subprocess.run([ffmpeg, "-v", "error", "-nostdin", "-i", os.path.abspath(movie), "-pix_fmt", "rgba",
                               pattern], capture_output=True, text=True)
        if done.returncode != 0 or not image_files(build):
            raise MediaError(f"ffmpeg could not decode '{movie}': {done.stderr.strip() or 'no frames'}")
        _publish(build, folder, stamp)
    finally:
        shutil.rmtree(build, ignore_errors=True)
    return folder


def _linked_sequence(files, cache_dir):
    """A folder in `cache_dir` holding (links to) exactly `files`, in order."""
    folder = _cache_folder(cache_dir, files[0])
    stamp = {"files": [_stamp_of(f) for f in files]}
    if _is_current(folder, stamp):
        return folder
    build = tempfile.mkdtemp(prefix=".linking-", dir=cache_dir)
    try:
        for i, path in enumerate(files, start=1):
            target = os.path.join(build, f"frame_{i:04d}{os.path.splitext(path)[1].lower()}")
            try:
                os.symlink(path, target)
            except OSError:  # file systems without symbolic links
                shutil.copyfile(path, target)
        _publish(build, folder, stamp)
    finally:
        shutil.rmtree(build, ignore_errors=True)
    return folder


def sequence_folder(path, cache_dir):
    """The folder of an image sequence's frames: `path` itself if it is a
    folder of images, else the numbered sequence `path` is the first file of
    (its own folder when that holds nothing else, else a linked copy)."""
    if os.path.isdir(path):
        if not image_files(path):
            raise MediaError(f"The folder '{path}' holds no image files ({', '.join(IMAGE_EXTENSIONS)}).")
        return path
    files = numbered_sequence(path)
    if len(files) < 2:
        raise MediaError(f"'{path}' is not the first file of a numbered image sequence (name_0001.png, ...).")
    if sorted(files) == image_files(os.path.dirname(files[0])):
        return os.path.dirname(files[0])
    return _linked_sequence(files, cache_dir)


def exemplar_source(kind, path, cache_dir):
    """What a job takes for the exemplar picked as `kind` ("STILL", "SEQUENCE"
    or "MOVIE") at `path`: the still's path, or a folder of frames."""
    if not path:
        raise MediaError("Choose the exemplar file or folder.")
    if not os.path.exists(path):
        raise MediaError(f"The exemplar '{path}' does not exist.")
    if kind == "STILL":
        if not os.path.isfile(path) or not is_image(path):
            raise MediaError(f"The still exemplar '{path}' is not an image file ({', '.join(IMAGE_EXTENSIONS)}).")
        return path
    if kind == "SEQUENCE":
        return sequence_folder(path, cache_dir)
    if kind == "MOVIE":
        if not os.path.isfile(path) or not is_movie(path):
            raise MediaError(f"'{path}' is not a movie file ({', '.join(MOVIE_EXTENSIONS)}).")
        return decode_movie(path, cache_dir)
    raise MediaError(f"unknown exemplar kind {kind!r} (STILL, SEQUENCE or MOVIE)")
