#!/usr/bin/env python3
"""Merges PLY files with per-vertex x y z (+ colour, quality) into one, for
pictures: merge_ply.py OUT IN[=r,g,b] ...; '=r,g,b' paints that file's
vertices one colour (e.g. mirrors and glass, which carry no diffuse radiosity)."""
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "integration"))
from plyread import read_ply  # noqa: E402

out, parts = sys.argv[1], sys.argv[2:]
verts, faces = [], []
for spec in parts:
    path, _, paint = spec.partition("=")
    ply = read_ply(path)
    base = len(verts)
    colour = tuple(int(c) for c in paint.split(",")) if paint else None
    for r in ply["vertex"]:
        c = colour or (r.get("red", 200), r.get("green", 200), r.get("blue", 200))
        verts.append((r["x"], r["y"], r["z"]) + tuple(c) + (r.get("quality", 0.0),))
    faces += [[base + i for i in f["vertex_indices"]] for f in ply.get("face", [])]
with open(out, "wb") as f:
    head = ["ply", "format binary_little_endian 1.0", "element vertex %d" % len(verts), "property float x",
            "property float y", "property float z", "property uchar red", "property uchar green", "property uchar blue",
            "property float quality", "element face %d" % len(faces), "property list uchar int vertex_indices",
            "end_header"]
    f.write(("\n".join(head) + "\n").encode())
    for v in verts:
        f.write(struct.pack("<fffBBBf", *v))
    for t in faces:
        f.write(struct.pack("<B%di" % len(t), len(t), *t))
