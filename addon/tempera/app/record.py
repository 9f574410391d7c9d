"""The job core's resume record (native/include/tempera/app/record.hpp) for
the jobs written in Python: a unit of work (a frame, a step) is current when
its record has the same format and key and every file it wrote is unchanged
(size and checksum), so a deleted, damaged or replaced output is made again."""
from __future__ import annotations

import hashlib
from pathlib import Path

from .. import _native


def unit_key(*parts):
    """The key of a unit of work: a hash of everything it is made from."""
    return hashlib.sha256("\n".join(map(str, parts)).encode()).hexdigest()


def is_current(record, record_format, key, files):
    return _native.record_current(str(record), record_format, key, [str(f) for f in files])


def write(record, record_format, key, files):
    """Written last and atomically, after every file of the unit."""
    Path(record).parent.mkdir(parents=True, exist_ok=True)
    _native.write_record(str(record), record_format, key, [str(f) for f in files])
