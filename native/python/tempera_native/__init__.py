"""The compiled half of Tempera in the self-contained wheel.

`tempera_native._native` is the pybind11 engine module (the package `tempera`
imports it as `tempera._native`); `bin/tempera` is the batch command line.
Both were repaired with auditwheel: the OpenImageIO they link is in the
`tempera_native.libs` folder beside this package, under renamed file names,
and Embree is linked into them with its symbols hidden, so they keep to their
own copies beside the ones Blender bundles (docs/extensions_and_farms.md).
"""
import stat
from pathlib import Path

CLI = Path(__file__).resolve().parent / "bin" / "tempera"


def cli():
    """CLI, executable. Blender's extension installer unpacks wheels with
    zipfile, which drops the executable bit, and unpacks them again whenever
    the extension is enabled, so bin/tempera, this package's own file, gets it
    back here, at each use (readable -> executable for the same users). A
    read-only install is left as it is; the callers then name the problem."""
    try:
        mode = CLI.stat().st_mode
        readable = mode & (stat.S_IRUSR | stat.S_IRGRP | stat.S_IROTH)
        if readable and not mode & stat.S_IXUSR:
            CLI.chmod(mode | (readable >> 2))
    except OSError:
        pass
    return CLI
