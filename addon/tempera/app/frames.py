"""Frame ranges as artists and render farms write them: "1-24", "7", "1-10,15,20-22"."""

# Blender's last frame (MAXFRAME): it renders any later frame as this one, so
# no range may go beyond it. This also bounds every range.
MAX_FRAME = 1048574


def check_frame(frame, what="frame"):
    """`frame` as an int, or ValueError if Blender cannot render it."""
    if isinstance(frame, bool) or not isinstance(frame, int):
        try:
            as_int = int(frame)
        except (TypeError, ValueError):
            raise ValueError(f"{what} must be a whole number, got {frame!r}") from None
        if as_int != frame:
            raise ValueError(f"{what} must be a whole number, got {frame!r}")
        frame = as_int
    if not 0 <= frame <= MAX_FRAME:
        raise ValueError(f"{what} {frame} is outside 0-{MAX_FRAME} (the frames Blender can render)")
    return frame


def parse_frames(text):
    """Sorted unique frame numbers of a range text; ValueError naming the bad part."""
    frames = set()
    for part in str(text).replace(" ", "").split(","):
        if not part:
            raise ValueError(f"empty part in frame range {text!r} (write e.g. 1-24 or 1-10,15)")
        first, dash, last = part.partition("-")
        try:
            start = int(first)
            end = int(last) if dash else start
        except ValueError:
            raise ValueError(f"cannot read {part!r} in frame range {text!r} (write e.g. 1-24 or 1-10,15)") from None
        for number in (start, end):
            check_frame(number, f"frame range {text!r}: frame")
        if end < start:
            raise ValueError(f"frame range {part!r} ends before it starts")
        frames.update(range(start, end + 1))
    return sorted(frames)
