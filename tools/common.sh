# Shared by the scripts in tools/: where the project is, and how to give VTK a display.
# Sourced, not run.

FEM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
JOBS="$(nproc 2>/dev/null || echo 2)"

# Runs a command with an X display: the current one if set, else a virtual one (Xvfb). Debian's
# VTK renders only through X; without a display the executables skip their PNGs.
with_display() {
    if [ -n "${DISPLAY:-}" ]; then
        "$@"
    else
        xvfb-run -a -s "-screen 0 1280x1024x24" "$@"
    fi
}

# Prints a stage's title with the minutes and seconds since the script started (bash's SECONDS), so
# that a run's log shows what each stage cost.
step() { printf '\n=== [%d:%02d] %s\n' $((SECONDS / 60)) $((SECONDS % 60)) "$*"; }
