"""The method registry (native/include/tempera/methods/registry.hpp) for the
Python side: the panel's Method list, the `tempera` console script's
dispatch and the farm planner read it, so a method is named once."""
from __future__ import annotations

from collections.abc import Mapping

from .. import _native
from ..app.frame_job import MethodJob
from ..app.segment_job import MethodSegmentJob

# dicts: name, title, summary, paper, unit, light_path_guides, docs,
# job (a job factory: make_job runs it), options_help, default_exemplar
METHODS = tuple(_native.methods())


def names() -> list:
    return [m["name"] for m in METHODS]


def default_name() -> str:
    """The method when none is named (`tempera stylize` without --method, the
    panel's Method, the farm): the registry's first."""
    return _native.default_method()


def find(name: str) -> dict:
    """The entry of `name`; ValueError naming every method (the CLI's message)."""
    return _native.find_method(str(name))


def panel_items() -> tuple:
    """The panel's Method EnumProperty items: (NAME, title, summary) in the registry's order."""
    return tuple((m["name"].upper(), m["title"], m["summary"]) for m in METHODS)


def _option_text(value) -> str:
    """An option's value as the command line writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(_option_text(v) for v in value)
    return repr(value) if isinstance(value, float) else str(value)


def make_job(name: str, exemplar, guides, frames, out, *, format: str = "png", resume: bool = True,
             options: dict = None):
    """The job of a method with a job factory (its entry's ``job``: built in or
    a registered plug-in), as ``tempera stylize --method NAME`` runs it: a
    tempera.app.frame_job.MethodJob (run ``run_frame(i)`` for each frame
    index), or for a method whose unit is the segment (the coherent method) a
    tempera.app.segment_job.MethodSegmentJob (``run_segment(i)`` for i in
    ``selected``). Its frames go to OUT/frames, as for every method.

    ``options`` are the method's, keyed by their command-line flags without
    the dashes (``{"lambda": 0.3, "motion_blur": 4, "rotations": True}``;
    ``_`` stands for ``-``), as ``tempera stylize --method NAME --help`` lists
    them. A flag given more than once (the coherent method's ``key``): a
    list of (flag, value) pairs instead of the dict. ValueError for an
    unknown method, option or value. StyLit and the coherent method
    take the exemplar render's guide cache as ``{"exemplar-guides": DIR}``."""
    config = _native.JobConfig(exemplar=exemplar, guides=guides, frames=[int(f) for f in frames], out=out, format=format,
                               resume=resume)
    pairs = options.items() if isinstance(options, Mapping) else (options or ())
    flags = [(str(flag).replace("_", "-"), _option_text(value)) for flag, value in pairs]
    if find(name)["unit"] == "segment":
        return MethodSegmentJob(_native.method_segment_job(str(name), config, flags))
    return MethodJob(_native.method_job(str(name), config, flags))
