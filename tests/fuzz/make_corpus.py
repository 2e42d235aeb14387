#!/usr/bin/env python3
"""Writes the fuzz seed corpus (tests/fuzz/corpus): one small valid file for
every path through the readers (PLY ASCII and both binaries with the
properties we read and the extras MeshLab writes, OFF and COFF with colours,
OBJ with normals, texture coordinates, negative indices and vertex colours,
binary and ASCII STL, concave polygons). Run it again after changing a reader's grammar."""
import os
import struct

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
os.makedirs(out, exist_ok=True)
quad = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]


def write(name, data):
    with open(os.path.join(out, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


write("ascii.ply", "ply\nformat ascii 1.0\ncomment seed\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nelement face 2\nproperty list uchar int vertex_indices\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float quality\nend_header\n" +
      "".join("%g %g %g 0 0 1 10 20 30\n" % v for v in quad) + "3 0 1 2 200 100 50 1\n3 0 2 3 1 2 3 0.5\n")


def binary_ply(endian):
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    h = ("ply\nformat %s 1.0\ncomment VCGLIB generated\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nproperty float quality\nproperty float red\nproperty float green\nproperty float blue\n"
         "element face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n"
         "property int flags\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty double quality\n"
         "element edge 0\nproperty int vertex1\nend_header\n" % fmt).encode()
    body = b"".join(struct.pack(endian + "3f4f", *v, 0.5, 1, 0.5, 0) for v in quad)
    body += struct.pack(endian + "B4iB8fi3Bd", 4, 0, 1, 2, 3, 8, 0, 0, 1, 0, 1, 1, 0, 1, 0, 9, 8, 7, 2.0)
    return h + body


write("binary_le.ply", binary_ply("<"))
write("binary_be.ply", binary_ply(">"))
write("quad.off", "OFF\n# seed\n4 1 0\n" + "".join("%g %g %g\n" % v for v in quad) + "4 0 1 2 3 221 219 215\n")
write("colour.off", "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2 0.5 1.0 0\n")
write("quad.obj", "# seed\no quad\n" + "".join("v %g %g %g\n" % v for v in quad) +
      "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\ng top\ns off\nf 1/1/1 2/2/1 3/3/1\nf -4//1 -2//1 -1//1\n")
write("colour.obj", "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n")
# Concave polygons (ear clipping): an L-shaped hexagon and a notched quad;
# an OBJ with materials in use (usemtl) and a polygon.
concave = [(0, 0, 0), (2, 0, 0), (2, 1, 0), (1, 1, 0), (1, 2, 0), (0, 2, 0)]
notch = [(2, 0, 0), (0.5, 0.5, 0), (0, 2, 0), (0, 0, 0)]
write("concave.ply", "ply\nformat ascii 1.0\nelement vertex 10\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n" +
      "".join("%g %g %g\n" % v for v in concave + notch) + "6 0 1 2 3 4 5 32\n4 6 7 8 9 0\n")
write("concave.off", "OFF\n6 1 0\n" + "".join("%g %g %g\n" % v for v in concave) + "6 0 1 2 3 4 5\n")
write("concave.obj", "".join("v %g %g %g\n" % v for v in concave) + "usemtl a\nf 1 2 3 4 5 6\nusemtl b\nf 1 2 3\n")
stl = b"STLB seed".ljust(80, b" ") + struct.pack("<I", 2)
for t in ((quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])):
    stl += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *p) for p in t) + b"\0\0"
write("binary.stl", stl)
write("ascii.stl", "solid seed\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n"
      "  endloop\n endfacet\nendsolid seed\n")
