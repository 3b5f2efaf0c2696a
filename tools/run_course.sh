#!/usr/bin/env bash
# Runs the course: builds the reference solutions and runs every chapter executable (or the
# chapters given, e.g. `tools/run_course.sh 01 05`), writing VTK files, CSV tables and PNG figures
# under out/NN_name/. Provides a virtual display when none is set, so the PNGs are drawn.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"

"$FEM_ROOT/tools/setup.sh"
step "build (release)"
cmake --preset release >/dev/null
cmake --build --preset release -j "$JOBS"

chapters=("$@")
if [ ${#chapters[@]} -eq 0 ]; then
    for exe in build/release/bin/ch[0-9][0-9]_*; do chapters+=("$(basename "$exe" | cut -c3-4)"); done
fi
for number in "${chapters[@]}"; do
    exe=$(ls build/release/bin/ch"${number}"_* 2>/dev/null | head -n 1) ||
        { echo "error: no chapter $number" >&2; exit 1; }
    [ -n "$exe" ] || { echo "error: no chapter $number" >&2; exit 1; }
    name=$(basename "$exe")
    step "$name  ->  out/${name#ch}"
    with_display "$exe" --out "out/${name#ch}"
done
