"""Builds the `tempera` wheel; the compiled module comes from CMake.

Metadata lives in pyproject.toml. This file adds what pyproject.toml cannot
express: the version taken from CMakeLists.txt, and a build_ext that runs
CMake (configure with tests off, build only the `_native` target) in its own
build folder, build/pip/cmake, writing the module straight into the wheel's
staging folder.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
BUILD_BASE = ROOT / "build" / "pip"


def cmake_project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"^project\(tempera VERSION ([0-9.]+)", text, re.MULTILINE)
    if not match:
        sys.exit("setup.py: no 'project(tempera VERSION x.y.z' line in CMakeLists.txt")
    return match.group(1)


class CMakeExtension(Extension):
    """An extension without sources: CMake builds it. Declaring it makes the
    wheel platform-specific (cp311-cp311-linux_x86_64)."""

    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        target = Path(self.get_ext_fullpath(ext.name)).resolve()
        cmake_dir = BUILD_BASE / "cmake"
        config = "Debug" if self.debug else "Release"
        jobs = str(self.parallel or os.cpu_count() or 1)
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(cmake_dir),
            f"-DCMAKE_BUILD_TYPE={config}",
            "-DTEMPERA_BUILD_TESTS=OFF",
            "-DTEMPERA_BUILD_PYTHON=ON",
            f"-DTEMPERA_PYTHON_PACKAGE_DIR={target.parent}",
            # The module must match the interpreter the wheel is built for.
            f"-DPython3_EXECUTABLE={sys.executable}",
        ]
        build = ["cmake", "--build", str(cmake_dir), "--target", "_native", "-j", jobs]
        for cmd in (configure, build):
            print(" ".join(cmd), flush=True)
            subprocess.run(cmd, check=True)
        if not target.is_file():
            found = sorted(p.name for p in target.parent.glob("_native*"))
            raise RuntimeError(f"CMake did not produce {target} (found: {found or 'nothing'})")


BUILD_BASE.mkdir(parents=True, exist_ok=True)
setup(
    version=cmake_project_version(),
    ext_modules=[CMakeExtension("tempera._native")],
    cmdclass={"build_ext": CMakeBuild},
    options={
        "build": {"build_base": str(BUILD_BASE.relative_to(ROOT))},
        "egg_info": {"egg_base": str(BUILD_BASE.relative_to(ROOT))},
    },
)
