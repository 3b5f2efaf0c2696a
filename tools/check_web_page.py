#!/usr/bin/env python3
"""The browser test of fem_scene's web page (docs/scenes.md#the-web-page, ctest scenes_web_page_browser).

Runs a scene with --html, opens the page in headless Chromium with the network off at its first and
last frame (#frame=N: the page opens there, paused), takes a screenshot of each, and checks in the
3D view's part of each picture (the left 68 %, between the caption and the controls) that the body
is drawn in the colour map's colours (pixels that are not grey) and that it moved between the two
frames (the two sets of body pixels differ).

Headless WebGL here: --use-angle=swiftshader --enable-unsafe-swiftshader (ANGLE on SwiftShader,
the CPU renderer Chromium ships); --use-gl=swiftshader gives a page without WebGL in Chromium 156.

Then the positions, read back through the page's own decoding: the page opened at
#positions=0,1,… writes what its test hook window.femPlayer.positions(k) returns (frame k's surface
vertices decoded into float32 by the function the 3D view draws with) into <pre id="fem-positions">,
which chromium --dump-dom prints; every coordinate must be the .vtu frame k's X + warp·u of its
point within the stated bound, half a quantisation step (high − low)/65535/2 on its axis (the page's
low and high), plus float32's rounding of the drawn value (2⁻²⁴ of the axis's largest |x|). The
comparison is checked to catch a decoding off by one step: the page's positions moved by one step
on one axis, and decoded over 65536 steps instead of 65535, must both fail it.

Exit 0: passed; 1: failed; 77 (ctest SKIP): no chromium, or no libjs-three for fem_scene --html.
"""
import argparse
import base64
import html
import json
import re
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


