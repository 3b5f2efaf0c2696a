#!/usr/bin/env python3
"""Keeps docs/NN_name.md from drifting away from the code (a ctest test per chapter).

Checks:
  1. every exercise of the chapter has a heading "### Exercise NN.k: function_name" followed by a
     line "Builds on: NN.k, …." (or "Builds on: nothing.") naming earlier exercises, every
     "exercise NN.k" the text mentions exists, and every exercise's docs section (#anchor) is a
     heading of the page;
  2. every function or type the page names in backticks (snake_case calls like
     `central_difference(f, x, h)` and qualified names like `fem::fd::HeatRod`) is declared in the
     headers of this chapter, an earlier one, or common/;
  3. the tables between <!-- fem:table NAME.csv --> and <!-- /fem:table --> hold the numbers the
     executable prints today: the page's <!-- fem:run chNN_name [args] --> line says how to run it
     ({root} in args: the project's folder);
     cell by cell by the rules of csv_compare.cells_differ (measured columns such as times are
     skipped, iteration counts agree within one, round-off is held to bounds);
  4. every number a sentence quotes from a table, marked
         <!-- fem:value NAME.csv KEY=VALUE … "COLUMN" -->6·10⁻³<!-- /fem:value -->
     (the row whose KEY columns hold those VALUEs, quoted with "" when they contain spaces), is the
     executable's value rounded to the significant digits the sentence shows (see
     csv_compare.quoted_number), or agrees with it by the column's rules (csv_compare.cells_differ:
     iteration counts within one, a "[±X]" column within X);
  5. every image the page shows exists;
  6. the page's "## Exercises" section opens with the exercise table (check_exercise_table), one row
     per exercise of the chapter, before its first "### Exercise" heading:
         | exercise | stub file | tests | builds on |
         |---|---|---|---|
         | [05.8 `element_stiffness`](#exercise-058-element_stiffness) | `exercises/05_strain_stress/material.cpp` | `tests/05_strain_stress/test_stiffness.cpp` | 05.3, 05.6 |
     the stub file holds the exercise's stub, the tests are every file of tests/NN_name holding a
     test case tagged [exNN.k], the builds-on cell repeats the "Builds on:" line (— for nothing), and
     the exercise's heading or the first paragraph after that line names the stub file. --exercise-table prints the table the
     check expects; --exercises-only runs checks 1 and 6 alone (no executable needed: ctest
     chNN_exercise_table).

The check runs the executable with --no-figures: it compares numbers, and the figures are drawn by
the chapter's quick run (chNN_quick_run) and checked by figures_current; drawing them at full size
here took about a third of each run's time. --update reruns the executable with its figures,
rewrites the tables and copies the figures named by
<!-- fem:figure NAME.png --> into docs/figures/NN_name/, a chart's NAME.svg beside its PNG (run it
under xvfb-run -a). It never
rewrites a quoted number: a sentence around a number that changed needs a person, so --update
lists those and fails.
"""

import argparse
import math
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from csv_compare import as_number, cells_differ, is_measured, quoted_number, read_csv, rounded  # noqa: E402
from exercises import BUILDS_ON, EXERCISE_HEADING, all_exercises, builds_on, exercise_key  # noqa: E402

RUN = re.compile(r"<!-- fem:run (?P<exe>\S+)(?P<args>[^>]*?)\s*-->")
TABLE = re.compile(r"(<!-- fem:table (?P<csv>\S+) -->\n)(?P<body>.*?)(<!-- /fem:table -->)", re.S)
FIGURE = re.compile(r"<!-- fem:figure (?P<png>\S+) -->")
IMAGE = re.compile(r"!\[[^\]]*\]\((?P<path>[^)\s]+)\)")
HEADING = re.compile(r"^(#{1,6})\s+(?P<text>.+?)\s*$", re.M)
EXERCISE_MENTION = re.compile(r"[Ee]xercises?\s+(?P<id>\d\d\.\d+)")
CODE_SPAN = re.compile(r"`([^`\n]+)`")
CALL = re.compile(r"^(?:fem::(?:\w+::)*)?(?P<name>[a-z]\w*_\w+)\(")
QUALIFIED = re.compile(r"^fem::(?:\w+::)*(?P<name>\w+)$")
VALUE = re.compile(r"<!-- fem:value (?P<spec>.*?) -->(?P<text>.*?)<!-- /fem:value -->", re.S)
RELATIVE_TOLERANCE = 2e-3  # the tables print 4 significant digits


