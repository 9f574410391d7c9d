#!/usr/bin/env bash
# Installs Tempera's build and test dependencies from Debian's archive, then
# (tools/setup_venvs.sh) the Python environments from PyPI: blender.org's
# Blender 4.5 and 5.0 as the bpy module, and the wheel/farm tools.
# Idempotent and fast when everything is present: apt-get runs only for
# packages that are missing, pip only for environments that are.
set -euo pipefail

# package                 why it is needed
PACKAGES=(
  blender               # the host application; runs the add-on and blender_tests
  cmake g++ make        # native build
  pybind11-dev          # the tempera._native Python module
  python3-dev           # headers of /usr/bin/python3, the Python Debian's Blender runs
  libopenimageio-dev    # image IO (PNG, JPEG, TIFF, EXR) in the core library
  openimageio-tools     # oiiotool/iinfo for inspecting guide caches by hand
  python3-openimageio   # reading EXR guide caches from Python tests
  libopenexr-dev        # EXR headers used by OpenImageIO's EXR support
  libembree-dev         # the light-path-expression tracer (same libembree3 Blender links)
  libtbb-dev            # Embree's and OpenImageIO's threading runtime headers
  libfmt-dev            # fmt headers, which the wheel's OpenImageIO 3 headers include (tools/wheel_deps.py)
  python3-numpy         # arrays in and out of the native module
  python3-pytest        # Python and in-Blender tests
  python3-setuptools python3-pip  # offline pyproject build (--no-build-isolation)
  libgtest-dev          # C++ unit tests
  ffmpeg                # mp4 previews of stylized sequences
  python3-venv          # virtual environments for PyPI's bpy and the wheel/farm tools
  libx11-6 libxi6 libxxf86vm1 libxfixes3 libxrender1 libxkbcommon0 libsm6 \
  libgl1 libegl1        # X11/GL libraries blender.org's bpy (4.2, 4.5, 5.0) loads, even headless
  nodejs                # tests of the Flamenco job type (farm/flamenco/tempera.js)
  xvfb xdotool imagemagick  # docs/make_panel_screenshots.py: the real panel in a window on a virtual display
)

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

missing=()
for pkg in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PACKAGES[@]} packages present"
else
  echo "deps: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
"$HERE/setup_venvs.sh"
