"""The compiled half of Tempera in the self-contained wheel.

`tempera_native._native` is the pybind11 engine module (the package `tempera`
imports it as `tempera._native`); `bin/tempera` is the batch command line.
Both were repaired with auditwheel: the OpenImageIO, OpenEXR, Embree and TBB
they link are in the `tempera_native.libs` folder beside this package, under
renamed file names, so they never clash with another copy of those libraries
in the same process (Blender bundles its own).
"""
from pathlib import Path

CLI = Path(__file__).resolve().parent / "bin" / "tempera"
