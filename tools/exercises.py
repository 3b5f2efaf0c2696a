#!/usr/bin/env python3
"""The exercise machinery: one source of truth in solutions/, stubs generated into exercises/.

An exercise region in a solution file looks like this (ids are NN.k, NN the chapter number):

    // BEGIN EXERCISE 05.2 strain_displacement_matrix #strain
    // HINT: B_e = D J_e; D picks the six strain components out of vec(J).
    ...the solution...
    // END EXERCISE

`#strain` is the section of docs/NN_name.md that teaches it. The HINT lines stay in the stub.

Commands:
  generate  write exercises/ from solutions/ (stubs throw fem::NotImplemented)
  check     fail if exercises/ is not what `generate` would write
  list      print every exercise: id, function, docs section, file:line
  graded    write one chapter's solutions (the files named, else all) with each region behind the run-time switch
            fem::exercise_stubbed(id), for a grading build (-DFEM_GRADING=ON)
  grade     with a build configured with -DFEM_GRADING=ON whose target fem_graded_tests is built
            (<build>/bin/test_chNN), check every exercise's tests against its stubs
            (see command_grade)

What an exercise builds on is written in its chapter's docs, on the line right under its heading:

    ### Exercise 05.8: element_stiffness

    Builds on: 05.3, 05.6.

("Builds on: nothing." when it needs no other exercise). It lists the exercises whose code the
tests tagged [ex05.8] run besides 05.8's own: earlier exercises of the same chapter (those the
check below holds to it) or of an earlier chapter (for the reader; a student's build links the
reference solution of every other chapter). `grade` proves the list right.
"""

import argparse
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

BEGIN = re.compile(r"^(?P<indent>\s*)// BEGIN EXERCISE (?P<id>\d\d\.\d+) (?P<function>\w+) "
                   r"#(?P<section>[\w-]+)\s*$")
END = re.compile(r"^\s*// END EXERCISE\s*$")
HINT = re.compile(r"^\s*// HINT: ?(?P<text>.*)$")
CHAPTER_DIR = re.compile(r"^(?P<number>\d\d)_\w+$")
EXERCISE_HEADING = re.compile(r"^###\s+Exercise\s+(?P<id>\d\d\.\d+):\s+`?(?P<function>\w+)", re.M)
BUILDS_ON = re.compile(r"^Builds on: (?:nothing|(?P<ids>\d\d\.\d+(?:, \d\d\.\d+)*))\.$")
NOT_IMPLEMENTED = re.compile(r"exercise (?P<id>\d\d\.\d+) \(\w+\) is not implemented yet")
# Catch2 wraps a message at 80 columns and indents it by 2: a docs link on its own line (see
# common/error.cpp) stays whole if it is at most this long.
MAX_LINK_LENGTH = 76


class ExerciseError(Exception):
    """A malformed exercise region, reported with file and line."""


@dataclass
class Exercise:
    id: str
    function: str
    section: str
    chapter: str          # e.g. 01_finite_differences
    path: Path            # the solution file
    begin_line: int       # 1-based line of BEGIN
    end_line: int         # 1-based line of END
    hints: list = field(default_factory=list)

    @property
    def docs(self):
        return f"docs/{self.chapter}.md#{self.section}"


def chapters(root):
    """The chapter folders of solutions/, in order."""
    base = Path(root) / "solutions"
    return sorted(p.name for p in base.iterdir() if p.is_dir() and CHAPTER_DIR.match(p.name))


def parse_file(path, chapter):
    """The exercises of one solution file, and its lines."""
    lines = path.read_text().splitlines(keepends=True)
    number = CHAPTER_DIR.match(chapter)["number"]
    exercises, current = [], None
    for index, line in enumerate(lines, start=1):
        begin = BEGIN.match(line)
        where = f"{path}:{index}"
        if begin:
            if current:
                raise ExerciseError(f"{where}: BEGIN EXERCISE {begin['id']} inside exercise "
                                    f"{current.id} (started at line {current.begin_line})")
            if not begin["id"].startswith(number + "."):
                raise ExerciseError(f"{where}: exercise {begin['id']} in chapter {chapter}: "
                                    f"its id must start with {number}.")
            current = Exercise(begin["id"], begin["function"], begin["section"], chapter, path,
                               index, -1)
        elif "BEGIN EXERCISE" in line:
            raise ExerciseError(f"{where}: malformed marker; expected "
                                f"'// BEGIN EXERCISE NN.k function_name #docs-section'")
        elif END.match(line):
            if not current:
                raise ExerciseError(f"{where}: END EXERCISE without a BEGIN")
            current.end_line = index
            exercises.append(current)
            current = None
        elif current and HINT.match(line) and index == current.begin_line + 1 + len(current.hints):
            current.hints.append(HINT.match(line)["text"])
    if current:
        raise ExerciseError(f"{path}:{current.begin_line}: exercise {current.id} has no END EXERCISE")
    return exercises, lines


