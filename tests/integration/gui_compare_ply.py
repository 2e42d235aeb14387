#!/usr/bin/env python3
"""Compares the mesh MeshLab's GUI exported after a filter with what the
command-line tool wrote for the same filter, mesh and parameters.

usage: gui_compare_ply.py WRITTEN.ply EXPECTED.ply TOL

Both run gi::runFilter with the same seed on the same scene, so with TOL = 0
vertex quality and colour (and face quality and colour, where both files have
them) must be identical. TOL > 0 (a fraction) allows each quality q to differ by
TOL x max(|q|, mean |q|) and each colour channel by 1: for a dialog that rounds
a parameter to the digits it shows and hands the rounded value to the filter. The files must hold the same mesh (counts, positions to 1e-5 of
the bounding box). Exit 0 and one summary line, or 1 and one line saying what
differs.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plyread import read_ply  # noqa: E402


def main():
    written, expected, tol = read_ply(sys.argv[1]), read_ply(sys.argv[2]), float(sys.argv[3])
    wv, ev = written["vertex"], expected["vertex"]
    wf, ef = written.get("face", []), expected.get("face", [])
    if len(wv) != len(ev) or len(wf) != len(ef):
        print(f"different meshes: {len(wv)} vertices and {len(wf)} faces written, {len(ev)} and {len(ef)} expected")
        return 1
    extent = max(max(abs(v[c]) for v in ev) for c in "xyz") or 1.0
    far = max(max(abs(a[c] - b[c]) for c in "xyz") for a, b in zip(wv, ev))
    if far > 1e-5 * extent:
        print(f"different meshes: a vertex lies {far:g} from its counterpart (extent {extent:g})")
        return 1
    report = []
    for what, w, e in (("vertex", wv, ev), ("face", wf, ef)):
        props = [p for p in ("quality", "red", "green", "blue") if e and p in w[0] and p in e[0]]
        if what == "vertex" and props != ["quality", "red", "green", "blue"]:
            print(f"vertex quality and colour missing: written has {sorted(wv[0])}, expected {sorted(ev[0])}")
            return 1
        if not props:
            continue
        mean_q = sum(abs(x["quality"]) for x in e) / len(e) if "quality" in props else 0.0
        dq = max((abs(a["quality"] - b["quality"]) for a, b in zip(w, e)), default=0.0) if "quality" in props else 0.0
        # the largest |dq| against what the tolerance allows at that element
        excess = max((abs(a["quality"] - b["quality"]) / max(abs(b["quality"]), mean_q, 1e-30)
                      for a, b in zip(w, e)), default=0.0) if "quality" in props else 0.0
        dc = max((abs(a[c] - b[c]) for a, b in zip(w, e) for c in ("red", "green", "blue")), default=0) \
            if "red" in props else 0
        if tol == 0 and (dq != 0 or dc != 0):
            i = next(k for k, (a, b) in enumerate(zip(w, e)) if any(a[p] != b[p] for p in props))
            print(f"{what} {i} differs: written {[w[i][p] for p in props]}, expected {[e[i][p] for p in props]} "
                  f"(max |dq| {dq:g}, max colour difference {dc})")
            return 1
        if tol > 0 and (excess > tol or dc > 1):
            print(f"{what} values differ beyond the tolerance: |dq| up to {excess:g} x max(|q|, mean |q| {mean_q:g}) "
                  f"> {tol:g}, or a colour by {dc} > 1")
            return 1
        report.append(f"{len(e)} {what} values: {'/'.join(props)} " +
                      ("identical" if dq == 0 and dc == 0 else
                       f"within tolerance {tol:g} (max |dq| {dq:g}, relative {excess:.2g}; colour {dc})"))
    print("; ".join(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
