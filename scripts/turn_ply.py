#!/usr/bin/env python3
"""Turns a PLY 180 degrees about the y axis (x -> -x, z -> -z), keeping every
other property: used to face the Cornell box's opening to MeshLab's camera.
An optional third argument tilts it that many degrees about the x axis
afterwards (towards the camera: the floor shows more)."""
import math
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "integration"))
from plyread import read_ply  # noqa: E402

src, dst = sys.argv[1], sys.argv[2]
tilt = math.radians(float(sys.argv[3])) if len(sys.argv) > 3 else 0.0
ct, st = math.cos(tilt), math.sin(tilt)
ply = read_ply(src)
v, f = ply["vertex"], ply.get("face", [])
vkeys = [k for k in v[0].keys()]
with open(dst, "wb") as out:
    head = ["ply", "format binary_little_endian 1.0", "element vertex %d" % len(v)]
    types = {"red": "uchar", "green": "uchar", "blue": "uchar", "alpha": "uchar"}
    for k in vkeys:
        head.append("property %s %s" % (types.get(k, "float"), k))
    head += ["element face %d" % len(f), "property list uchar int vertex_indices", "end_header"]
    out.write(("\n".join(head) + "\n").encode())
    for r in v:
        r = dict(r)
        r["x"], r["z"] = -r["x"], -r["z"]
        r["y"], r["z"] = ct * r["y"] - st * r["z"], st * r["y"] + ct * r["z"]
        if "nx" in r:
            r["nx"], r["nz"] = -r["nx"], -r["nz"]
            r["ny"], r["nz"] = ct * r["ny"] - st * r["nz"], st * r["ny"] + ct * r["nz"]
        for k in vkeys:
            out.write(struct.pack("<B" if types.get(k) == "uchar" else "<f", r[k]))
    for r in f:
        idx = r["vertex_indices"]
        out.write(struct.pack("<B%di" % len(idx), len(idx), *idx))
