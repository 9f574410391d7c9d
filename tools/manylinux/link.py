#!/usr/bin/env python3
"""Links the wheel's binaries so that they run on glibc 2.28 (manylinux_2_28): CMake's
linker launcher for the wheel build (tools/build_wheel.py sets it).

    CMAKE_CXX_LINKER_LAUNCHER="PYTHON;tools/manylinux/link.py"

CMake then runs `PYTHON link.py /usr/bin/g++ FLAGS -o OUT INPUTS`. The objects stay
GCC 12's, compiled against Debian's headers; only the link changes:

- `zig cc -target x86_64-linux-gnu.2.28` (PyPI's ziglang, in the tool venvs) links
  against glibc 2.28's symbol versions, with its own crt1 and libc_nonshared, so no
  symbol newer than GLIBC_2.28 can be bound. Debian 12's linker would bind
  2.29-2.35 versions of pow, hypot, pthread_* and __libc_start_main.
- libstdc++ and libgcc are linked in statically (Debian's libstdc++.a, zig's libunwind
  for _Unwind_*), so the binaries need no GLIBCXX_3.4.29 that Rocky 8's libstdc++
  lacks. OpenImageIO's libraries keep using the system's libstdc++.so.6.
- glibc_2_28_compat.c stands in for the few newer glibc symbols libstdc++.a calls.
- A version script exports only Python's module entry point (PyInit_*): the static C++
  runtime, Embree and the stand-ins stay inside each binary, as --exclude-libs,ALL
  does with GNU ld (which zig's driver does not accept). Inside Blender, that keeps
  Blender's own libraries from binding to ours and ours to theirs.
"""
import os
import subprocess
import sys
import tempfile
from pathlib import Path

TARGET = "x86_64-linux-gnu.2.28"
COMPAT = Path(__file__).resolve().parent / "glibc_2_28_compat.c"
EXPORTS = "{ global: PyInit_*; local: *; };\n"
# What the static runtime replaces, or zig's driver does not take.
DROPPED = {"-Wl,--exclude-libs,ALL", "-static-libstdc++", "-static-libgcc"}


def gcc_file(compiler, name):
    """The path of one of the compiler's own libraries (libstdc++.a, libgcc.a)."""
    path = subprocess.run([compiler, f"-print-file-name={name}"], capture_output=True, text=True,
                          check=True).stdout.strip()
    if not os.path.isabs(path):
        sys.exit(f"link.py: {compiler} has no {name} (install its static C++ runtime)")
    return path


def zig_link_command(argv, version_script):
    compiler, *args = argv
    for arg in args:
        if arg.startswith("-flto"):
            sys.exit("link.py: objects built for link-time optimization cannot be linked by zig's lld; "
                     "configure with CMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF")
    kept = [arg for arg in args if arg not in DROPPED]
    return [sys.executable, "-m", "ziglang", "cc", "-target", TARGET, *kept,
            f"-Wl,--version-script={version_script}",
            "-O2", "-fno-sanitize=all", str(COMPAT),  # the stand-ins, compiled against glibc 2.28
            gcc_file(compiler, "libstdc++.a"), gcc_file(compiler, "libgcc.a"),
            "-lgcc_s"]  # zig links its static libunwind for this


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: link.py COMPILER ARGS... (CMake's linker launcher)")
    with tempfile.TemporaryDirectory(prefix="tempera-link-") as tmp:
        version_script = Path(tmp) / "exports.map"
        version_script.write_text(EXPORTS)
        sys.exit(subprocess.run(zig_link_command(sys.argv[1:], version_script)).returncode)


if __name__ == "__main__":
    main()