def slug(heading):
    """GitHub's anchor for a heading."""
    text = re.sub(r"[`*_]", lambda m: "_" if m.group(0) == "_" else "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def format_number(value, measured=False):
    """A table cell: integers whole, 4 significant digits otherwise; but a value that has 5
    significant digits in full is printed in full (ν = 0.49999 must not read 0.5). Measured values
    (times, rates) always get 4 digits: more would be noise."""
    if value == int(value) and abs(value) < 1e6:
        return str(int(value))
    if 1e-2 <= abs(value) < 1e4:
        exact = f"{value:.5g}"
        return exact if float(exact) == value and not measured else f"{value:.4g}"
    return f"{value:.3e}"


def markdown_table(csv_path):
    header, rows = read_csv(csv_path)
    escape = lambda text: text.replace("|", "\\|")
    lines = ["| " + " | ".join(map(escape, header)) + " |", "|" + "|".join("---:" for _ in header) + "|"]
    for row in rows:
        cells = [format_number(float(c), is_measured(column)) if as_number(c) is not None else escape(c)
                 for c, column in zip(row, header)]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def parse_markdown_table(body):
    lines = [l.strip() for l in body.strip().splitlines() if l.strip().startswith("|")]
    split = lambda l: [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", l.strip()[1:-1])]
    return split(lines[0]), [split(l) for l in lines[2:]]


def check_quotes(text, out):
    """Problems with the numbers quoted inline by <!-- fem:value … --> (see the module's docstring)."""
    problems = []
    tables = {}
    for m in VALUE.finditer(text):
        spec, quoted = m["spec"], m["text"]
        where = f"fem:value {spec} (quoting '{quoted}')"
        try:
            name, *rest = shlex.split(spec)
        except ValueError as error:
            problems.append(f"{where}: {error}")
            continue
        selectors = [token.split("=", 1) for token in rest if "=" in token]
        columns = [token for token in rest if "=" not in token]
        number = quoted_number(quoted)
        if len(columns) != 1 or not selectors:
            problems.append(f"{where}: expected NAME.csv KEY=VALUE … \"COLUMN\" (one column, at least one key)")
            continue
        if number is None:
            problems.append(f"{where}: '{quoted}' is not a number the check can read (e.g. 6e-3, 6·10⁻³, 0.27)")
            continue
        if not (out / name).is_file():
            problems.append(f"{where}: the executable wrote no {name}")
            continue
        header, rows = tables.setdefault(name, read_csv(out / name))
        column = columns[0]
        unknown = [c for c in [column] + [k for k, _ in selectors] if c not in header]
        if unknown:
            problems.append(f"{where}: {name} has no column {unknown}; it has {header}")
            continue
        if is_measured(column):
            problems.append(f"{where}: '{column}' is measured (it changes from run to run): quote it in words")
            continue

        def matches(row, key, want):
            got = row[header.index(key)]
            a, b = as_number(want), as_number(got)
            return a == b if a is not None and b is not None else want == got

        found = [row for row in rows if all(matches(row, k, v) for k, v in selectors)]
        if len(found) != 1:
            problems.append(f"{where}: {len(found)} rows of {name} match {dict(selectors)}, expected one")
            continue
        cell = found[0][header.index(column)]
        value, digits = number
        actual = as_number(cell)
        # The quote holds when it is the cell rounded to the quote's digits, or when the two agree by
        # the column's own rules (iteration counts within one, a ±X column within X, round-off bounds).
        if actual is None or not (math.isclose(rounded(actual, digits), rounded(value, digits), rel_tol=1e-9)
                                  or cells_differ(column, repr(value), cell, 0.0) is None):
            problems.append(f"{where}: the executable prints {cell}, which to {digits} significant "
                            f"digit(s) is not {quoted}: rewrite the sentence around the new number")
    return problems


def chapter_order(name):
    """A chapter's place in the course: its number; the scenes capstone (chapters/scenes, docs/scenes.md)
    comes after every chapter."""
    return 99 if name == "scenes" else int(name[:2]) if name[:2].isdigit() else None


def declared_names(root, chapter):
    number = chapter_order(chapter)
    headers = list((root / "common").glob("*.hpp"))
    for folder in (root / "chapters").iterdir():
        if folder.is_dir() and chapter_order(folder.name) is not None and chapter_order(folder.name) <= number:
            headers += list(folder.glob("*.hpp"))
    return "\n".join(h.read_text() for h in headers)


def check_names(text, root, chapter):
    declarations = declared_names(root, chapter)
    problems = []
    for span in set(CODE_SPAN.findall(text)):
        match = CALL.match(span) or QUALIFIED.match(span)
        if not match:
            continue
        name = match["name"]
        pattern = rf"(\b{name}\s*\(|\b(struct|class|enum class|enum|using|namespace)\s+{name}\b)"
        if not re.search(pattern, declarations):
            problems.append(f"the docs name `{span}`, but no header of chapters ≤ {chapter[:2]} "
                            f"or common/ declares {name}")
    return problems


def check_exercises(text, root, chapter):
    problems = []
    anchors = {slug(m["text"]) for m in HEADING.finditer(text)}
    exercises = {e.id: e for e in all_exercises(root)}
    headed = {m["id"]: m["function"] for m in EXERCISE_HEADING.finditer(text)}
    for e in exercises.values():
        if e.chapter != chapter:
            continue
        if e.id not in headed:
            problems.append(f"exercise {e.id} ({e.function}) has no heading '### Exercise {e.id}: "
                            f"{e.function}' in docs/{chapter}.md")
        elif headed[e.id] != e.function:
            problems.append(f"the heading of exercise {e.id} names {headed[e.id]}, the code {e.function}")
        if e.section not in anchors:
            problems.append(f"exercise {e.id} points at #{e.section}, which is no heading of docs/{chapter}.md")
    for m in list(EXERCISE_MENTION.finditer(text)) + list(EXERCISE_HEADING.finditer(text)):
        if m["id"] not in exercises:
            problems.append(f"the docs mention exercise {m['id']}, which does not exist")
    for exercise_id, listed in builds_on(text).items():
        if listed is None:
            problems.append(f"the heading of exercise {exercise_id} is not followed by a line "
                            f"'Builds on: NN.k, NN.k.' or 'Builds on: nothing.'")
            continue
        if len(set(listed)) != len(listed):
            problems.append(f"exercise {exercise_id} builds on {listed}: an exercise is named twice")
        for other in listed:
            if other not in exercises:
                problems.append(f"exercise {exercise_id} builds on exercise {other}, which does not exist")
            elif exercise_key(other) >= exercise_key(exercise_id):
                problems.append(f"exercise {exercise_id} builds on exercise {other}, which does not come "
                                f"before it: an exercise builds on earlier ones only")
    return problems


EXERCISE_TABLE_HEADER = ["exercise", "stub file", "tests", "builds on"]
TAG_STRING = re.compile(r'"((?:\[[^\]"]+\])+)"')  # a Catch2 tag string, e.g. "[ex05.8][slow]"
EXERCISE_TAG = re.compile(r"\[ex(?P<id>\d\d\.\d+)\]")


def tagged_test_files(root, chapter):
    """{exercise id: the files of tests/NN_name (paths from the root, sorted) with a test case
    tagged [exNN.k]}; tags are read from the test cases' tag strings only, not from comments."""
    found = {}
    folder = root / "tests" / chapter
    for path in sorted(folder.rglob("*.cpp")) if folder.is_dir() else []:
        for tags in TAG_STRING.findall(path.read_text()):
            for m in EXERCISE_TAG.finditer(tags):
                files = found.setdefault(m["id"], [])
                relative = path.relative_to(root).as_posix()
                if relative not in files:
                    files.append(relative)
    return found


def exercise_table_row(e, heading, tests, listed):
    """The exercise table's row of exercise e (see check 6 of the module's docstring): heading is
    the text of its "### Exercise" heading, tests its tagged test files, listed its Builds-on ids."""
    link = f"[{e.id} `{e.function}`](#{slug(heading)})"
    stub = f"`exercises/{e.chapter}/{e.path.name}`"
    test_cell = " ".join(f"`{t}`" for t in tests)
    builds = ", ".join(listed) if listed else "—"
    return [link, stub, test_cell, builds]


def expected_exercise_table(text, root, chapter):
    """The exercise table (lines of markdown) the page must hold, from the chapter's exercise markers,
    its tests' tags and the page's headings and Builds-on lines."""
    headings = {m["id"]: line for line in text.splitlines() for m in [EXERCISE_HEADING.match(line)] if m}
    listed = builds_on(text)
    tests = tagged_test_files(root, chapter)
    lines = ["| " + " | ".join(EXERCISE_TABLE_HEADER) + " |", "|---|---|---|---|"]
    for e in all_exercises(root):
        if e.chapter == chapter:
            heading = headings.get(e.id, f"### Exercise {e.id}: {e.function}").lstrip("#").strip()
            lines.append("| " + " | ".join(exercise_table_row(e, heading, tests.get(e.id, []),
                                                              listed.get(e.id))) + " |")
    return lines


def check_exercise_table(text, root, chapter):
    """Check 6 of the module's docstring: the table under "## Exercises", row by row."""
    exercises = [e for e in all_exercises(root) if e.chapter == chapter]
    if not exercises:
        return []
    lines = text.splitlines()
    start = next((i for i, l in enumerate(lines) if l.strip() == "## Exercises"), None)
    if start is None:
        return [f"docs/{chapter}.md has no '## Exercises' section for its {len(exercises)} exercises"]
    # The table sits between the section's heading and the next heading (the first "### Exercise").
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("#")), len(lines))
    section = lines[start + 1:end]
    table = [l.strip() for l in section if l.strip().startswith("|")]
    if not table or parse_markdown_table(table[0] + "\n|-|\n")[0] != EXERCISE_TABLE_HEADER:
        return [f"the '## Exercises' section of docs/{chapter}.md does not open with the exercise table "
                f"'| {' | '.join(EXERCISE_TABLE_HEADER)} |' before its first '### Exercise' heading "
                f"(python3 tools/check_docs.py --chapter {chapter} --exercise-table prints it)"]
    _, rows = parse_markdown_table("\n".join(table))
    problems = []
    headings = {m["id"]: line.lstrip("#").strip() for line in lines for m in [EXERCISE_HEADING.match(line)] if m}
    listed = builds_on(text)
    tests = tagged_test_files(root, chapter)
    by_id = {}
    for number, row in enumerate(rows, start=1):
        m = re.match(r"\[(?P<id>\d\d\.\d+) ", row[0]) if row else None
        if len(row) != 4 or not m:
            problems.append(f"exercise table, row {number}: expected 4 cells, the first "
                            f"'[NN.k `function`](#anchor)'; found {row}")
            continue
        if m["id"] in by_id:
            problems.append(f"exercise table: exercise {m['id']} has two rows")
        by_id[m["id"]] = row
    known = {e.id for e in exercises}
    for extra in sorted(set(by_id) - known, key=exercise_key):
        problems.append(f"exercise table: a row for exercise {extra}, which chapter {chapter} does not have")
    for e in exercises:
        row = by_id.get(e.id)
        where = f"exercise table, row of {e.id}"
        if row is None:
            problems.append(f"exercise table: no row for exercise {e.id} ({e.function})")
            continue
        heading = headings.get(e.id)
        want = exercise_table_row(e, heading or "", tests.get(e.id, []), listed.get(e.id))
        if heading and row[0] != want[0]:
            problems.append(f"{where}: the link is {row[0]}, expected {want[0]} (the heading's anchor)")
        stub_path = re.fullmatch(r"`(?P<path>[^`]+)`", row[1])
        stub = root / stub_path["path"] if stub_path else None
        marker = f"// EXERCISE {e.id} ({e.function}):"
        if stub is None or not stub.is_file():
            problems.append(f"{where}: the stub file {row[1]} does not exist; the stub is {want[1]}")
        elif stub.parent != root / "exercises" / chapter or marker not in stub.read_text():
            problems.append(f"{where}: {row[1]} does not hold the stub of {e.id} ('{marker}'); {want[1]} does")
        cited = re.findall(r"`([^`]+)`", row[2])
        for path in cited:
            if not (root / path).is_file():
                problems.append(f"{where}: the test file {path} does not exist")
            elif path not in tests.get(e.id, []):
                problems.append(f"{where}: {path} holds no test case tagged [ex{e.id}]")
        for path in tests.get(e.id, []):
            if path not in cited:
                problems.append(f"{where}: {path} holds test cases tagged [ex{e.id}] but is not listed")
        if not tests.get(e.id):
            problems.append(f"{where}: no file of tests/{chapter} holds a test case tagged [ex{e.id}]")
        if listed.get(e.id) is not None and row[3] != want[3]:
            problems.append(f"{where}: builds on '{row[3]}', but its Builds-on line says '{want[3]}'")
    for e in exercises:
        stub = f"exercises/{e.chapter}/{e.path.name}"
        paragraph = first_paragraph_after_builds_on(lines, e.id)
        if paragraph is not None and stub not in paragraph and stub not in (headings.get(e.id) or ""):
            problems.append(f"neither the heading of exercise {e.id} nor the first paragraph under its "
                            f"Builds-on line names its stub file `{stub}`")
    return problems


