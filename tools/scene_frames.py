#!/usr/bin/env python3
"""One representative frame of every gallery scene for docs/scenes.md (docs/figures/scenes/).

Runs each scene of scenes/ as written (its full run, so that the frame's camera, colour range and
caption, slow motion included, are the video's), without its video and charts, and copies the PNG
frame of the moment listed in MOMENTS, when the motion shows, to docs/figures/scenes/<scene>.png
(a skinned scene's frame is its skin's, <scene>_skin_NNNN.png, with the lattice around it).
Two more pictures, named like scenes:
  web_page   the web page (fem_scene --html) of bunny_drop's full run at its moment, a screenshot of
             headless Chromium (tools/check_web_page.py's flags, network off), stamped with the
             figure code's version as the PNG frames are (tools/check_figures.py);
  live_pull  the live view while the mouse pulls the cantilever: the picture the test "the live
             view's mouse: …" (test_scenes, XTEST under Xvfb) saves at step 90 with the button held.
Needs a display: run it under xvfb-run -a, e.g.

    xvfb-run -a -s "-screen 0 1280x1024x24" tools/scene_frames.py --bin build/release/bin [name ...]
"""

import argparse
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import tomllib
import zlib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from check_web_page import CHROMIUM_FLAGS  # noqa: E402

# The time [s] of each scene's representative frame: when its motion is plain to see.
MOMENTS = {
    "cantilever": 0.5,       # swinging down, well past its sag
    "twisted_bar": 0.75,     # its end turned by 90°
    "bunny": 0.3,            # released, swinging back
    "hanging_cube": 0.5,     # fallen and stretched from its two corners
    "stiff_soft_pair": 0.5,  # the soft beam far below the stiff one
    "skinned_bunny": 0.3,    # as the bunny, its skin on the lattice
    "bunny_drop": 0.16,      # on the floor, squashed
    "slope_slide": 0.5,      # 0.3 m down the slope
    "slope_stick": 0.5,      # where it landed
    "beam_on_sphere": 0.4,   # folded over the ball
    "bowl_drop": 0.3,        # landed on the bowl's wall, sliding down
    "two_bunnies": 0.1,      # squashed against each other
    "block_stack": 0.6,      # stacked
    "bar_coil": 3.0,         # looped onto itself
}


WEB_PAGE_SCENE = "bunny_drop"   # the web page's picture: this scene's page at its moment
PULLED_STEP = 90                 # the step of the test's picture with the button held (test_live_view.cpp)


def stamp_version(png, root):
    """Adds the figure code's version (common/figures.cpp) to a PNG as its tEXt chunk after IHDR,
    as common/figures.cpp's write_png does, for tools/check_figures.py."""
    version = re.search(r"const int figure_code_version\s*=\s*(\d+)\s*;", (root / "common" / "figures.cpp").read_text())[1]
    body = b"fem-figure-version\0" + version.encode()
    chunk = struct.pack(">I", len(body)) + b"tEXt" + body + struct.pack(">I", zlib.crc32(b"tEXt" + body))
    data = png.read_bytes()
    end_of_header = 8 + 12 + struct.unpack(">I", data[8:12])[0]
    png.write_bytes(data[:end_of_header] + chunk + data[end_of_header:])


def web_page_picture(args, target):
    """docs/figures/scenes/web_page.png: WEB_PAGE_SCENE's page at its moment in headless Chromium."""
    scene = args.root / "scenes" / f"{WEB_PAGE_SCENE}.toml"
    with open(scene, "rb") as file:
        frame_rate = tomllib.load(file).get("output", {}).get("frame_rate", 30.0)
    index = round(MOMENTS[WEB_PAGE_SCENE] * frame_rate)
    with tempfile.TemporaryDirectory() as out:
        command = [str(args.bin / "fem_scene"), str(scene), "--no-progress", "--no-figures", "--html", "--out", out]
        print(" ".join(command), flush=True)
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        shot = Path(out) / "web_page.png"
        page = Path(out) / f"{WEB_PAGE_SCENE}.html"
        subprocess.run([shutil.which("chromium") or "chromium", *CHROMIUM_FLAGS, f"--user-data-dir={Path(out) / 'profile'}",
                        f"--screenshot={shot}", "--window-size=1200,700", "--virtual-time-budget=5000",
                        f"{page.as_uri()}#frame={index}"], capture_output=True, timeout=300)
        if not shot.exists():
            sys.exit("error: web_page: chromium wrote no screenshot (is Debian's chromium installed?)")
        stamp_version(shot, args.root)
        shutil.copyfile(shot, target / "web_page.png")
    print(f"web_page: {WEB_PAGE_SCENE}.html#frame={index} -> docs/figures/scenes/web_page.png")


def pull_picture(args, target):
    """docs/figures/scenes/live_pull.png: the live view's mouse test's picture with the button held."""
    command = [str(args.bin / "test_scenes"), "the live view's mouse*"]
    print(" ".join(command), flush=True)
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    picture = args.bin.parent / "test_output" / "scenes" / "pull" / f"view_{PULLED_STEP}.png"
    if not picture.exists():
        sys.exit(f"error: live_pull: the test wrote no {picture} (is there a display? run under xvfb-run -a)")
    shutil.copyfile(picture, target / "live_pull.png")
    print(f"live_pull: {picture} -> docs/figures/scenes/live_pull.png")


EXTRA_PICTURES = {"web_page": web_page_picture, "live_pull": pull_picture}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--bin", type=Path, required=True, help="the build's bin folder (holds fem_scene)")
    parser.add_argument("scenes", nargs="*",
                        help="scene names, web_page, live_pull (default: every scene in scenes/, then the two)")
    args = parser.parse_args()
    names = args.scenes or sorted(p.stem for p in (args.root / "scenes").glob("*.toml")) + list(EXTRA_PICTURES)
    missing = [name for name in names if name not in MOMENTS and name not in EXTRA_PICTURES]
    if missing:
        sys.exit(f"error: no moment for scene(s) {', '.join(missing)}: add them to MOMENTS in {__file__}")
    target = args.root / "docs" / "figures" / "scenes"
    target.mkdir(parents=True, exist_ok=True)
    for name in names:
        if name in EXTRA_PICTURES:
            EXTRA_PICTURES[name](args, target)
            continue
        scene = args.root / "scenes" / f"{name}.toml"
        with open(scene, "rb") as file:
            spec = tomllib.load(file)
        frame_rate = spec.get("output", {}).get("frame_rate", 30.0)
        index = round(MOMENTS[name] * frame_rate)
        stem = f"{name}_skin" if "skin" in spec else name
        with tempfile.TemporaryDirectory() as out:
            command = [str(args.bin / "fem_scene"), str(scene), "--no-progress", "--set", "output.video=\"none\"",
                       "--set", "output.charts=false", "--out", out]
            print(" ".join(command), flush=True)
            subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
            frame = Path(out) / f"{stem}_{index:04d}.png"
            if not frame.exists():
                sys.exit(f"error: {name}: no frame {frame.name} (is there a display? run under xvfb-run -a)")
            shutil.copyfile(frame, target / f"{name}.png")
            print(f"{name}: t = {MOMENTS[name]} s -> docs/figures/scenes/{name}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
