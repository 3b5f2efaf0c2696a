#!/usr/bin/env bash
# Installs the Debian 12 packages the course uses, when any is missing (needs root or sudo).
# Both README commands call it; running it again does nothing once everything is there.
set -euo pipefail

packages=(
  g++ cmake ninja-build python3           # toolchain
  libeigen3-dev catch2 libcli11-dev       # linear algebra, tests, command lines
  libvtk9-dev libx11-dev xvfb xauth       # VTK files and figures; a virtual display
  libxtst-dev                             # the live view's mouse test: real pointer input (XTEST)
  zlib1g-dev                              # .vtu data blocks checked before VTK reads them
  fonts-dejavu-core                       # the figures' font (common/figures.cpp)
  libsuitesparse-dev libopenblas0-pthread # CHOLMOD, the speed reference of chapters 08-09
  tetgen                                  # tetrahedral meshes from surfaces
  libspectra-dev                          # sparse eigenvalues (chapter 10: modes)
  libtomlplusplus-dev                     # scene files (scenes/*.toml, docs/scenes.md)
  ffmpeg                                  # the scenes' videos from their PNG frames (optional)
  libjs-three                             # three.js r111, inlined into the scenes' web pages (--html)
  chromium                                # the web page's and the website's browser tests (headless)
  mkdocs mkdocs-material python3-pymdownx # the course's website (tools/site.sh)
  time                                    # GNU time: the course's peak memory (docs/engineering.md)
  clang-14 libclang-rt-14-dev             # the sanitizer build and the readers' fuzz targets (libFuzzer)
  libomp-14-dev                           # OpenMP for clang (the sanitizer build)
)

missing=()
for package in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$package")
    fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "installing: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "error: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
    sudo=sudo
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "installed: ${missing[*]}"