def vtu_arrays(path):
    """{name: list of numbers} of a .vtu written by VTK's XML writer (common/vtk_io): every
    DataArray in format="binary", zlib-compressed (header UInt32: blocks, block size, last block's
    size, each block's compressed size; base64 apart from the data) or uncompressed, or "ascii"."""
    text = pathlib.Path(path).read_text()
    head = re.search(r"<VTKFile[^>]*>", text).group(0)
    compressed = "vtkZLibDataCompressor" in head
    if 'header_type="UInt64"' in head:
        word, word_format = 8, "<Q"
    else:
        word, word_format = 4, "<I"
    kinds = {"Float64": "d", "Float32": "f", "Int64": "q", "Int32": "i", "UInt8": "B", "UInt32": "I", "UInt64": "Q"}
    arrays = {}
    for m in re.finditer(r"<DataArray(?P<attrs>[^>]*)>(?P<body>[^<]*)", text):  # the data, before any <InformationKey>
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', m["attrs"]))
        kind, body = kinds[attrs["type"]], m["body"].strip()
        if attrs.get("format") == "ascii":
            arrays[attrs["Name"]] = [float(v) for v in body.split()]
            continue
        if compressed:
            count = struct.unpack(word_format, base64.b64decode(body[:8 if word == 4 else 12])[:word])[0]
            header_chars = 4 * -(-(3 + count) * word // 3)
            header = base64.b64decode(body[:header_chars])
            sizes = [struct.unpack(word_format, header[i * word:(i + 1) * word])[0] for i in range(3 + count)][3:]
            data, raw, at = base64.b64decode(body[header_chars:]), b"", 0
            for size in sizes:
                raw += zlib.decompress(data[at:at + size])
                at += size
        else:
            blob = base64.b64decode(body)
            raw = blob[word:word + struct.unpack(word_format, blob[:word])[0]]
        arrays[attrs["Name"]] = list(struct.unpack(f"<{len(raw) // struct.calcsize(kind)}{kind}", raw))
    return arrays


def drawn_positions(vtu, warp):
    """X + warp·u of every point of a .vtu frame: a list of (x, y, z)."""
    arrays = vtu_arrays(vtu)
    rest, u = arrays["Points"], arrays["displacement"]
    return [tuple(rest[3 * p + a] + warp * u[3 * p + a] for a in range(3)) for p in range(len(rest) // 3)]


def worst_errors(page_frames, point_ids, vtu_frames, bound):
    """(largest |page − vtu| / bound over every frame, vertex and axis, where): page_frames[k] the
    3P page coordinates of frame k, vtu_frames[k] the .vtu frame's drawn positions, bound per axis."""
    worst, where = 0.0, None
    for k, coordinates in page_frames.items():
        for i, point in enumerate(point_ids):
            for a in range(3):
                ratio = abs(coordinates[3 * i + a] - vtu_frames[k][point][a]) / bound[a]
                if ratio > worst:
                    worst, where = ratio, f"frame {k}, surface vertex {i} (.vtu point {point}), axis {'xyz'[a]}"
    return worst, where


def check_positions(chromium, page, data, out, stated):
    """The failures of the positions' read-back (module doc): the page's decoded positions of every
    frame against the .vtu frames of its run. stated: the bound fem_scene printed [m]."""
    pvd = next(page.parent.glob("*.pvd")).read_text()
    vtus = [page.parent / f for f in re.findall(r'file="([^"]+)"', pvd)]
    if len(vtus) != data["frames"]:
        return [f"the page has {data['frames']} frames, the .pvd {len(vtus)}"]
    frames = ",".join(str(k) for k in range(data["frames"]))
    command = [chromium, *CHROMIUM_FLAGS, f"--user-data-dir={out / 'profile'}", "--dump-dom",
               "--virtual-time-budget=5000", f"{page.as_uri()}#positions={frames}"]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=180).stdout
    found = re.search(r'<pre id="fem-positions"[^>]*>(.*?)</pre>', dom, re.S)
    if not found:
        return [f"the page wrote no <pre id=\"fem-positions\"> (its test hook): {' '.join(command)}"]
    read = json.loads(html.unescape(found.group(1)))
    page_frames = {int(k): v for k, v in read["frames"].items()}
    if sorted(page_frames) != list(range(data["frames"])):
        return [f"the page's hook gave frames {sorted(page_frames)}, not 0 … {data['frames'] - 1}"]
    vtu_frames = [drawn_positions(v, data["warp"]) for v in vtus]
    low, high = data["low"], data["high"]
    half_step = [(high[a] - low[a]) / 65535 / 2 for a in range(3)]
    largest = [max(abs(low[a]), abs(high[a])) for a in range(3)]
    bound = [half_step[a] + 2.0 ** -24 * largest[a] + 1e-12 for a in range(3)]
    worst, where = worst_errors(page_frames, read["point_ids"], vtu_frames, bound)
    print(f"positions of {len(read['point_ids'])} surface vertices × {len(page_frames)} frames, read back from the "
          f"page: largest error {worst:.3f} of the bound (half a step + float32: {', '.join(f'{b:.4g}' for b in bound)} m; "
          f"at {where})")
    failures = []
    if max(half_step) > stated * (1 + 1e-4):
        failures.append(f"the page's half step {max(half_step):.6g} m is more than the bound fem_scene states, {stated:.6g} m")
    if worst > 1.0:
        failures.append(f"a decoded position is off by {worst:.3f} of the bound at {where}")
    # The comparison must catch a decoding off by one step: a coordinate one step over, and the
    # codes read over 65536 steps instead of 65535 (the top of each axis one step short).
    axis = max(range(3), key=lambda a: half_step[a])  # the longest axis: a step there is largest
    one_over = {k: [c + (2 * half_step[axis] if i % 3 == axis else 0.0) for i, c in enumerate(v)]
                for k, v in page_frames.items()}
    short = {k: [low[i % 3] + (c - low[i % 3]) * 65535 / 65536 for i, c in enumerate(v)] for k, v in page_frames.items()}
    for name, wrong in ((f"one step over on {'xyz'[axis]}", one_over), ("over 65536 steps", short)):
        ratio, _ = worst_errors(wrong, read["point_ids"], vtu_frames, bound)
        print(f"a decoding {name}: largest error {ratio:.3f} of the bound")
        if ratio <= 1.0:
            failures.append(f"the comparison passes a decoding {name}: it cannot tell a step")
    return failures


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
    data = json.loads(text[start:text.index("</script>", start)])
    frames = data["frames"]
    stated = re.search(r"positions to within (\S+) m", run.stdout)
    if not stated:
        print(f"fem_scene stated no bound ('positions to within … m'):\n{run.stdout}")
        return 1
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
    failures = check_positions(chromium, page, data, out, float(stated.group(1)))
    if min(len(first), len(last)) < 2000:
        failures.append("the body is not drawn in colour in both frames (fewer than 2000 pixels): no WebGL?")
    if moved < 0.05 * max(len(first), len(last), 1):
        failures.append("the body looks the same in the first and last frame: the frames were not applied")
    for failure in failures:
        print("FAILED: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