def all_exercises(root):
    """Every exercise of every chapter, checked for unique ids."""
    found, seen = [], {}
    for chapter in chapters(root):
        for path in sorted((Path(root) / "solutions" / chapter).glob("*.cpp")):
            exercises, _ = parse_file(path, chapter)
            for exercise in exercises:
                if exercise.id in seen:
                    other = seen[exercise.id]
                    raise ExerciseError(f"{path}:{exercise.begin_line}: exercise id {exercise.id} "
                                        f"is also used at {other.path}:{other.begin_line}")
                seen[exercise.id] = exercise
                found.append(exercise)
    return sorted(found, key=lambda e: (e.chapter, int(e.id.split(".")[1])))


def exercise_key(exercise_id):
    """Sort key of an id: 05.10 comes after 05.9."""
    chapter, number = exercise_id.split(".")
    return int(chapter), int(number)


def builds_on(text):
    """{exercise id: the ids on the "Builds on:" line under its heading, or None} of a docs page.
    None means the first non-blank line under the heading is not a well-formed "Builds on:" line."""
    lines = text.splitlines()
    found = {}
    for index, line in enumerate(lines):
        heading = EXERCISE_HEADING.match(line)
        if not heading:
            continue
        following = next((l.strip() for l in lines[index + 1:] if l.strip()), "")
        match = BUILDS_ON.match(following)
        if match is None:
            found[heading["id"]] = None
        else:
            found[heading["id"]] = match["ids"].split(", ") if match["ids"] else []
    return found


def prerequisites(root, chapter):
    """{exercise id: the ids it builds on} of one chapter, from its docs (see builds_on)."""
    doc = Path(root) / "docs" / f"{chapter}.md"
    return builds_on(doc.read_text()) if doc.is_file() else {}


def closure_in_chapter(exercise_id, listed):
    """Every exercise of exercise_id's chapter it builds on, directly or through another one."""
    chapter = exercise_id.split(".")[0]
    found, todo = set(), [exercise_id]
    while todo:
        for other in listed.get(todo.pop()) or []:
            if other.split(".")[0] == chapter and other not in found:
                found.add(other)
                todo.append(other)
    return found


def throw_statement(exercise, indent):
    return (f'{indent}throw fem::NotImplemented("{exercise.id}", "{exercise.function}", '
            f'"{exercise.docs}");\n')


def stub_source(path, chapter):
    """The exercise version of one solution file: each region replaced by its stub."""
    exercises, lines = parse_file(path, chapter)
    out, skip_until = [], 0
    regions = {e.begin_line: e for e in exercises}
    for index, line in enumerate(lines, start=1):
        if index <= skip_until:
            continue
        exercise = regions.get(index)
        if not exercise:
            out.append(line)
            continue
        indent = BEGIN.match(line)["indent"]
        out.append(f"{indent}// EXERCISE {exercise.id} ({exercise.function}): see {exercise.docs}\n")
        for hint in exercise.hints:
            out.append(f"{indent}// HINT: {hint}\n")
        out.append(throw_statement(exercise, indent))
        skip_until = exercise.end_line
    header = ("// GENERATED by tools/exercises.py from solutions/ — edit the solution, then run\n"
              "// `python3 tools/exercises.py generate`. Fill in the regions marked EXERCISE.\n")
    return header + "".join(out)


def graded_source(path, chapter):
    """One solution file with each region behind the run-time switch of the grading build."""
    exercises, lines = parse_file(path, chapter)
    regions = {e.begin_line: e for e in exercises}
    out = [f'#line 1 "{path.resolve()}"\n']
    for index, line in enumerate(lines, start=1):
        out.append(line)
        exercise = regions.get(index)
        if exercise:
            indent = BEGIN.match(line)["indent"]
            out.append(f'{indent}if (fem::exercise_stubbed("{exercise.id}"))\n')
            out.append(throw_statement(exercise, indent + "    "))
            out.append(f'#line {index + 1} "{path.resolve()}"\n')
    return "".join(out)


def expected_exercise_tree(root):
    """{relative path under exercises/: content} for every solution file with an exercise region:
    its copy with the regions stubbed. A solution file without one has no copy (a student would
    find nothing to do in it); a build from exercises/ compiles the solution file itself
    (fem_add_chapter)."""
    tree = {}
    for chapter in chapters(root):
        for path in sorted((Path(root) / "solutions" / chapter).iterdir()):
            if path.is_file() and path.suffix == ".cpp" and "// BEGIN EXERCISE" in path.read_text():
                tree[Path(chapter) / path.name] = stub_source(path, chapter)
    return tree


