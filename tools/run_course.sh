#!/usr/bin/env bash
# Runs the course: builds the reference solutions and runs every chapter executable (or the
# chapters given, e.g. `tools/run_course.sh 01 05`), writing VTK files, CSV tables and PNG figures
# under out/NN_name/; then the scenes gallery (or only it: `tools/run_course.sh scenes`): every
# scenes/*.toml with fem_scene into out/scenes/<scene>/ (.pvd, PNG frames, video, energies, and the
# web page <scene>.html beside the video) and the
# model comparison of all of them into out/scenes/compare/ (docs/scenes.md). Provides a virtual
# display when none is set, so the PNGs are drawn.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"

"$FEM_ROOT/tools/setup.sh"
step "build (release)"
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS"

chapters=()
gallery=0
for argument in "$@"; do
    if [ "$argument" = scenes ]; then gallery=1; else chapters+=("$argument"); fi
done
if [ $# -eq 0 ]; then
    for exe in build/release/bin/ch[0-9][0-9]_*; do chapters+=("$(basename "$exe" | cut -c3-4)"); done
    gallery=1
fi
for number in "${chapters[@]}"; do
    exe=$(ls build/release/bin/ch"${number}"_* 2>/dev/null | head -n 1) ||
        { echo "error: no chapter $number" >&2; exit 1; }
    [ -n "$exe" ] || { echo "error: no chapter $number" >&2; exit 1; }
    name=$(basename "$exe")
    step "$name  ->  out/${name#ch}"
    with_display "$exe" --out "out/${name#ch}"
done

if [ "$gallery" -eq 1 ]; then
    for scene in scenes/*.toml; do
        name=$(basename "$scene" .toml)
        step "fem_scene $scene  ->  out/scenes/$name"
        with_display build/release/bin/fem_scene "$scene" --html --out "out/scenes/$name"
    done
    # The comparison's reference is each scene at dt/16: the scenes of bodies against bodies and
    # self-contact (docs/scenes.md#bodies-against-bodies) would take 16x their full runs, so it leaves them out.
    mapfile -t compared < <(grep -L -E '^(bodies|self_contact) = true' scenes/*.toml)
    step "fem_scene ${compared[*]} --compare  ->  out/scenes/compare"
    with_display build/release/bin/fem_scene "${compared[@]}" --compare --out out/scenes/compare
fi
