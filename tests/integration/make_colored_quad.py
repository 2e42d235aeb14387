#!/usr/bin/env python3
"""Writes the input of the GUI screenshot test: an ASCII PLY of a flat quad grid
(z = 0, facing +z) with per-vertex colours, no normals.

    make_colored_quad.py OUT.ply [--grey] [--n N]

By default the left half (x < 0) is red-ish (230,40,40) and the right half
(x >= 0) green-ish (40,200,60); each half is its own set of vertices so the
colours do not blend across the seam.  --grey paints every vertex (128,128,128):
the negative control, a mesh on which gui_screenshot.sh's colour check must fail.
"""
import argparse
import sys

import numpy as np

RED = (230, 40, 40)
GREEN = (40, 200, 60)
GREY = (128, 128, 128)


def half_grid(x0, x1, n, colour):
    """Vertices (x, y, z, r, g, b) and triangles of an n x n cell grid over [x0,x1] x [-1,1]."""
    xs = np.linspace(x0, x1, n + 1)
    ys = np.linspace(-1.0, 1.0, n + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="xy")          # row j = y index, col i = x index
    verts = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
    cols = np.tile(np.asarray(colour, dtype=np.int64), (verts.shape[0], 1))
    j, i = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    v00 = (j * (n + 1) + i).ravel()
    v10 = v00 + 1
    v01 = v00 + (n + 1)
    v11 = v01 + 1
    # counter-clockwise seen from +z, so the front face points at the default camera
    tris = np.concatenate([np.stack([v00, v10, v11], 1), np.stack([v00, v11, v01], 1)])
    return verts, cols, tris


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--grey", action="store_true", help="uniform grey (negative control)")
    ap.add_argument("--n", type=int, default=16, help="cells per half along each axis")
    a = ap.parse_args(argv)
    left, right = (GREY, GREY) if a.grey else (RED, GREEN)
    vl, cl, tl = half_grid(-2.0, 0.0, a.n, left)
    vr, cr, tr = half_grid(0.0, 2.0, a.n, right)
    verts = np.concatenate([vl, vr])
    cols = np.concatenate([cl, cr])
    tris = np.concatenate([tl, tr + len(vl)])
    with open(a.out, "w", encoding="ascii") as f:
        f.write("ply\nformat ascii 1.0\ncomment gi gui_screenshot test quad\n")
        f.write(f"element vertex {len(verts)}\n")
        f.write("property float x\nproperty float y\nproperty float z\n")
        f.write("property uchar red\nproperty uchar green\nproperty uchar blue\n")
        f.write(f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n")
        for (x, y, z), (r, g, b) in zip(verts, cols):
            f.write(f"{x:.6g} {y:.6g} {z:.6g} {r} {g} {b}\n")
        for t in tris:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
