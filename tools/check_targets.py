#!/usr/bin/env python3
"""Checks a chapter's own build target (a ctest test per chapter): `cmake --build --preset student
--target test_chNN` must build that chapter's tests from the chapter and the earlier chapters it
uses only, never a later one, so that a student working on chapter NN waits for nothing else
(README, "A student's loop"). Reads the dependency graph of the Ninja build without building.
"""

import argparse
import re
import subprocess
import sys
from pathlib import Path

CHAPTER_SOURCE = re.compile(r"/(?:chapters|solutions|exercises|tests)/(?P<number>\d\d)_\w+/")


UNITY_INCLUDE = re.compile(r'^#include "(?P<path>[^"]+)"$', re.MULTILINE)


def with_unity_sources(build, inputs):
    """The inputs, each unity source CMake generated (a unity build, FEM_UNITY_TEST_BATCH ≠ 1:
    <target>.dir/Unity/unity_N_cxx.cxx, relative to the build folder) followed by the sources it includes."""
    expanded = []
    for path in inputs:
        expanded.append(path)
        if "/Unity/unity_" in path and path.endswith(".cxx"):
            unity = Path(path) if Path(path).is_absolute() else build / path
            expanded += UNITY_INCLUDE.findall(unity.read_text())
    return expanded


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--build", type=Path, required=True, help="a configured build folder")
    parser.add_argument("--chapter", required=True, help="e.g. 05_strain_stress")
    args = parser.parse_args()
    number = args.chapter[:2]
    target = f"bin/test_ch{number}"
    if not (args.build / "build.ninja").is_file():
        print(f"SKIP {args.build} is not a Ninja build: nothing to read the target graph from")
        return 0
    result = subprocess.run(["ninja", "-C", str(args.build), "-t", "inputs", target],
                            capture_output=True, text=True)
    if result.returncode != 0:
        print(f"FAIL there is no target test_ch{number} in {args.build}: {result.stderr.strip()}")
        return 1
    inputs = with_unity_sources(args.build, result.stdout.split())
    later = sorted({i for i in inputs if (m := CHAPTER_SOURCE.search(i)) and m["number"] > number})
    own_tests = [i for i in inputs if f"/tests/{args.chapter}/" in i and i.endswith(".cpp")]
    problems = [f"test_ch{number} builds {path}, a file of a later chapter" for path in later]
    if not own_tests:
        problems.append(f"test_ch{number} builds none of tests/{args.chapter}/*.cpp")
    for problem in problems:
        print(f"FAIL {problem}")
    if not problems:
        print(f"OK: test_ch{number} builds chapter {number}'s tests from {len(inputs)} inputs, "
              f"none of a later chapter")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
