"""The job core's per-frame job (native/include/tempera/app/frame_job.hpp) as
Python sees it, whatever the method: each method's job class (tempera.methods.NAME),
the noise pass's and the MethodJob of any method with a job factory
(tempera.methods.registry.make_job) wrap a native job ``_job`` (a
_native.FrameJob) and show it the same way."""
from __future__ import annotations

import os
from typing import Callable, Optional

ProgressFn = Optional[Callable[[float], Optional[bool]]]


class FrameJob:
    """The frames, the warnings of the job's checks, a frame's output path, and
    run_frame: one frame, with the GIL released."""

    @property
    def frames(self) -> list:
        return self._job.frames

    @property
    def warnings(self) -> list:
        return self._job.warnings

    @property
    def summary(self) -> str:
        """How the run went, in a phrase for a report ("flow from velocity_forward"), or ""."""
        return self._job.summary

    def output_path(self, frame: int) -> str:
        return self._job.output_path(int(frame))

    def run_frame(self, index: int, progress: ProgressFn = None) -> dict:
        """Makes frames[index] (a chained frame: the frames before it first,
        where they are not current), or skips it when current. Returns
        dict(frame, path, status "stylized" (the noise pass: "made") |
        "skipped", seconds, flicker (NaN where not measured),
        source_coverage). ``progress(fraction)`` returning False cancels
        (tempera.Cancelled), and nothing of the frame is written."""
        return self._job.run_frame(int(index), progress)


class SheetFrameJob(FrameJob):
    """A per-frame job with a contact sheet of its exemplar and frames."""

    def write_contact_sheet(self, path, columns: int = 0) -> None:
        """The exemplar followed by the frames written so far, on one image under ~2000 px wide."""
        self._job.write_contact_sheet(os.fspath(path), int(columns))


class MethodJob(SheetFrameJob):
    """The job of a method with a job factory, from tempera.methods.registry.make_job."""

    def __init__(self, job):
        self._job = job

    @property
    def has_contact_sheet(self) -> bool:
        """False for a method without one: write_contact_sheet then raises ValueError."""
        return self._job.has_contact_sheet
