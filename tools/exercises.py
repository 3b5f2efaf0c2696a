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
  graded    write one chapter's solutions with each region behind the run-time switch
            fem::exercise_stubbed(id), for the grading build (-DFEM_GRADING=ON)
  grade     with a grading build, stub one exercise at a time (FEM_STUB_EXERCISE=id), run the
            tests tagged [exNN.k], print how many fail, and fail if any exercise has none
"""

import argparse
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

BEGIN = re.compile(r"^(?P<indent>\s*)// BEGIN EXERCISE (?P<id>\d\d\.\d+) (?P<function>\w+) "
                   r"#(?P<section>[\w-]+)\s*$")
END = re.compile(r"^\s*// END EXERCISE\s*$")
HINT = re.compile(r"^\s*// HINT: ?(?P<text>.*)$")
CHAPTER_DIR = re.compile(r"^(?P<number>\d\d)_\w+$")


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
    """{relative path under exercises/: content} for every solution file."""
    tree = {}
    for chapter in chapters(root):
        for path in sorted((Path(root) / "solutions" / chapter).iterdir()):
            if path.is_file():
                relative = Path(chapter) / path.name
                tree[relative] = stub_source(path, chapter) if path.suffix == ".cpp" else path.read_text()
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
            print(f"removed {path} (no solution file of that name)")
    print(f"exercises/: {len(tree)} files, {written} rewritten, {len(all_exercises(root))} exercises")
    return 0


def command_check(args):
    root = Path(args.root)
    tree = expected_exercise_tree(root)
    stale = [str(r) for r, content in tree.items()
             if not (root / "exercises" / r).exists() or (root / "exercises" / r).read_text() != content]
    extra = [str(p.relative_to(root / "exercises")) for p in (root / "exercises").rglob("*")
             if p.is_file() and p.relative_to(root / "exercises") not in tree]
    if stale or extra:
        for name in stale:
            print(f"exercises/{name} is out of sync with solutions/{name}")
        for name in extra:
            print(f"exercises/{name} has no solution file")
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
    for path in sorted((root / "solutions" / args.chapter).glob("*.cpp")):
        content = graded_source(path, args.chapter)
        target = out / path.name
        if not target.exists() or target.read_text() != content:
            target.write_text(content)
    return 0


def run_tagged_tests(binary, tag, stub):
    """(tests run, tests failed) of the test cases tagged `tag`, with `stub` stubbed ('' for none)."""
    env = dict(os.environ, FEM_STUB_EXERCISE=stub)
    result = subprocess.run([str(binary), f"[{tag}]", "--reporter", "xml"], env=env,
                            capture_output=True, text=True, timeout=600)
    try:
        report = ElementTree.fromstring(result.stdout)
    except ElementTree.ParseError:
        return 0, 0, f"the test binary crashed or printed no report (exit {result.returncode})"
    cases = report.findall(".//TestCase")
    failed = sum(1 for case in cases if case.find("OverallResult").get("success") != "true")
    return len(cases), failed, ""


def command_grade(args):
    root = Path(args.root)
    build = Path(args.build)
    # Only the chapters the build registers (fem_add_chapter in CMakeLists.txt) are graded; a
    # chapter still being written has solutions but no test binary yet.
    registered = set(re.findall(r"^fem_add_chapter\((\d\d)\s", (root / "CMakeLists.txt").read_text(), re.M))
    exercises = [e for e in all_exercises(root) if e.chapter[:2] in registered]
    if args.chapters:
        exercises = [e for e in exercises if e.chapter[:2] in args.chapters]
    print(f"\nEach exercise stubbed alone: the tests tagged [exNN.k] must fail\n")
    print(f"{'exercise':9} {'function':34} {'tagged tests':>12} {'pass as solution':>16} "
          f"{'fail as stub':>12}")
    problems = []
    for e in exercises:
        binary = build / "bin" / f"test_ch{e.chapter[:2]}"
        if not binary.exists():
            problems.append(f"{e.id}: no test binary {binary}")
            continue
        tag = f"ex{e.id}"
        total, failed_solution, crash_solution = run_tagged_tests(binary, tag, "")
        total_stub, failed_stub, crash_stub = run_tagged_tests(binary, tag, e.id)
        print(f"{e.id:9} {e.function:34} {total:>12} {total - failed_solution:>16} {failed_stub:>12}")
        if total == 0:
            problems.append(f"{e.id}: no test case is tagged [{tag}]")
        elif crash_solution or crash_stub:
            problems.append(f"{e.id}: {crash_solution or crash_stub}")
        elif failed_solution:
            problems.append(f"{e.id}: {failed_solution} tagged test(s) fail on the solution")
        elif failed_stub == 0:
            problems.append(f"{e.id}: no tagged test fails when it is a stub: its tests do not grade it")
    print()
    if problems:
        for problem in problems:
            print(f"FAIL {problem}")
        return 1
    print(f"all {len(exercises)} exercises are graded: each fails at least one test as a stub")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=["generate", "check", "list", "graded", "grade"])
    parser.add_argument("--root", default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--chapter", help="graded: the chapter folder, e.g. 01_finite_differences")
    parser.add_argument("--out", help="graded: the folder for the generated sources")
    parser.add_argument("--build", help="grade: a build configured with -DFEM_GRADING=ON")
    parser.add_argument("--chapters", nargs="*", help="grade: only these chapter numbers (01 05 ...)")
    args = parser.parse_args()
    try:
        return globals()[f"command_{args.command}"](args)
    except ExerciseError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
