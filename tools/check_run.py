#!/usr/bin/env python3
"""Runs a chapter executable in --quick mode and checks what it leaves behind (a ctest test).

Checks: the exit code is 0; nothing printed is NaN or inf; no staging folder or temporary file is
left behind; every file listed in
<expected>/files.txt exists and is not empty (PNGs only when the run had a display); every .pvd
names frames that exist; every CSV stored in <expected>/ is reproduced (see csv_compare.py: the
measured columns are skipped, the rest must agree to --rtol).

  check_run.py --exe build/bin/ch01_finite_differences --expected tests/01_finite_differences/expected \
               --out build/check_runs/01_finite_differences [--update]

--update stores the run's CSVs and file list as the new expectation (review the diff, then commit).
"""

import argparse
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from csv_compare import compare_tables, read_csv  # noqa: E402

NON_FINITE = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.IGNORECASE)
SKIPPED_PNG = "PNG figures were skipped"


def run(exe, out, extra_args):
    if out.exists():
        shutil.rmtree(out)
    command = [str(exe), "--quick", "--out", str(out), *extra_args]
    result = subprocess.run(command, capture_output=True, text=True, timeout=1200)
    return command, result


def check_pvd(path):
    problems = []
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        return [f"{path.name} is not valid XML: {error}"]
    datasets = root.findall("./Collection/DataSet")
    if not datasets:
        problems.append(f"{path.name} lists no frames")
    for dataset in datasets:
        frame = path.parent / dataset.get("file", "")
        if not frame.is_file() or frame.stat().st_size == 0:
            problems.append(f"{path.name} names a missing frame {dataset.get('file')}")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--exe", required=True, type=Path)
    parser.add_argument("--expected", required=True, type=Path)
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--update", action="store_true")
    parser.add_argument("args", nargs="*", help="extra arguments for the executable")
    args = parser.parse_args()

    command, result = run(args.exe, args.out, args.args)
    printed = result.stdout + result.stderr
    print(f"$ {' '.join(command)}\n{printed}")
    problems = []
    if result.returncode != 0:
        problems.append(f"exit code {result.returncode}, expected 0")
    for match in NON_FINITE.finditer(printed):
        line = printed[:match.start()].count("\n") + 1
        problems.append(f"output line {line} prints a non-finite number: '{match.group(0)}'")
    if problems:
        return report(problems)

    # Hidden entries are the run's bookkeeping (.fem-run-files): not results. A staging folder or
    # temporary file left behind is a bug (common/files.hpp: the run's files appear together).
    produced = sorted(p.name for p in args.out.iterdir() if p.is_file() and not p.name.startswith("."))
    for leftover in sorted(args.out.rglob("*")):
        if leftover.name.startswith(".staging-") or ".tmp-" in leftover.name:
            problems.append(f"{leftover.relative_to(args.out)} was left behind")
    if args.update:
        args.expected.mkdir(parents=True, exist_ok=True)
        for old in args.expected.glob("*.csv"):
            old.unlink()
        for name in produced:
            if name.endswith(".csv"):
                shutil.copy(args.out / name, args.expected / name)
        (args.expected / "files.txt").write_text("\n".join(produced) + "\n")
        print(f"updated {args.expected}: {len(produced)} files listed")
        return 0

    drew_pngs = SKIPPED_PNG not in printed
    listed = (args.expected / "files.txt").read_text().split()
    for name in listed:
        if name.endswith((".png", ".svg")) and not drew_pngs:  # figures need a display
            continue
        path = args.out / name
        if not path.is_file() or path.stat().st_size == 0:
            problems.append(f"{name} was not written (or is empty)")
        elif name.endswith(".pvd"):
            problems += check_pvd(path)
    for expected in sorted(args.expected.glob("*.csv")):
        actual = args.out / expected.name
        if not actual.is_file():
            problems.append(f"{expected.name} was not written")
            continue
        problems += compare_tables(*read_csv(expected), *read_csv(actual), args.rtol, expected.name)
    return report(problems)


def report(problems):
    for problem in problems:
        print(f"FAIL {problem}")
    if not problems:
        print("OK: exit code 0, files written, numbers reproduce")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
