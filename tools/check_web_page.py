#!/usr/bin/env python3
"""The browser test of fem_scene's web page (docs/scenes.md#the-web-page, ctest scenes_web_page_browser).

Runs a scene with --html, opens the page in headless Chromium with the network off at its first and
last frame (#frame=N: the page opens there, paused), takes a screenshot of each, and checks in the
3D view's part of each picture (the left 68 %, between the caption and the controls) that the body
is drawn in the colour map's colours (pixels that are not grey) and that it moved between the two
frames (the two sets of body pixels differ).

Headless WebGL here: --use-angle=swiftshader --enable-unsafe-swiftshader (ANGLE on SwiftShader,
the CPU renderer Chromium ships); --use-gl=swiftshader gives a page without WebGL in Chromium 156.

Exit 0: passed; 1: failed; 77 (ctest SKIP): no chromium, or no libjs-three for fem_scene --html.
"""
import argparse
import json
import pathlib
import shutil
import struct
import subprocess
import sys
import zlib

SKIP = 77
WIDTH, HEIGHT = 1200, 700          # the window; the page's view is the left 68 %, controls 52 px
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--proxy-server=127.0.0.1:9",
                  "--host-resolver-rules=MAP * ~NOTFOUND", "--hide-scrollbars"]


def read_png(path):
    """(width, height, rows): rows[y][x] = (r, g, b) of an 8-bit RGB or RGBA PNG (no interlace)."""
    data = pathlib.Path(path).read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour_type, _, _, interlace = header
    if depth != 8 or colour_type not in (2, 6) or interlace:
        raise ValueError(f"{path}: an 8-bit RGB(A) PNG without interlace expected")
    channels = 3 if colour_type == 2 else 4
    raw, stride = zlib.decompress(idat), width * channels
    rows, previous, at = [], bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up, corner = previous[i], previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + left) & 255
            elif kind == 2:
                line[i] = (line[i] + up) & 255
            elif kind == 3:
                line[i] = (line[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                line[i] = (line[i] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        previous = line
    return width, height, rows


def body_pixels(path):
    """The set of (x, y) in the 3D view drawn in a colour (max − min channel > 40): the body on
    the colour map, never the white background, the grey obstacles or the dark caption."""
    width, height, rows = read_png(path)
    found = set()
    for y in range(60, height - 56):
        for x in range(int(0.68 * width) - 4):
            r, g, b = rows[y][x]
            if max(r, g, b) - min(r, g, b) > 40:
                found.add((x, y))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--exe", required=True, help="fem_scene")
    parser.add_argument("--scene", required=True, help="a scene file; run with --quick")
    parser.add_argument("--out", required=True, help="a folder for the run and the screenshots")
    parser.add_argument("--chromium", default="chromium")
    args = parser.parse_args()
    chromium = shutil.which(args.chromium)
    if chromium is None:
        print(f"SKIPPED: no {args.chromium} (tools/setup.sh installs Debian's chromium)")
        return SKIP
    out = pathlib.Path(args.out).resolve()
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    run = subprocess.run([args.exe, args.scene, "--quick", "--html", "--no-figures", "--no-progress",
                          "--out", str(out / "run")], capture_output=True, text=True)
    if run.returncode != 0:
        if "libjs-three" in run.stdout + run.stderr:
            print("SKIPPED: " + (run.stdout + run.stderr).strip())
            return SKIP
        print(f"fem_scene failed ({run.returncode}):\n{run.stdout}{run.stderr}")
        return 1
    page = next((out / "run").glob("*.html"))
    text = page.read_text(encoding="utf-8")
    start = text.index('id="fem-data">') + len('id="fem-data">')
    frames = json.loads(text[start:text.index("</script>", start)])["frames"]
    shots = {}
    for frame in (0, frames - 1):
        shot = out / f"frame_{frame}.png"
        command = [chromium, *CHROMIUM_FLAGS, f"--user-data-dir={out / 'profile'}", f"--screenshot={shot}",
                   f"--window-size={WIDTH},{HEIGHT}", "--virtual-time-budget=5000", f"{page.as_uri()}#frame={frame}"]
        subprocess.run(command, capture_output=True, timeout=180)
        if not shot.exists():
            print(f"chromium wrote no screenshot: {' '.join(command)}")
            return 1
        shots[frame] = body_pixels(shot)
        print(f"frame {frame}: {len(shots[frame])} body pixels ({shot})")
    first, last = shots[0], shots[frames - 1]
    moved = len(first ^ last)
    print(f"pixels drawn in only one of the two frames: {moved}")
    failures = []
    if min(len(first), len(last)) < 2000:
        failures.append("the body is not drawn in colour in both frames (fewer than 2000 pixels): no WebGL?")
    if moved < 0.05 * max(len(first), len(last), 1):
        failures.append("the body looks the same in the first and last frame: the frames were not applied")
    for failure in failures:
        print("FAILED: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
