#!/usr/bin/env bash
# The memory each executable needs: runs every chapter executable of a build (full runs, not
# --quick), then fem_scene on every scene and its --compare, ONE AT A TIME (two at once would add
# up), and prints a Markdown table of the peak resident memory each run reports on its last line
# ("peak memory: N MB", common/memory.hpp) with its wall time. docs/engineering.md, "Memory", holds the result.
#
#   tools/memory_table.sh [BUILD_DIR] [NN ...]     default build/release, every chapter and the scenes
#   tools/memory_table.sh build/release 10 12      chapters 10 and 12 only
#
# Outputs go to a temporary folder, removed at the end.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"

build=${1:-build/release}
shift || true
[ -d "$build/bin" ] || { echo "error: no $build/bin: build first (cmake --build --preset release)" >&2; exit 1; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

runs=()
if [ $# -eq 0 ]; then
    for exe in "$build"/bin/ch[0-9][0-9]_*; do runs+=("$(basename "$exe")"); done
    for scene in scenes/*.toml; do runs+=("fem_scene $scene"); done
    runs+=("fem_scene --compare")
else
    for number in "$@"; do runs+=("$(basename "$(ls "$build"/bin/ch"$number"_* | head -n 1)")"); done
fi

echo "| run | peak resident memory | wall time |"
echo "|---|---|---|"
for run in "${runs[@]}"; do
    read -r exe args <<< "$run"
    [ "$args" = "--compare" ] && args="$(echo scenes/*.toml) --compare"
    start=$SECONDS
    # shellcheck disable=SC2086  # args holds whole words (scene paths without spaces)
    if ! log=$(with_display "$build/bin/$exe" $args --out "$out/run" 2>&1); then
        echo "| \`$run\` | failed: $(echo "$log" | tail -n 1) | |"
        continue
    fi
    peak=$(echo "$log" | sed -n 's/^peak memory: \([0-9]*\) MB.*/\1/p' | tail -n 1)
    echo "| \`$run\` | ${peak:-?} MB | $((SECONDS - start)) s |"
    rm -rf "$out/run"
done
