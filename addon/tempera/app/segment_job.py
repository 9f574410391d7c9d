"""The job core's segment job (native/include/tempera/app/segment_job.hpp) as
Python sees it: a shot cut at its key frames into segments, each solved
whole (the coherent method's unit of work). MethodSegmentJob wraps the
native job that tempera.methods.registry.make_job gives for a method whose
unit is the segment; the coherent method's own class (tempera.methods.tcia.tcia.ShotJob)
shares SegmentJob with it."""
from __future__ import annotations

import os
from typing import Callable, Optional

StageFn = Optional[Callable[[float, str], Optional[bool]]]


class SegmentJob:
    """The segments, the ones this job runs (all, or a farm task's one), the
    warnings of the job's checks and the contact sheet, of a native segment
    job ``_job`` (a _native.SegmentJob)."""

    @property
    def segments(self) -> list:
        """(first, last, frames it writes) per segment of the shot."""
        return self._job.segments

    @property
    def selected(self) -> list:
        return self._job.selected

    @property
    def whole_shot(self) -> bool:
        """False for a farm task's one segment: the contact sheet waits for the finish."""
        return self._job.whole_shot

    @property
    def warnings(self) -> list:
        return self._job.warnings

    def write_contact_sheet(self, path, columns: int = 0) -> None:
        """The exemplar followed by the frames written so far, on one image under ~2000 px wide."""
        self._job.write_contact_sheet(os.fspath(path), int(columns))


class MethodSegmentJob(SegmentJob):
    """The job of a method whose unit is the segment, from
    tempera.methods.registry.make_job: run_segment runs one, with the GIL released."""

    def __init__(self, job):
        self._job = job

    def run_segment(self, index: int, progress: StageFn = None) -> dict:
        """Solves segments[index] (one of ``selected``) or skips it when
        current. Returns dict(frame (the segment's first), status "stylized" |
        "skipped", seconds, ...). ``progress(fraction, finished)`` gets the
        stage just finished ("level 2/4 forward sweep", else ""); returning
        False cancels (tempera.Cancelled), and nothing of the segment is written."""
        return self._job.run_unit(int(index), progress)
