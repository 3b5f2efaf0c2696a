#!/usr/bin/env bash
# Fuzzes the course's file readers and the scene reader: builds the fuzzers of the asan preset (clang,
# libFuzzer + ASan + UBSan; the same build as the sanitizer stage's tests, fuzz/CMakeLists.txt) and
# runs each reader's target from its seed corpus (fuzz/corpus/<target>/) for a bounded time, as many
# targets at once as there are cores. Exits 1 if any target found something, naming the input that
# caused it. New inputs that reach new code are kept in build/fuzz/corpus/<target>/ for the next run
# (build/fuzz/ holds the runs' corpus, findings and logs; the fuzzers are build/asan/bin/fuzz_*).
#
#   tools/fuzz.sh                         every target, 15 s each (the CI stage of tools/test.sh)
#   tools/fuzz.sh --seconds 3600 ply      one target for an hour
#   tools/fuzz.sh --runs 1000000 obj stl  until a million inputs each
#
# Targets: obj ply stl tetgen pvd vtu (whole files: the checks before VTK, VTK's XML reader, the
# checks after it), vtu_grid (the checks after VTK, on any grid VTK could return), scene (a scene
# file and --set overrides, split at a line ===; read_scene without TetGen and with 256 MB for the run)
# and ccd_queries (chapter 14's reader of the CCD benchmark's query files, then both CCD methods).
# Limits: an input may take 10 s and allocate 512 MB at once (2 GB in all); a reader must refuse a
# huge count with an fem::Error before it reserves memory for it. Leaks are not reported: VTK's XML
# reader leaks on some errors.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"
export ASAN_OPTIONS="detect_leaks=0"

seconds=15
runs=-1
formats=()
while [ $# -gt 0 ]; do
    case "$1" in
        --seconds) seconds="$2"; shift 2 ;;
        --runs) runs="$2"; seconds=0; shift 2 ;;
        -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "error: unknown option '$1'; allowed: --seconds N, --runs N, formats" >&2; exit 1 ;;
        *) formats+=("$1"); shift ;;
    esac
done
[ ${#formats[@]} -eq 0 ] && formats=(obj ply stl tetgen pvd vtu vtu_grid scene ccd_queries)
for format in "${formats[@]}"; do
    [ -d "fuzz/corpus/$format" ] || { echo "error: no fuzz target '$format'; allowed: $(ls fuzz/corpus | xargs)" >&2; exit 1; }
done

cmake --preset asan -DFEM_WERROR=ON >/dev/null
cmake --build --preset asan --target fem_fuzzers -j "$JOBS"

# One target per core at a time (JOBS, tools/common.sh): each is one libFuzzer process on one thread,
# so each still runs its full time on a core of its own.
fuzz_target() {
    local format="$1" work="build/fuzz/corpus/$1" findings="build/fuzz/findings/$1" log="build/fuzz/fuzz_$1.log"
    local start=$SECONDS status=0
    mkdir -p "$work" "$findings"
    "build/asan/bin/fuzz_$format" -max_total_time="$seconds" -runs="$runs" -timeout=10 \
        -rss_limit_mb=2048 -malloc_limit_mb=512 -detect_leaks=0 -max_len=8192 -print_final_stats=1 \
        -artifact_prefix="$findings/" "$work" "fuzz/corpus/$format" >"$log" 2>&1 || status=$?
    echo "$status $((SECONDS - start))" >"build/fuzz/result_$format"
}

rm -f build/fuzz/result_*
for format in "${formats[@]}"; do
    while [ "$(jobs -pr | wc -l)" -ge "$JOBS" ]; do
        wait -n || true
    done
    fuzz_target "$format" &
done
wait

printf '\n%-8s %12s %10s %8s\n' target executions "exec/s" seconds
failed=()
for format in "${formats[@]}"; do
    log="build/fuzz/fuzz_$format.log"
    read -r status took <"build/fuzz/result_$format"
    if [ "$status" -ne 0 ]; then
        failed+=("$format")
        continue
    fi
    executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
    printf '%-8s %12s %10s %8s\n' "$format" "$executions" "$rate" "$took"
done
for format in "${failed[@]}"; do
    tail -n 40 "build/fuzz/fuzz_$format.log" >&2
    echo "error: fuzz_$format found a bug; the input is in build/fuzz/findings/$format/ (full log: build/fuzz/fuzz_$format.log)" >&2
done
[ ${#failed[@]} -eq 0 ]
