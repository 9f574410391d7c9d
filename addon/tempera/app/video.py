"""The stylized frames as a video (native/src/app/process.cpp encode_video)."""
import os

from .. import _native


def encode_video(pattern, first_frame: int, out, fps: float = 24.0) -> bool:
    """H.264 MP4 of numbered frames (printf pattern, e.g. 'out/frame_%04d.png')
    with ffmpeg, written atomically; False (and no file) when ffmpeg is missing."""
    return _native.encode_video(os.fspath(pattern), int(first_frame), float(fps), os.fspath(out))