def command_generate(args):
    root = Path(args.root)
    tree = expected_exercise_tree(root)
    written = 0
    for relative, content in tree.items():
        target = root / "exercises" / relative
        if not target.exists() or target.read_text() != content:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(content)
            written += 1
    for path in (root / "exercises").rglob("*"):
        if path.is_file() and path.relative_to(root / "exercises") not in tree:
            path.unlink()
            print(f"removed {path} (its solution file has no exercise region)")
    print(f"exercises/: {len(tree)} files, {written} rewritten, {len(all_exercises(root))} exercises")
    return 0


def command_check(args):
    root = Path(args.root)
    long_links = [e for e in all_exercises(root) if len(e.docs) > MAX_LINK_LENGTH]
    for e in long_links:
        print(f"exercise {e.id}: its docs link {e.docs} has {len(e.docs)} characters; Catch2 would "
              f"break it over two lines: shorten the section's heading to {MAX_LINK_LENGTH} at most")
    if long_links:
        return 1
    tree = expected_exercise_tree(root)
    stale = [str(r) for r, content in tree.items()
             if not (root / "exercises" / r).exists() or (root / "exercises" / r).read_text() != content]
    extra = [str(p.relative_to(root / "exercises")) for p in (root / "exercises").rglob("*")
             if p.is_file() and p.relative_to(root / "exercises") not in tree]
    if stale or extra:
        for name in stale:
            print(f"exercises/{name} is out of sync with solutions/{name}")
        for name in extra:
            print(f"exercises/{name} has no exercise region in solutions/{name}")
        print("run: python3 tools/exercises.py generate")
        return 1
    print(f"exercises/ is in sync with solutions/ ({len(tree)} files, "
          f"{len(all_exercises(root))} exercises)")
    return 0


def command_list(args):
    for e in all_exercises(args.root):
        print(f"{e.id:7} {e.function:34} {e.docs:52} {e.path.relative_to(Path(args.root).resolve()) if e.path.is_absolute() else e.path}:{e.begin_line}")
    return 0


def command_graded(args):
    root = Path(args.root).resolve()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # The files named (the build's files with an exercise region), else every file of the chapter.
    paths = [root / "solutions" / args.chapter / name for name in args.files] if args.files else \
        sorted((root / "solutions" / args.chapter).glob("*.cpp"))
    for path in paths:
        content = graded_source(path, args.chapter)
        target = out / path.name
        if not target.exists() or target.read_text() != content:
            target.write_text(content)
    return 0


@dataclass
class TestRun:
    """The test cases one run of a chapter's test binary ran, from Catch2's XML report."""
    cases: int = 0
    failed: list = field(default_factory=list)   # names of the failed test cases
    failed_untagged: list = field(default_factory=list)  # those of them without an [exNN.k] tag
    missing: set = field(default_factory=set)    # exercise ids named by NotImplemented in failures
    crash: str = ""                              # why there is no report, if there is none


def run_tests(binary, test_spec, stubbed):
    """Runs the test cases of binary that match test_spec (e.g. "[ex05.3]") with the exercises in
    stubbed (a collection of ids) behind their stubs; every test case when test_spec is None."""
    env = dict(os.environ, FEM_STUB_EXERCISE=",".join(sorted(stubbed, key=exercise_key)))
    spec = [test_spec] if test_spec else []
    result = subprocess.run([str(binary), *spec, "--reporter", "xml"], env=env,
                            capture_output=True, text=True, timeout=600)
    try:
        report = ElementTree.fromstring(result.stdout)
    except ElementTree.ParseError:
        return TestRun(crash=f"the test binary crashed or printed no report (exit {result.returncode})")
    run = TestRun()
    for case in report.iter("TestCase"):
        run.cases += 1
        if case.find("OverallResult").get("success") != "true":
            run.failed.append(case.get("name"))
            if not re.search(r"\[ex\d\d\.\d+\]", case.get("tags", "")):
                run.failed_untagged.append(case.get("name"))
            run.missing |= {m["id"] for m in NOT_IMPLEMENTED.finditer("".join(case.itertext()))}
    return run


