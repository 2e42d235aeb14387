#!/usr/bin/env python3
"""Writes a copy of a PLY mesh in which one face is selected, the way MeshLab
saves a selection: a per-face 'flags' property with vcglib's SELECTED bit
(0x20; MeshLab's PLY reader restores the flags). Lets a GUI test open a mesh
with the face already selected, as after selecting it by hand.

usage: gui_select_face.py IN.ply FACE_INDEX OUT.ply

Vertex and face properties (scalars) are copied; the output is ASCII with
every float printed exactly (repr), so it reads back as the same mesh.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plyread import read_ply  # noqa: E402

SELECTED = 0x20  # vcg::FaceBase SELECTED (vcg/simplex/face/base.h)
TYPES = {"x": "float", "y": "float", "z": "float", "nx": "float", "ny": "float", "nz": "float", "quality": "float",
         "red": "uchar", "green": "uchar", "blue": "uchar", "alpha": "uchar"}


def main():
    src, face, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    mesh = read_ply(src)
    verts, faces = mesh["vertex"], mesh["face"]
    if not 0 <= face < len(faces):
        sys.exit(f"face {face} is not in 0..{len(faces) - 1}")
    vprops = [p for p in verts[0] if p in TYPES]
    fprops = [p for p in faces[0] if p in TYPES]
    fmt = lambda p, x: str(int(x)) if TYPES[p] == "uchar" else repr(float(x))  # noqa: E731
    with open(out, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(verts)}\n" + "".join(f"property {TYPES[p]} {p}\n" for p in vprops))
        f.write(f"element face {len(faces)}\nproperty list uchar int vertex_indices\n")
        f.write("".join(f"property {TYPES[p]} {p}\n" for p in fprops) + "property int flags\nend_header\n")
        for v in verts:
            f.write(" ".join(fmt(p, v[p]) for p in vprops) + "\n")
        for i, t in enumerate(faces):
            idx = t["vertex_indices"]
            f.write(" ".join([str(len(idx))] + [str(k) for k in idx] + [fmt(p, t[p]) for p in fprops] +
                             [str(SELECTED if i == face else 0)]) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
