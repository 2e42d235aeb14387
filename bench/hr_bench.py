#!/usr/bin/env python3
"""Hierarchical against flat radiosity on a generated, subdivided Cornell-like
room (README, "Hierarchical radiosity"): time and peak memory against the
triangle count, the log-log slope, and the relative RMS difference of the
two solutions' vertex values (patch averages) where both run.

The room: floor, ceiling, back and side walls of a 1 x 1 x 1 box (open at the
front, like the Cornell box; red left wall, green right wall, white rest),
two boxes standing on the floor, and a square light of 0.2 x 0.2 below the
ceiling (at most 200 triangles, one planar luminaire for the direct light
at every size) marked by face quality 1. Every quad of a k x k grid is two
triangles; k grows to reach the requested triangle counts. Generated here,
never shipped.

Each run is `gi radiosity ROOM.ply --solver ... --vertex_output 'Patch
average' --json` in a child process; its peak resident memory comes from
wait4. The flat solver runs only up to --flat_max triangles (quadratic).

With --reference_vertices N, `gi reference` traces N vertices drawn at random
(--traced_vertices N, --traced_vertex_seed; the others stay 0 and its
ReferenceTraced attribute is 0 there) and the hierarchical solution's
relative RMS error and mean error is measured at those vertices only; the
radiosity runs then use --vertex_output (default 'Final gather', the values
the reference is comparable with; 'Patch average' otherwise).

usage: python3 bench/hr_bench.py [--gi build/tools/gi] [--sizes 10000,40000,160000] [--flat_max 40000]
                                 [--out hr_bench.json] [--reference_vertices N [--reference_paths 1024]
                                 [--reference_seed 0] [--vertex_output 'Final gather']]
                                 [--radiosity_args "--gather_rays 256 --gather_share_rings 2"]
"""
import argparse
import json
import math
import os
import shlex
import struct
import subprocess
import sys
import tempfile
import time


def quad_grid(p0, u, v, k, color, emit, verts, faces):
    """k x k quads spanning p0 + [0,1] u + [0,1] v, counter-clockwise seen from u x v."""
    base = len(verts)
    for j in range(k + 1):
        for i in range(k + 1):
            verts.append(tuple(p0[c] + u[c] * i / k + v[c] * j / k for c in range(3)))
    w = k + 1
    for j in range(k):
        for i in range(k):
            a = base + j * w + i
            faces.append(((a, a + 1, a + w + 1), color, emit))
            faces.append(((a, a + w + 1, a + w), color, emit))


