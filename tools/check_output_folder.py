#!/usr/bin/env python3
"""Checks the rule of a run's output folder with a chapter executable (a ctest test,
output_folder_rule): a run that fails leaves the previous results as they were, with no half-written
or temporary file; a run that succeeds replaces them whole (files of the previous run that it did
not write again are gone) and leaves files it did not write (the user's) alone.

The failures are real: a file size limit (RLIMIT_FSIZE, as `ulimit -f` sets it; the executable
must turn the write past it into "error: ...", like a full disk) and an --out whose parent is a
file (which stops root too). Each run starts in an empty temporary working folder.

  check_output_folder.py --exe build/release/bin/ch01_finite_differences
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

try:
    import resource
except ImportError:  # not a POSIX system: no file size limit to test with
    resource = None

SKIP = 77  # ctest's SKIP_RETURN_CODE for this test
LIMIT = 1024  # bytes: the quick run of chapter 01 writes larger files (its CSV tables)


def snapshot(folder):
    """{relative path: bytes} of every file under folder."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def run(exe, work, out, size_limit=None):
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (size_limit, size_limit))
    return subprocess.run([str(exe), "--quick", "--no-figures", "--out", str(out)], cwd=work, capture_output=True,
                          text=True, timeout=600, preexec_fn=limit if size_limit else None)


def error_lines(result):
    return [line for line in result.stderr.splitlines() if line.startswith("error:")]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--exe", required=True, type=Path)
    exe = parser.parse_args().exe.resolve()
    if resource is None:
        print("SKIPPED: this system has no file size limit (Python's resource module is missing)")
        return SKIP
    problems = []

    def expect(condition, problem):
        if not condition:
            problems.append(problem)

    with tempfile.TemporaryDirectory(prefix="output_folder_") as folder:
        work = Path(folder)
        out = work / "out"

        first = run(exe, work, "out")
        if first.returncode != 0:
            print(f"FAIL the first run failed:\n{first.stderr}")
            return 1
        # What the user keeps there, and a file the previous run wrote that the next will not.
        (out / "notes.txt").write_text("the user's own notes\n")
        (out / "stale_result.csv").write_text("from an earlier run\n")
        with open(out / ".fem-run-files", "a") as manifest:
            manifest.write("stale_result.csv\n")
        before = snapshot(out)

        full = run(exe, work, "out", size_limit=LIMIT)
        expect(full.returncode == 1, f"under a {LIMIT}-byte file size limit: exit code {full.returncode}, expected 1 "
                                     "(a signal means the executable did not ignore SIGXFSZ)")
        expect(any("File too large" in line for line in error_lines(full)),
               f"under the file size limit: no 'error: ... File too large' line; stderr: {full.stderr.strip()}")
        expect(not any(".staging-" in line for line in error_lines(full)),
               "the error names the staging folder instead of --out: " + " | ".join(error_lines(full)))
        expect(snapshot(out) == before, "the failed run changed the previous results (or left a file behind)")
        expect(sorted(p.name for p in work.iterdir()) == ["out"], "the failed run wrote outside --out")

        (work / "a_file").write_text("not a folder\n")
        blocked = run(exe, work, work / "a_file" / "out")
        expect(blocked.returncode == 1 and any("--out" in line for line in error_lines(blocked)),
               f"--out under a file: exit code {blocked.returncode}, stderr: {blocked.stderr.strip()}")
        (work / "a_file").unlink()

        again = run(exe, work, "out")
        expect(again.returncode == 0, f"the run after the failures failed: {again.stderr.strip()}")
        after = snapshot(out)
        expect("stale_result.csv" not in after, "a file of the previous run that this run did not write is still there")
        expect(after.get("notes.txt") == before["notes.txt"], "the user's own file was touched")
        expect(set(before) - {"stale_result.csv"} <= set(after), "the successful rerun is missing results")
        expect(not any(".staging-" in name or ".tmp-" in name for name in after), "a temporary was left behind")

    for problem in problems:
        print(f"FAIL {problem}")
    if not problems:
        print("ok: a failed run left the previous results intact; a successful one replaced them whole")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
