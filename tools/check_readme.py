#!/usr/bin/env python3
"""Keeps README.md true to the tree (ctest test readme_current).

- A count marked <!-- fem:count NAME -->N<!-- /fem:count --> equals the tree's: `chapters` (the
  folders chapters/NN_name), `scenes` (scenes/*.toml), `exercises` (BEGIN EXERCISE markers in
  solutions/).
- The chapter table has a row for every chapter folder, and every docs link in the README exists.
- Every path the README names in backticks or in its layout block, under a top-level folder of the
  project, exists (names with NN, *, or a placeholder are patterns, not paths).
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
    for problem in problems:
        print(f"FAIL README.md: {problem}")
    if problems:
        return 1
    print("OK: README.md's counts, chapter table, links and paths match the tree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
