#!/usr/bin/env python3
"""Checks the course layout (a ctest test): every chapter registered in CMakeLists.txt has its
header(s), programs/NN_name/main.cpp, solutions, tests, stored quick-run expectations and docs; its
contract folder chapters/NN_name holds headers only (programs, studies and build files live in
programs/NN_name); a chapter includes only its own and earlier chapters' headers, each of them
listed in its DEPENDS; common/ includes no
chapter at all; no Catch2 test name contains a character that ctest cannot carry (';' splits a
CMake list, so the ctest entry would run no test case; a leading '-' makes Catch2 read it as an
option); no test case carries more than one exercise
tag [exNN.k] (a test grades one exercise; what else it needs, that exercise's docs list under
"Builds on", and tools/exercises.py grade checks)."""

import argparse
import re
import sys
from pathlib import Path

REGISTER = re.compile(r"^fem_add_chapter\((?P<number>\d\d)\s+(?P<name>\w+)(?:\s+DEPENDS(?P<deps>[\s\d]+))?"
                      r"(?:\s+OWN[\s\w.]+)?\)", re.M)
INCLUDE = re.compile(r'^\s*#\s*include\s+"(?P<chapter>\d\d)_\w+/', re.M)
# TEST_CASE( followed by one or more adjacent string literals: the test name, then its tags.
TEST_NAME = re.compile(r'\bTEST_CASE\(\s*((?:"(?:[^"\\]|\\.)*"\s*)+)(?:,\s*"(?P<tags>[^"]*)")?')
EXERCISE_TAG = re.compile(r"\[ex\d\d\.\d+\]")
STRING_PIECE = re.compile(r'"((?:[^"\\]|\\.)*)"')


def test_case_problems(root):
    """Catch2 test names that ctest cannot carry (a ';' splits the name into two CMake list items)
    and test cases with more than one exercise tag."""
    problems = []
    for source in sorted((root / "tests").rglob("*.cpp")):
        text = source.read_text()
        for m in TEST_NAME.finditer(text):
            name = "".join(STRING_PIECE.findall(m.group(1)))
            where = f"{source.relative_to(root)}:{text[:m.start()].count(chr(10)) + 1}"
            if ";" in name:
                problems.append(f"{where}: test name '{name}' contains ';', which CMake splits: its "
                                "ctest entry would run no test case")
            if name.startswith("-"):
                problems.append(f"{where}: test name '{name}' starts with '-': its ctest entry passes it "
                                "to Catch2, which reads it as an option")
            tags = EXERCISE_TAG.findall(m["tags"] or "")
            if len(tags) > 1:
                problems.append(f"{where}: test '{name}' has the exercise tags {''.join(tags)}: tag it "
                                "with the one exercise it grades and list the others under that "
                                "exercise's 'Builds on' in the docs")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    root = parser.parse_args().root
    problems = []
    registered = {m["number"]: (m["name"], set((m["deps"] or "").split()))
                  for m in REGISTER.finditer((root / "CMakeLists.txt").read_text())}
    if not registered:
        problems.append("CMakeLists.txt registers no chapter with fem_add_chapter")
    for number, (name, deps) in sorted(registered.items()):
        chapter = f"{number}_{name}"
        required = [root / "programs" / chapter / "main.cpp", root / "docs" / f"{chapter}.md",
                    root / "tests" / chapter / "expected" / "files.txt"]
        for path in required:
            if not path.is_file():
                problems.append(f"chapter {chapter}: {path.relative_to(root)} is missing")
        for folder, pattern in [("chapters", "*.hpp"), ("solutions", "*.cpp"), ("exercises", "*.cpp"),
                                ("tests", "*.cpp")]:
            if not list((root / folder / chapter).glob(pattern)):
                problems.append(f"chapter {chapter}: no {pattern} in {folder}/{chapter}")
        for entry in sorted((root / "chapters" / chapter).iterdir()):
            if entry.suffix != ".hpp":
                problems.append(f"chapter {chapter}: {entry.relative_to(root)} is not a header: the contract "
                                f"folder holds the public headers only (programs go in programs/{chapter})")
        for folder in ["chapters", "solutions", "tests", "programs"]:
            for source in sorted((root / folder / chapter).glob("*.?pp")):
                for m in INCLUDE.finditer(source.read_text()):
                    used = m["chapter"]
                    where = source.relative_to(root)
                    if used > number:
                        problems.append(f"{where} includes chapter {used}: a chapter may use earlier chapters only")
                    elif used != number and used not in deps:
                        problems.append(f"{where} includes chapter {used}, which is not in the DEPENDS "
                                        f"of fem_add_chapter({number} {name} ...)")
    for source in sorted((root / "common").glob("*.?pp")):
        if INCLUDE.search(source.read_text()):
            problems.append(f"{source.relative_to(root)} includes a chapter: common/ holds no chapter's math")
    problems += test_case_problems(root)
    for problem in problems:
        print(f"FAIL {problem}")
    if not problems:
        print(f"OK: {len(registered)} chapters, each complete and including only earlier chapters")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