def box(lo, hi, k, color, verts, faces):
    """The five visible sides of an axis-aligned box standing on the floor, facing out."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    quad_grid((x0, y1, z0), (0, 0, dz), (dx, 0, 0), k, color, 0, verts, faces)  # top (+y)
    quad_grid((x0, y0, z0), (dx, 0, 0), (0, dy, 0), k, color, 0, verts, faces)  # -z
    quad_grid((x1, y0, z1), (-dx, 0, 0), (0, dy, 0), k, color, 0, verts, faces)  # +z
    quad_grid((x0, y0, z1), (0, 0, -dz), (0, dy, 0), k, color, 0, verts, faces)  # -x
    quad_grid((x1, y0, z0), (0, 0, dz), (0, dy, 0), k, color, 0, verts, faces)  # +x


def room(path, k):
    """Writes the room with k x k quads per wall; returns the triangle count."""
    verts, faces = [], []
    white, red, green = (186, 185, 180), (166, 34, 30), (40, 120, 36)
    quad_grid((0, 0, 0), (0, 0, 1), (1, 0, 0), k, white, 0, verts, faces)      # floor, facing +y
    quad_grid((0, 1, 0), (1, 0, 0), (0, 0, 1), k, white, 0, verts, faces)      # ceiling, facing -y
    quad_grid((0, 0, 1), (0, 1, 0), (1, 0, 0), k, white, 0, verts, faces)      # back wall z = 1, facing -z
    quad_grid((0, 0, 0), (0, 1, 0), (0, 0, 1), k, red, 0, verts, faces)        # left wall x = 0, facing +x
    quad_grid((1, 0, 0), (0, 0, 1), (0, 1, 0), k, green, 0, verts, faces)      # right wall x = 1, facing -x
    kb = max(1, k // 4)
    box((0.2, 0.0, 0.5), (0.45, 0.5, 0.75), kb, white, verts, faces)
    box((0.55, 0.0, 0.25), (0.8, 0.25, 0.5), kb, white, verts, faces)
    kl = max(1, min(k // 5, 10))  # at most 200 emitter triangles, one luminaire
    quad_grid((0.4, 0.999, 0.4), (0.2, 0, 0), (0, 0, 0.2), kl, (255, 255, 255), 1, verts, faces)  # light, facing -y
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nproperty uchar red\n"
                 "property uchar green\nproperty uchar blue\nproperty float quality\nend_header\n"
                 % (len(verts), len(faces))).encode())
        f.write(b"".join(struct.pack("<3f", *v) for v in verts))
        f.write(b"".join(struct.pack("<B3i3Bf", 3, *t, *c, float(e)) for t, c, e in faces))
    return len(faces)


def k_for(triangles):
    """Grid resolution whose room has about this many triangles (5 walls + 2 boxes x 5 sides + light)."""
    # 2 k^2 (5 + 10 / 16) triangles and the light
    return max(2, int(round(math.sqrt(triangles / (2 * (5 + 10 / 16))))))


def run(gi, mesh, out, solver, extra, vertex_output="Patch average", usage=None):
    """The run's JSON, wall seconds and peak resident MB; its CPU seconds (user + system) are appended to
    `usage` if given."""
    cmd = [gi, "radiosity", mesh, "-o", out, "--solver", solver, "--vertex_output", vertex_output,
           "--json"] + extra
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    stdout = p.stdout.read()
    stderr = p.stderr.read()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise RuntimeError("%s failed: %s" % (" ".join(cmd), stderr.decode()[-500:]))
    if usage is not None:
        usage.append(ru.ru_utime + ru.ru_stime)
    return json.loads(stdout), wall, ru.ru_maxrss / 1024.0


def vertex_values(path):
    """Vertex radiosity luminance (vertex quality; patch averages here) from the output PLY."""
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.readline()
        lines = header.decode().splitlines()
        nv = nf = 0
        vprops, fprops, cur = [], [], None
        for ln in lines:
            t = ln.split()
            if t[:2] == ["element", "vertex"]: nv, cur = int(t[2]), vprops
            elif t[:2] == ["element", "face"]: nf, cur = int(t[2]), fprops
            elif t[0] == "property" and cur is not None: cur.append(t[1:])
        sizes = {"float": 4, "uchar": 1, "int": 4, "double": 8, "uint": 4}
        fmt = {"float": "f", "uchar": "B", "int": "i", "double": "d", "uint": "I"}
        out = []
        for _ in range(nv):
            vals = {}
            for p in vprops:
                (vals[p[1]],) = struct.unpack("<" + fmt[p[0]], f.read(sizes[p[0]]))
            out.append(vals.get("quality", 0.0))
        return out


def reference_at_sample(gi, mesh, tmp, count, paths, seed, extra=()):
    """`gi reference` on `count` random vertices: (traced vertex indices, their B luminance, standard errors, seconds)."""
    saved = os.path.join(tmp, "ref.json")
    cmd = [gi, "reference", mesh, "--traced_vertices", str(count), "--traced_vertex_seed", str(seed),
           "--samples_per_vertex", str(paths), "--save-result", saved, "--json"] + list(extra)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError("%s failed: %s" % (" ".join(cmd), p.stderr[-500:]))
    wall = time.perf_counter() - t0
    with open(saved) as f:
        r = json.load(f)
    traced = r["attributes"]["ReferenceTraced"]["values"]
    err = r["attributes"]["StdError"]["values"]
    idx = [i for i, x in enumerate(traced) if x > 0.5]
    return idx, [r["vertex_quality"][i] for i in idx], [err[i] for i in idx], wall


def error_at(values, idx, ref, ref_err):
    """At the reference's vertices (B > 0): the RMS and the mean of the relative differences (x - r) / r of
    `values`, and the RMS of the reference's own relative standard errors there (the floor below which a
    difference cannot be resolved). Relative per vertex, so that the light's bright vertices do not weigh
    more than the room's."""
    pts = [(values[i], r, e) for i, r, e in zip(idx, ref, ref_err) if r > 0]
    rel = [(x - r) / r for x, r, _ in pts]
    out = {"rms_relative_error": math.sqrt(sum(d * d for d in rel) / len(rel)),
           "mean_relative_error": sum(rel) / len(rel),
           "reference_rms_relative_std_error": math.sqrt(sum((e / r) ** 2 for _, r, e in pts) / len(pts)),
           "vertices": len(pts)}
    # Where the reference resolves the value (relative standard error below 5%), with its noise removed
    # in quadrature: the README's measure for the 100k room.
    res = [((x - r) / r, e / r) for x, r, e in pts if e / r < 0.05]
    if res:
        d2 = sum(d * d for d, _ in res) / len(res)
        n2 = sum(n * n for _, n in res) / len(res)
        out.update({"resolved_vertices": len(res), "rms_relative_error_resolved": math.sqrt(d2),
                    "reference_noise_resolved": math.sqrt(n2),
                    "rms_relative_error_noise_removed": math.sqrt(max(0.0, d2 - n2))})
    return out


