#!/usr/bin/env bash
# The course's full check (what CI runs): every stage must pass.
#   1. grading   each exercise, stubbed alone, fails at least one of its tagged tests, and they
#                pass with only it and what its docs say it builds on done (a table); built in
#                build/release (-DFEM_GRADING=ON: the exercise regions behind a run-time stub switch)
#   2. exercises every stub file of exercises/ compiles (the files students start from; the other
#                files of a chapter are the solutions' own, compiled by stage 1)
#   3. asan      under AddressSanitizer + UndefinedBehaviorSanitizer (and float-cast-overflow):
#                the unit tests (but those tagged [slow], which stage 4 runs), the scene runner's
#                tests and gallery quick runs, and chapters 01 and 14's executables (--quick run,
#                bad command lines, output-folder rule; the other executables run in stage 4:
#                FEM_PROGRAMS); built with clang 14, which also builds stage 5's fuzzers there
#   4. release   (the rest of build/release) every test passes on the reference solutions: unit
#                tests, the layout and exercise-sync checks, each executable's --quick run against
#                stored numbers, and each chapter's docs against its executable
#   5. fuzz      every file reader's libFuzzer target runs 15 s from its seed corpus without a
#                finding (tools/fuzz.sh; built by stage 3)
#   6. site      the course's website (tools/site.sh) built into build/site from the docs and one scene
#                page the stage makes itself (a --quick run of scenes/block_stack.toml by stage 4's
#                fem_scene into build/site_runs; tools/run_course.sh is not run, so the other scenes
#                are listed as missing), then used in headless Chromium with the network off: every
#                page loads with no request off the machine and no console error, no broken link or
#                image, search finds "Rayleigh" on chapter 10, the embedded scene page draws and moves
#                (tools/site/check_site.py; about a minute)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Two tests run at once on two cores: each runs its element loops on one thread (tests that compare
# thread counts set them themselves).
export OMP_NUM_THREADS=1

"$FEM_ROOT/tools/setup.sh"

step "exercises/ in sync with solutions/"
python3 tools/exercises.py check

# The grading stage builds in the release build folder (-DFEM_GRADING=ON: the exercise regions
# behind a run-time switch, off unless FEM_STUB_EXERCISE names them): stage 4 runs the same test
# binaries on the solutions and only builds the executables on top.
step "1/6 grading build: every exercise fails its tests as a stub and needs only what it builds on"
cmake --preset release -DFEM_GRADING=ON -DFEM_WERROR=ON >/dev/null
cmake --build --preset release --target fem_graded_tests -j "$JOBS"
with_display python3 tools/exercises.py grade --build build/release

step "2/6 every stub file of exercises/ compiles"
cmake --preset exercises -DFEM_WERROR=ON >/dev/null
cmake --build --preset exercises -j "$JOBS"

step "3/6 unit tests, the scene runner and two executables under AddressSanitizer + UndefinedBehaviorSanitizer"
cmake --preset asan -DFEM_WERROR=ON >/dev/null
cmake --build --preset asan -j "$JOBS"
with_display ctest --preset asan

step "4/6 release: all tests on the reference solutions"
cmake --build --preset release -j "$JOBS"
with_display ctest --preset release

step "5/6 the file readers fuzzed: each libFuzzer target 15 s from its seeds, no crash, sanitizer report, stray exception or runaway allocation"
tools/fuzz.sh --seconds 15

step "6/6 the website: built, then every page, link, search and the embedded scene page checked in headless Chromium"
tools/site.sh --quick-scene --site build/site --check

step "done: every stage passed"
