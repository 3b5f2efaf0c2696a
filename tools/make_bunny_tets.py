#!/usr/bin/env python3
"""Tetrahedralises data/bunny.obj with TetGen (Debian's `tetgen` program) into the coarse tet mesh
data/bunny_coarse.node + data/bunny_coarse.ele that chapter 10 simulates (see data/README.md).

  tools/make_bunny_tets.py [--tetgen tetgen] [--switches pq1.8YQ]

-p tetrahedralises the closed surface, -q1.8 bounds the radius-edge ratio of every tet by 1.8
(adding interior Steiner points only), -Y keeps the surface triangles exactly as they are (so the
bunny's surface is the .obj's own), -Q is quiet. The .obj is passed as an OFF file (TetGen does
not read .obj) with every coordinate written in full precision. Units are the .obj's.
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def read_obj(path):
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        fields = line.split()
        if fields and fields[0] == "v":
            vertices.append(fields[1:4])
        elif fields and fields[0] == "f":
            faces.append([int(token.split("/")[0]) - 1 for token in fields[1:]])
    return vertices, faces


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tetgen", default="tetgen")
    parser.add_argument("--switches", default="pq1.8YQ")
    args = parser.parse_args()
    vertices, faces = read_obj(ROOT / "data" / "bunny.obj")
    with tempfile.TemporaryDirectory() as work:
        off = Path(work) / "bunny.off"
        with off.open("w") as file:
            file.write(f"OFF\n{len(vertices)} {len(faces)} 0\n")
            file.writelines(" ".join(v) + "\n" for v in vertices)
            file.writelines(f"{len(f)} " + " ".join(map(str, f)) + "\n" for f in faces)
        subprocess.run([args.tetgen, "-" + args.switches, str(off)], check=True)
        for extension in ("node", "ele"):
            shutil.copy(Path(work) / f"bunny.1.{extension}", ROOT / "data" / f"bunny_coarse.{extension}")
    for extension in ("node", "ele"):
        count = (ROOT / "data" / f"bunny_coarse.{extension}").read_text().split()[0]
        print(f"data/bunny_coarse.{extension}: {count} {'vertices' if extension == 'node' else 'tetrahedra'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
