#!/usr/bin/env python3
"""One representative frame of every gallery scene for docs/scenes.md (docs/figures/scenes/).

Runs each scene of scenes/ as written (its full run, so that the frame's camera, colour range and
caption, slow motion included, are the video's), without its video and charts, and copies the PNG
frame of the moment listed in MOMENTS, when the motion shows, to docs/figures/scenes/<scene>.png
(a skinned scene's frame is its skin's, <scene>_skin_NNNN.png, with the lattice around it).
Needs a display: run it under xvfb-run -a, e.g.

    xvfb-run -a -s "-screen 0 1280x1024x24" tools/scene_frames.py --bin build/release/bin [scene ...]
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--bin", type=Path, required=True, help="the build's bin folder (holds fem_scene)")
    parser.add_argument("scenes", nargs="*", help="scene names (default: every scene in scenes/)")
    args = parser.parse_args()
    names = args.scenes or sorted(p.stem for p in (args.root / "scenes").glob("*.toml"))
    missing = [name for name in names if name not in MOMENTS]
    if missing:
        sys.exit(f"error: no moment for scene(s) {', '.join(missing)}: add them to MOMENTS in {__file__}")
    target = args.root / "docs" / "figures" / "scenes"
    target.mkdir(parents=True, exist_ok=True)
    for name in names:
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
