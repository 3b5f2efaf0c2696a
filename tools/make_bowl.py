#!/usr/bin/env python3
"""Writes data/bowl.obj: the course's bowl, an open spherical cap (chapter 14's mesh obstacle).

The cap of the sphere of radius R = 0.15 m centred at (0, 0, R), from its lowest point (the origin)
up to the polar angle 70 degrees (the rim: radius R sin 70 = 0.141 m, height R (1 - cos 70) = 0.099 m):
one vertex at the bottom, then RINGS rings of SEGMENTS vertices at equal steps of the polar angle;
triangles wound so that their normals (right hand) point into the bowl (up at the bottom).
Usage: python3 tools/make_bowl.py [output]   (default data/bowl.obj, next to this script's parent)
"""
import math
import pathlib
import sys

R, TOP, RINGS, SEGMENTS = 0.15, math.radians(70.0), 12, 32


def bowl():
    vertices = [(0.0, 0.0, 0.0)]
    for ring in range(1, RINGS + 1):
        polar = TOP * ring / RINGS
        for k in range(SEGMENTS):
            azimuth = 2.0 * math.pi * k / SEGMENTS
            vertices.append((R * math.sin(polar) * math.cos(azimuth), R * math.sin(polar) * math.sin(azimuth),
                             R - R * math.cos(polar)))
    index = lambda ring, k: 1 + (ring - 1) * SEGMENTS + k % SEGMENTS  # 0-based; ring >= 1
    faces = [(0, index(1, k), index(1, k + 1)) for k in range(SEGMENTS)]
    for ring in range(1, RINGS):
        for k in range(SEGMENTS):
            a, b, c, d = index(ring, k), index(ring, k + 1), index(ring + 1, k), index(ring + 1, k + 1)
            faces += [(a, c, d), (a, d, b)]
    return vertices, faces


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent / "data" / "bowl.obj"
    vertices, faces = bowl()
    lines = [f"# The course's bowl: an open spherical cap, R = {R} m, up to 70 degrees from its bottom at the origin",
             f"# (tools/make_bowl.py; {len(vertices)} vertices, {len(faces)} triangles; metres, z up)"]
    lines += [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
