#!/usr/bin/env python3
"""Keeps README.md true to the tree (ctest test readme_current).

- A count marked <!-- fem:count NAME -->N<!-- /fem:count --> equals the tree's: `chapters` (the
  folders chapters/NN_name), `scenes` (scenes/*.toml), `exercises` (BEGIN EXERCISE markers in
  solutions/).
- The chapter table has a row for every chapter folder, and every docs link in the README exists.
- Every path the README names in backticks or in its layout block, under a top-level folder of the
  project, exists (names with NN, *, or a placeholder are patterns, not paths).
- Every pointer elsewhere in the tree to a section of the README or of docs/engineering.md
  (`README, "Memory"`, `README.md, "Memory"`, `docs/engineering.md, "Memory"`, or in the docs
  `[engineering notes, "Memory"](engineering.md#memory)`) names a heading that page has: a section
  that moves leaves no stale pointer behind.
"""
import argparse
import re
import sys
from pathlib import Path

TOP_LEVEL = ("chapters", "solutions", "programs", "exercises", "tests", "docs", "scenes", "common", "data", "tools", "fuzz")


def tree_counts(root: Path) -> dict:
    chapters = [p for p in (root / "chapters").iterdir() if p.is_dir() and re.fullmatch(r"\d\d_\w+", p.name)]
    exercises = sum(f.read_text(encoding="utf-8").count("// BEGIN EXERCISE")
                    for f in (root / "solutions").rglob("*.cpp"))
    return {"chapters": len(chapters), "scenes": len(list((root / "scenes").glob("*.toml"))),
            "exercises": exercises}


POINTER = re.compile(r'(?P<page>README(?:\.md)?|docs/engineering\.md|engineering notes),? "(?P<section>[^"]{1,80})"')
# Where pointers are looked for: the project's own text files (not build/, not data/ or out/).
POINTER_FOLDERS = ("chapters", "solutions", "programs", "exercises", "tests", "docs", "common", "tools", "fuzz", "cmake")
POINTER_SUFFIXES = {".cpp", ".hpp", ".md", ".py", ".sh", ".cmake", ".txt"}


def headings(text: str) -> set:
    """The headings of a markdown page, their text only."""
    return {m.group(1).strip() for m in re.finditer(r"^#{1,6}\s+(.+)$", text, re.MULTILINE)}


def section_pointer_problems(root: Path) -> list:
    """Pointers to a README or docs/engineering.md section that names no heading of that page (see the
    module's docstring). A pointer may break over lines: line breaks and comment marks are spaces."""
    pages = {"README": headings((root / "README.md").read_text(encoding="utf-8")),
             "docs/engineering.md": headings((root / "docs" / "engineering.md").read_text(encoding="utf-8"))}
    files = [root / "CMakeLists.txt", root / "CONTRIBUTING.md"]
    for folder in POINTER_FOLDERS:
        if (root / folder).is_dir():
            files += [f for f in sorted((root / folder).rglob("*")) if f.is_file() and f.suffix in POINTER_SUFFIXES]
    problems = []
    for path in files:
        if path.resolve() == Path(__file__).resolve():
            continue  # its own examples above
        text = re.sub(r"\s*\n\s*(?:///?|#+)?\s*", " ", path.read_text(encoding="utf-8", errors="replace"))
        for m in POINTER.finditer(text):
            page = "README" if m["page"].startswith("README") else "docs/engineering.md"
            if m["section"] not in pages[page]:
                where = [p for p, h in pages.items() if m["section"] in h]
                hint = f"; it is a heading of {where[0]}" if where else ""
                problems.append(f"{path.relative_to(root)} points at {m['page']}, \"{m['section']}\", which is no "
                                f"heading of {'README.md' if page == 'README' else page}{hint}")
    return problems


def problems_of(root: Path, text: str) -> list:
    problems = []
    counts = tree_counts(root)
    marked = re.findall(r"<!-- fem:count (\w+) -->([^<]*)<!-- /fem:count -->", text)
    if not marked:
        problems.append("no <!-- fem:count … --> marks: the README's counts are not checked")
    for name, value in marked:
        if name not in counts:
            problems.append(f"fem:count {name}: unknown count (known: {', '.join(sorted(counts))})")
        elif value.strip() != str(counts[name]):
            problems.append(f"fem:count {name}: the README says {value.strip()}, the tree has {counts[name]}")
    for chapter in sorted(p.name for p in (root / "chapters").iterdir() if re.fullmatch(r"\d\d_\w+", p.name)):
        if not re.search(rf"^\| {chapter[:2]} \|.*\(docs/{chapter}\.md\)", text, re.MULTILINE):
            problems.append(f"the chapter table has no row '| {chapter[:2]} | … (docs/{chapter}.md)'")
    for link in re.findall(r"\]\(([^)#]+)\)", text):
        if not link.startswith("http") and not (root / link).exists():
            problems.append(f"link to {link}, which does not exist")
    candidates = re.findall(r"`([^`\s]+)`", text) + re.findall(r"^    ([\w./]+/)\s", text, re.MULTILINE)
    for name in candidates:
        path = name.rstrip("/")
        if path.split("/")[0] not in TOP_LEVEL or re.search(r"NN|\*|<|\.\.\.|…", path):
            continue
        if not (root / path).exists():
            problems.append(f"`{name}` is named but does not exist")
    for name in ("LICENSE", "CONTRIBUTING.md", "docs/engineering.md"):
        if name not in text or not (root / name).exists():
            problems.append(f"the README must name {name}, and it must exist")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    args = parser.parse_args()
    problems = problems_of(args.root, (args.root / "README.md").read_text(encoding="utf-8"))
    problems += section_pointer_problems(args.root)
    for problem in problems:
        print(f"FAIL README.md: {problem}")
    if problems:
        return 1
    print("OK: README.md's counts, chapter table, links and paths match the tree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
