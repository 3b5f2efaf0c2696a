#!/usr/bin/env python3
"""Runs a chapter executable with each bad command line of a table and checks that it refuses it
before doing anything (a ctest test, chNN_bad_options, registered by cmake/FemChapter.cmake for
every chapter with a tests/NN_name/bad_options.txt).

The table: one bad command line a line, the option its error must name first, then the arguments
(shell words; '#' starts a comment; {here} stands for the table's folder, for bad input files
kept beside it):

    --points    --points 2                  # out of range
    --points    --quick --points x          # not a number
    --colour    --colour red                # no such option
    --mesh      --mesh {here}/corrupt.vtu   # a file that cannot be read

Each line runs in an empty temporary folder as `exe --out <tmp>/out <arguments>` and must:
exit with code 1; print on stderr a line starting with 'error:' that names the option, and nothing
else but "run with --help to see the options" (no log of a library, no second message); print
nothing on stdout (no study ran); and write nothing (no <tmp>/out, or an empty one, and nothing
else in <tmp>, the working folder).

  check_bad_options.py --exe build/release/bin/ch01_finite_differences \\
                       --table tests/01_finite_differences/bad_options.txt
"""

import argparse
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

TIMEOUT = 60  # seconds: a run that is still going has accepted the option
HELP_HINT = "run with --help to see the options"  # what may follow the error line


def read_table(path):
    """[(line number, option, arguments)] of the table, or raises ValueError."""
    rows = []
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        words = [w.replace("{here}", str(path.parent.resolve())) for w in shlex.split(line, comments=True)]
        if not words:
            continue
        option, arguments = words[0], words[1:]
        if not option.startswith("--") or not any(a == option or a.startswith(option + "=") for a in arguments):
            raise ValueError(f"{path}:{number}: a line is the option the error names, then a command line "
                             f"that holds it; got {line!r}")
        rows.append((number, option, arguments))
    if not rows:
        raise ValueError(f"{path}: no bad command line")
    return rows


def check_line(exe, option, arguments):
    """The problems of one bad command line (an empty list when it was refused as it should be)."""
    with tempfile.TemporaryDirectory(prefix="bad_options_") as folder:
        work = Path(folder)
        command = [str(exe.resolve()), "--out", str(work / "out"), *arguments]
        try:
            result = subprocess.run(command, cwd=work, capture_output=True, text=True, timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            return [f"still running after {TIMEOUT} s: the option was accepted"]
        problems = []
        if result.returncode != 1:
            problems.append(f"exit code {result.returncode}, expected 1")
        errors = [line for line in result.stderr.splitlines() if line.startswith("error:")]
        if not any(option in line for line in errors):
            problems.append(f"no 'error: ...' line naming {option} on stderr")
        others = [line for line in result.stderr.splitlines() if line and not line.startswith("error:")
                  and line != HELP_HINT]
        if others:
            problems.append(f"printed more than the error on stderr: {others[0]!r}")
        if result.stdout.strip():
            problems.append("printed on stdout (something ran before the options were checked): "
                            + result.stdout.strip().splitlines()[0])
        written = sorted(str(p.relative_to(work)) for p in work.rglob("*") if p != work / "out")
        if written:
            problems.append(f"wrote {', '.join(written[:5])}{' ...' if len(written) > 5 else ''}")
        if problems:
            problems.append("stderr: " + " | ".join(result.stderr.strip().splitlines()[:3]))
        return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--exe", required=True, type=Path)
    parser.add_argument("--table", required=True, type=Path)
    args = parser.parse_args()
    try:
        rows = read_table(args.table)
    except ValueError as error:
        print(error)
        return 1
    failed = 0
    for number, option, arguments in rows:
        problems = check_line(args.exe, option, arguments)
        shown = shlex.join(arguments)
        if problems:
            failed += 1
            print(f"FAIL {args.table.name}:{number}: {shown}")
            for problem in problems:
                print(f"    {problem}")
        else:
            print(f"ok   {shown}")
    print(f"\n{len(rows) - failed} of {len(rows)} bad command lines refused before anything ran or was written")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
