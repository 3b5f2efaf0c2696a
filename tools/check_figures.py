#!/usr/bin/env python3
"""Nothing stale under docs/figures (ctest figures_current).

Every PNG that common/figures.cpp writes carries the version of the drawing code as a PNG text
chunk (tEXt, key "fem-figure-version", value fem::fig::figure_code_version, defined in
common/figures.cpp). This check fails for every PNG under docs/figures whose chunk is missing or
older than the header's constant, and names the chapter to redraw (tools/check_docs.py --update).

Before it looks at the figures it checks itself on PNGs it builds in memory: one of the current
version passes, one a version older and one without the chunk fail, so a checker that passed
everything would fail here.
"""

import argparse
import re
import struct
import sys
import zlib
from pathlib import Path

KEY = "fem-figure-version"
SIGNATURE = b"\x89PNG\r\n\x1a\n"


def code_version(source):
    """figure_code_version's value in common/figures.cpp."""
    match = re.search(r"const int figure_code_version\s*=\s*(\d+)\s*;", source.read_text())
    if not match:
        raise SystemExit(f"error: {source} defines no figure_code_version")
    return int(match.group(1))


def png_version(data):
    """The figure version a PNG's text chunk holds, or None without one. ValueError for bytes that
    are not a PNG."""
    if not data.startswith(SIGNATURE):
        raise ValueError("not a PNG (no PNG signature)")
    at = len(SIGNATURE)
    while at + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"tEXt":
            key, _, value = body.partition(b"\0")
            if key.decode("latin-1") == KEY:
                text = value.decode("latin-1")
                return int(text) if text.isdigit() else None
        if kind == b"IEND":
            break
        at += 12 + length
    return None


def stale(data, current):
    """Why a PNG is stale, or None when it is current."""
    try:
        version = png_version(data)
    except ValueError as error:
        return str(error)
    if version is None:
        return f"no {KEY} text chunk (drawn before figures carried their version)"
    if version < current:
        return f"drawn by figure code version {version}, the code is at {current}"
    if version > current:
        return f"claims figure code version {version}, newer than the code's {current}"
    return None


def tiny_png(version):
    """A 1×1 white PNG, with a text chunk holding version unless it is None."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    header = chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0))
    text = chunk(b"tEXt", KEY.encode() + b"\0" + str(version).encode()) if version is not None else b""
    pixels = chunk(b"IDAT", zlib.compress(b"\0\xff\xff\xff"))
    return SIGNATURE + header + text + pixels + chunk(b"IEND", b"")


def self_test(current):
    """The checker's verdicts on PNGs of known versions; a list of what went wrong."""
    problems = []
    if stale(tiny_png(current), current) is not None:
        problems.append("a PNG of the current version was called stale")
    for label, version in (("an older version", current - 1), ("no version", None)):
        if stale(tiny_png(version), current) is None:
            problems.append(f"a PNG with {label} passed")
    if stale(b"GIF89a", current) is None:
        problems.append("bytes that are not a PNG passed")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent,
                        help="the project's folder (default: this script's parent's parent)")
    args = parser.parse_args()
    current = code_version(args.root / "common" / "figures.cpp")
    problems = self_test(current)
    if problems:
        for p in problems:
            print(f"check_figures self-test: {p}")
        return 1
    figures = sorted((args.root / "docs" / "figures").rglob("*.png"))
    failures = [(png, why) for png in figures if (why := stale(png.read_bytes(), current))]
    for png, why in failures:
        chapter = png.parent.name
        print(f"{png.relative_to(args.root)}: {why}; redraw it: xvfb-run -a python3 tools/check_docs.py "
              f"--chapter {chapter} --bin build/release/bin --out /tmp/docs --update")
    print(f"{len(figures) - len(failures)} of {len(figures)} figures drawn by figure code version {current}")
    return 1 if failures or not figures else 0


if __name__ == "__main__":
    sys.exit(main())
