#!/usr/bin/env bash
# Builds the course's website into site/ (docs/engineering.md#the-website): every chapter's docs page
# in order with its figures, the README as the home page, the exercise map, the engineering page,
# CONTRIBUTING, search, and the gallery: each scene's web page playing, its video and its scene file,
# from what tools/run_course.sh wrote into out/ (scenes whose page is missing are listed, the rest of
# the site is built). Open site/index.html, or copy site/ to any web server: it loads nothing from the
# network. Links to source files go to copies inside the site, or to a forge with --source-url URL (or
# FEM_SITE_SOURCE_URL), e.g. https://github.com/OWNER/fem-course/blob/main.
#
#   tools/site.sh                          # out/ -> site/
#   tools/site.sh --runs DIR --site DIR    # another run folder, another site folder
#   tools/site.sh --check                  # then check it in headless Chromium (tools/site/check_site.py)
#   tools/site.sh --quick-scene            # CI: first a --quick run of scenes/block_stack.toml into build/site_runs
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cd "$FEM_ROOT"

"$FEM_ROOT/tools/setup.sh"
check=0
quick=0
site=site
arguments=()
while [ $# -gt 0 ]; do
    case "$1" in
        --check) check=1 ;;
        --quick-scene) quick=1 ;;
        --site) site="$2"; arguments+=("$1" "$2"); shift ;;
        -h|--help) sed -n '2,13p' "${BASH_SOURCE[0]}" | cut -c3-; python3 tools/site/build_site.py --help; exit 0 ;;
        *) arguments+=("$1") ;;
    esac
    shift
done

if [ "$quick" -eq 1 ]; then
    # One scene of several bodies (its energy legend has nine series), quick: under 2 s.
    [ -x build/release/bin/fem_scene ] || { echo "error: --quick-scene needs build/release/bin/fem_scene (cmake --build --preset release --target fem_scene)" >&2; exit 1; }
    rm -rf build/site_runs
    build/release/bin/fem_scene scenes/block_stack.toml --quick --html --no-figures --no-progress \
        --out build/site_runs/scenes/block_stack >/dev/null
    arguments=(--runs build/site_runs "${arguments[@]}")
fi
python3 tools/site/build_site.py "${arguments[@]}"
if [ "$check" -eq 1 ]; then
    python3 tools/site/check_site.py --site "$site"
fi
