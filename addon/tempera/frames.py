"""Frame ranges as artists and render farms write them: "1-24", "7", "1-10,15,20-22"."""


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
        if end < start:
            raise ValueError(f"frame range {part!r} ends before it starts")
        frames.update(range(start, end + 1))
    return sorted(frames)