def first_paragraph_after_builds_on(lines, exercise_id):
    """The first paragraph after the "Builds on:" line under exercise_id's heading (one string), or
    None when there is no such heading or line."""
    index = next((i for i, l in enumerate(lines)
                  if (m := EXERCISE_HEADING.match(l)) and m["id"] == exercise_id), None)
    if index is None:
        return None
    index = next((i for i in range(index + 1, len(lines)) if lines[i].strip()), None)
    if index is None or not BUILDS_ON.match(lines[index].strip()):
        return None
    paragraph = []
    for line in lines[index + 1:]:
        if line.strip():
            paragraph.append(line)
        elif paragraph:
            break
    return "\n".join(paragraph)


def run_executable(text, bin_dir, out, root, figures):
    match = RUN.search(text)
    if not match:
        return None, ["the page has tables but no <!-- fem:run chNN_name [args] --> line"]
    if out.exists():
        shutil.rmtree(out)
    # {root} in the arguments stands for the project's folder (e.g. the scene files of docs/scenes.md).
    arguments = match["args"].replace("{root}", str(root)).split()
    command = [str(bin_dir / match["exe"]), *arguments, "--out", str(out)]
    if not figures:
        command.append("--no-figures")
    result = subprocess.run(command, capture_output=True, text=True, timeout=3000)
    if result.returncode != 0:
        return None, [f"`{' '.join(command)}` failed ({result.returncode}):\n{result.stdout}{result.stderr}"]
    return out, []