def slope(xs, ys):
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", default="build/tools/gi")
    ap.add_argument("--sizes", default="10000,40000,160000")
    ap.add_argument("--flat_max", type=int, default=40000)
    ap.add_argument("--out", default="hr_bench.json")
    ap.add_argument("--reference_vertices", type=int, default=0,
                    help="measure the error against `gi reference` at this many random vertices (0: not)")
    ap.add_argument("--reference_paths", type=int, default=1024)
    ap.add_argument("--reference_seed", type=int, default=0)
    ap.add_argument("--radiosity_args", default="",
                    help="further options for every `gi radiosity` run, e.g. \"--gather_rays 256 "
                         "--gather_share_rings 2\"")
    ap.add_argument("--vertex_output", default=None,
                    help="the radiosity runs' vertex values (default: 'Final gather' with a reference, else "
                         "'Patch average')")
    a = ap.parse_args()
    vertex_output = a.vertex_output or ("Final gather" if a.reference_vertices > 0 else "Patch average")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for target in [int(x) for x in a.sizes.split(",")]:
            mesh = os.path.join(tmp, "room.ply")
            n = room(mesh, k_for(target))
            row = {"triangles": n}
            solvers = ["Hierarchical"] + (["Gauss-Seidel"] if n <= a.flat_max else [])
            vals = {}
            for solver in solvers:
                out = os.path.join(tmp, "out.ply")
                j, wall, rss = run(a.gi, mesh, out, solver, shlex.split(a.radiosity_args), vertex_output)
                st = j.get("stats", j)
                key = "hierarchical" if solver == "Hierarchical" else "flat"
                row[key] = {"seconds": wall, "peak_MB": rss, "stats": st}
                vals[key] = vertex_values(out)
                print("%8d triangles %-12s %7.2f s %7.0f MB" % (n, key, wall, rss), file=sys.stderr, flush=True)
            if a.reference_vertices > 0:
                idx, ref, ref_err, ref_wall = reference_at_sample(a.gi, mesh, tmp, a.reference_vertices,
                                                                  a.reference_paths, a.reference_seed)
                row["reference"] = {"seconds": ref_wall, "vertices": len(idx), "paths": a.reference_paths}
                for key in vals:
                    row[key]["error_at_reference"] = error_at(vals[key], idx, ref, ref_err)
                    print("%8d triangles %-12s error %.4f at %d reference vertices (reference noise %.4f)"
                          % (n, key, row[key]["error_at_reference"]["rms_relative_error"], len(idx),
                             row[key]["error_at_reference"]["reference_rms_relative_std_error"]),
                          file=sys.stderr, flush=True)
            if "flat" in vals:
                h, fl = vals["hierarchical"], vals["flat"]
                num = sum((x - y) ** 2 for x, y in zip(h, fl) if y > 0)
                den = sum(y * y for y in fl if y > 0)
                row["rms_relative_difference"] = math.sqrt(num / den)
            results.append(row)
    hs = [r for r in results if "hierarchical" in r]
    summary = {"runs": results}
    if len(hs) >= 2:
        xs = [r["triangles"] for r in hs]
        summary["hierarchical_time_slope"] = slope(xs, [r["hierarchical"]["seconds"] for r in hs])
        summary["hierarchical_memory_slope"] = slope(xs, [r["hierarchical"]["peak_MB"] for r in hs])
    fl = [r for r in results if "flat" in r]
    if len(fl) >= 2:
        xs = [r["triangles"] for r in fl]
        summary["flat_time_slope"] = slope(xs, [r["flat"]["seconds"] for r in fl])
    with open(a.out, "w") as f:
        json.dump(summary, f, indent=1)
    print(json.dumps({k: v for k, v in summary.items() if k != "runs"}, indent=1))


if __name__ == "__main__":
    main()