def grade_exercise(e, chapter_ids, listed, binary):
    """The table row of one exercise and the problems found: its tagged tests must fail with its stub
    alone, and pass when every exercise of its chapter that it does not build on is a stub (what a
    student sees who did it and what it builds on). That they pass on the solution is not run here
    again: the release stage runs every test on the solutions, and the second run above passes only
    where they do."""
    tag = f"[ex{e.id}]"
    needed = closure_in_chapter(e.id, listed)
    stub = run_tests(binary, tag, [e.id])
    others = [other for other in chapter_ids if other != e.id and other not in needed]
    student = run_tests(binary, tag, others)
    shown = ", ".join(listed.get(e.id) or []) or "nothing"
    row = (f"{e.id:9} {e.function:30} {shown:24} {student.cases:>6} "
           f"{len(stub.failed):>8} {student.cases - len(student.failed):>9}")
    crash = stub.crash or student.crash
    if listed.get(e.id) is None:
        return row, [f"{e.id}: docs/{e.chapter}.md has no line 'Builds on: …' under its heading"]
    if student.cases == 0 and not crash:
        return row, [f"{e.id}: no test case is tagged {tag}"]
    if crash:
        return row, [f"{e.id}: {crash}"]
    problems = []
    if not stub.failed:
        problems.append(f"{e.id}: no tagged test fails when it is a stub: its tests do not grade it")
    elif stub.missing != {e.id}:
        problems.append(f"{e.id}: as a stub, its tests fail without naming it ({stub.missing or 'no exercise'}): "
                        f"a student would not be told which exercise to do")
    if student.failed:
        extra = ", ".join(sorted(student.missing - {e.id}, key=exercise_key)) or "no exercise named"
        problems.append(f"{e.id}: with only it and what it builds on ({shown}) done, "
                        f"{len(student.failed)} of its tests (e.g. '{student.failed[0]}') still fail "
                        f"for {extra}: list those under 'Builds on' in docs/{e.chapter}.md, or make "
                        f"the tests need only {e.id} and what it builds on")
    return row, problems


def command_grade(args):
    """Every exercise of the registered chapters, graded by its tagged tests [exNN.k]:
      1. with the exercise alone a stub, at least one fails, and the failures name that exercise;
      2. with every other exercise of the chapter a stub except those it builds on (its docs'
         "Builds on:" line, followed through), they all pass: a test needs nothing unlisted.
    Also, with every exercise of a chapter a stub, its untagged tests pass (they grade no exercise,
    so they may run only the code the chapter gives)."""
    root = Path(args.root)
    build = Path(args.build)
    # Only the chapters the build registers (fem_add_chapter in CMakeLists.txt) are graded; a
    # chapter still being written has solutions but no test binary yet.
    registered = set(re.findall(r"^fem_add_chapter\((\d\d)\s", (root / "CMakeLists.txt").read_text(), re.M))
    exercises = [e for e in all_exercises(root) if e.chapter[:2] in registered]
    if args.chapters:
        exercises = [e for e in exercises if e.chapter[:2] in args.chapters]
    print("\nEach exercise's tests [exNN.k]: fail with it alone a stub, and pass when the rest of its")
    print("chapter is stubs except what it builds on (on the solutions they pass in the release stage)\n")
    print(f"{'exercise':9} {'function':30} {'builds on':24} {'tests':>6} {'as stub':>8} {'pre only':>9}")
    print(f"{'':9} {'':30} {'':24} {'':>6} {'failed':>8} {'passed':>9}")
    problems = []
    for chapter in sorted({e.chapter for e in exercises}):
        binary = build / "bin" / f"test_ch{chapter[:2]}"
        in_chapter = [e for e in exercises if e.chapter == chapter]
        if not binary.exists():
            problems.append(f"chapter {chapter}: no test binary {binary} (configure with -DFEM_GRADING=ON "
                            f"and build the target fem_graded_tests)")
            continue
        listed = prerequisites(root, chapter)
        chapter_ids = [e.id for e in all_exercises(root) if e.chapter == chapter]
        # The exercises' test runs are independent processes: as many at once as there are cores,
        # the rows printed in order.
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            graded = pool.map(lambda e: grade_exercise(e, chapter_ids, listed, binary), in_chapter)
            for row, found in graded:
                print(row, flush=True)
                problems += found
        all_stubs = run_tests(binary, None, chapter_ids)
        if all_stubs.crash or all_stubs.failed_untagged:
            problems.append(f"chapter {chapter}: with every exercise a stub, untagged tests fail "
                            f"({all_stubs.crash or all_stubs.failed_untagged}): tag each with the "
                            f"exercise it grades")
    print()
    if problems:
        for problem in problems:
            print(f"FAIL {problem}")
        return 1
    print(f"all {len(exercises)} exercises are graded by their own tests, which need only what "
          f"their docs say they build on")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=["generate", "check", "list", "graded", "grade"])
    parser.add_argument("--root", default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--chapter", help="graded: the chapter folder, e.g. 01_finite_differences")
    parser.add_argument("--out", help="graded: the folder for the generated sources")
    parser.add_argument("--files", nargs="*", help="graded: the chapter's files to write (default: all)")
    parser.add_argument("--build", help="grade: a build configured with -DFEM_GRADING=ON, "
                        "its target fem_graded_tests built")
    parser.add_argument("--chapters", nargs="*", help="grade: only these chapter numbers (01 05 ...)")
    args = parser.parse_args()
    try:
        return globals()[f"command_{args.command}"](args)
    except ExerciseError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