def check_tables(text, out):
    problems = []
    for block in TABLE.finditer(text):
        name = block["csv"]
        if not (out / name).is_file():
            problems.append(f"the executable wrote no {name}")
            continue
        want_header, want_rows = parse_markdown_table(block["body"])
        header, rows = parse_markdown_table(markdown_table(out / name))
        if want_header != header:
            problems.append(f"{name}: the docs table has columns {want_header}, the executable {header}")
            continue
        if len(want_rows) != len(rows):
            problems.append(f"{name}: the docs table has {len(want_rows)} rows, the executable {len(rows)}")
            continue
        for r, (want, got) in enumerate(zip(want_rows, rows)):
            if len(want) != len(header):
                problems.append(f"{name}, row {r + 1}: the docs row has {len(want)} cells, expected {len(header)}")
                continue
            for c, column in enumerate(header):
                rule = cells_differ(column, want[c], got[c], RELATIVE_TOLERANCE)
                if rule:
                    problems.append(f"{name}, row {r + 1}, column '{column}': the docs say {want[c]}, "
                                    f"the executable prints {got[c]} ({rule})")
    return problems


def update(doc, text, out, root, chapter):
    def replace(block):
        return block.group(1) + markdown_table(out / block["csv"]) + block.group(4)
    text = TABLE.sub(replace, text)
    figures = root / "docs" / "figures" / chapter
    for m in FIGURE.finditer(text):
        source = out / m["png"]
        if source.is_file():
            figures.mkdir(parents=True, exist_ok=True)
            shutil.copy(source, figures / m["png"])
            vector = source.with_suffix(".svg")  # a chart's vector twin, for slides
            if vector.is_file():
                shutil.copy(vector, figures / vector.name)
        else:
            print(f"warning: {m['png']} was not drawn (no display?); run under xvfb-run -a")
    doc.write_text(text)
    print(f"updated {doc}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--chapter", required=True, help="e.g. 01_finite_differences")
    parser.add_argument("--bin", type=Path, help="the build's bin/ folder (for the tables)")
    parser.add_argument("--out", type=Path, help="a scratch folder for the executable's output")
    parser.add_argument("--update", action="store_true")
    parser.add_argument("--exercises-only", action="store_true",
                        help="check the exercise headings, Builds-on lines and table only (no executable)")
    parser.add_argument("--exercise-table", action="store_true",
                        help="print the exercise table the page must hold under '## Exercises'")
    args = parser.parse_args()

    doc = args.root / "docs" / f"{args.chapter}.md"
    if not doc.is_file():
        print(f"FAIL docs/{args.chapter}.md does not exist")
        return 1
    text = doc.read_text()
    if args.exercise_table:
        print("\n".join(expected_exercise_table(text, args.root, args.chapter)))
        return 0
    problems = check_exercises(text, args.root, args.chapter) + check_exercise_table(text, args.root, args.chapter)
    if args.exercises_only:
        for problem in problems:
            print(f"FAIL {problem}")
        if not problems:
            print(f"OK: docs/{args.chapter}.md's exercise headings and table name what exists")
        return 1 if problems else 0
    problems += check_names(text, args.root, args.chapter)
    for m in IMAGE.finditer(text):
        if not (doc.parent / m["path"]).is_file():
            problems.append(f"the docs show {m['path']}, which does not exist")
    if TABLE.search(text) or VALUE.search(text):
        if not (args.bin and args.out):
            problems.append("--bin and --out are needed to check the tables and quoted numbers")
        else:
            out, run_problems = run_executable(text, args.bin, args.out, args.root, figures=args.update)
            problems += run_problems
            if out and args.update:
                update(doc, text, out, args.root, args.chapter)
                stale = check_quotes(text, out)
                for problem in stale:
                    print(f"FAIL {problem}")
                return 1 if stale else 0
            if out:
                problems += check_tables(text, out) + check_quotes(text, out)
    for problem in problems:
        print(f"FAIL {problem}")
    if not problems:
        print(f"OK: docs/{args.chapter}.md names what exists and quotes what the executable prints")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
