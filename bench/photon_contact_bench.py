#!/usr/bin/env python3
"""Photon mapping beside other surfaces: one or two builds of `gi` against the path tracer.

The k-nearest density estimate counts what a vertex does not see where another surface rises inside its
sphere (the Cornell box's lamp 0.1 mm below the ceiling, its blocks on a floor that goes on under them, the
objects and walls of a scan room); since 5 December 2026 such vertices take a final gather, whose near hits
are relit; later that day progressive photon mapping hands the same vertices over. This measures it:
`gi photonmap` (default settings; with `final_gather` on the box; `progressive` at its default 16 passes of
200,000 paths on both) against `gi reference` (cached under bench/results/refs), over

  - the Cornell box: all vertices (relative RMS), the ceiling vertices on the lamp's border, the blocks'
    sides at the floor and the floor within 30 mm of a block (sum of differences over sum of reference);
  - a 100k-triangle scan room (`gi-scenes scanroom`): 4,000 vertices drawn at random, 16,384 paths each;
    split into the vertices whose value changed between the two builds (handed over to the gather) and
    the rest (RMS and bias over the mean).

Each binary runs three times, alternated (medians of the wall time); results as JSON.

    python3 bench/photon_contact_bench.py --after build/tools/gi [--before OLD/tools/gi] \
        --out bench/results/photon_contact_bench.json
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from plyread import read_ply  # noqa: E402


def run(cmd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError("failed: %s\n%s" % (" ".join(cmd), p.stderr[-2000:]))
    return p.stdout, time.perf_counter() - t0


def reference(gi, mesh, cache, extra):
    out, _ = run([gi, "reference", mesh, "-q", "--json", "--cache", cache] + extra)
    path = [n for n in json.loads(out)["notes"] if "cached" in n][0].split(" ")[-1]
    with open(path) as f:
        at = json.load(f)["attributes"]
    B = np.array(at["Radiosity"]["values"]).reshape(-1, 3).mean(1)
    return B, np.array(at["StdError"]["values"]), np.array(at["Paths"]["values"])


def radiosity(ply):
    v = read_ply(ply)["vertex"]
    return np.array([[r["Radiosity_x"], r["Radiosity_y"], r["Radiosity_z"]] for r in v]).mean(1)


def box_groups(mesh):
    """Vertex groups of the shipped Cornell box (its coordinates): lamp border, blocks' feet, floor beside."""
    m = read_ply(mesh)
    P = np.array([[r["x"], r["y"], r["z"]] for r in m["vertex"]])
    up = np.zeros(len(P), int)
    feet = []

    def in_room(p):
        return 5 < p[0] < 545 and 5 < p[2] < 550

    for f in m["face"]:
        t = f["vertex_indices"]
        n = np.cross(P[t[1]] - P[t[0]], P[t[2]] - P[t[0]])
        n /= np.linalg.norm(n)
        for i in t:
            up[i] = 1 if n[1] > 0.99 else -1 if n[1] < -0.99 else up[i]
        if abs(n[1]) <= 0.5:
            for k in range(3):
                a, b = P[t[k]], P[t[(k + 1) % 3]]
                if a[1] < 0.5 and b[1] < 0.5 and in_room(a) and in_room(b):
                    feet.append((a, b))

    def dist(p, a, b):
        d = b - a
        t = np.clip(np.dot(p - a, d) / np.dot(d, d), 0, 1)
        return np.linalg.norm(p - (a + t * d))

    g = {"lamp border": [], "blocks' sides at the floor": [], "floor within 30 mm of a block": []}
    for i, p in enumerate(P):
        if up[i] == -1 and abs(p[1] - 548.8) < 0.01:
            on_x = (abs(p[0] - 213) < 0.01 or abs(p[0] - 343) < 0.01) and 226.9 < p[2] < 332.1
            on_z = (abs(p[2] - 227) < 0.01 or abs(p[2] - 332) < 0.01) and 212.9 < p[0] < 343.1
            if on_x or on_z:
                g["lamp border"].append(i)
        if p[1] > 0.01 or not in_room(p):
            continue
        d = min(dist(p, a, b) for a, b in feet)
        if up[i] == 0 and d < 0.01:
            g["blocks' sides at the floor"].append(i)
        if up[i] == 1 and d < 30:
            g["floor within 30 mm of a block"].append(i)
    return g


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--after", required=True, help="the gi binary to measure")
    ap.add_argument("--before", default="", help="optional: the gi binary before the change")
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(HERE, "results", "photon_contact_bench.json"))
    a = ap.parse_args()
    work = os.path.join(a.results, "photon_contact")
    cache = os.path.join(a.results, "refs")
    os.makedirs(work, exist_ok=True)
    os.makedirs(cache, exist_ok=True)
    gi = a.after
    scenes_tool = os.path.join(os.path.dirname(gi), "gi-scenes")
    box = os.path.join(ROOT, "test_meshes", "cornell_box.ply")
    room = os.path.join(work, "scanroom100k.ply")
    if not os.path.exists(room):
        run([scenes_tool, "scanroom", os.path.join(ROOT, "test_meshes", "bunny.ply"), "100000", room])
    binaries = {"after": a.after}
    if a.before:
        binaries["before"] = a.before
    cases = [("cornell_box", box, ["--emitter_source", "1"]),
             ("cornell_box, final_gather", box, ["--emitter_source", "1", "--final_gather", "true"]),
             ("cornell_box, progressive", box, ["--emitter_source", "1", "--progressive", "true"]),
             ("scan room 100k", room, []),
             ("scan room 100k, progressive", room, ["--progressive", "true"])]
    refs = {"cornell_box": reference(gi, box, cache, ["--emitter_source", "1", "--target_relative_error", "0.01"]),
            "scan room 100k": reference(gi, room, cache, ["--traced_vertices", "4000", "--samples_per_vertex", "16384",
                                                           "--traced_vertex_seed", "7"])}
    groups = box_groups(box)
    out = {"what": __doc__.split("\n\n")[0], "started": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()),
           "binaries": binaries, "rows": []}
    values = {}
    for name, mesh, extra in cases:
        for label, binary in binaries.items():
            ply = os.path.join(work, "%s_%s.ply" % (label, name.replace(" ", "_").replace(",", "")))
            times = []
            for _ in range(a.repeats):
                stdout, wall = run([binary, "photonmap", mesh, "-q", "--json", "-o", ply] + extra)
                times.append(wall)
            stats = json.loads(stdout)["stats"]
            values[(name, label)] = radiosity(ply)
            row = {"case": name, "binary": label, "wall_seconds_median": statistics.median(times),
                   "wall_seconds": times,
                   "vertices_gathered": stats.get("vertices_gathered_beside_other_surfaces", 0.0)
                   + stats.get("vertices_gathered_at_creases", 0.0),
                   "gather_near_hits_relit": stats.get("gather_near_hits_relit", 0.0)}
            out["rows"].append(row)
            print(json.dumps(row), flush=True)
    for name, _, _ in cases:
        B, se, paths = refs["scan room 100k" if name.startswith("scan") else "cornell_box"]
        for label in binaries:
            q = values[(name, label)]
            row = {"case": name, "binary": label, "errors": {}}
            if name.startswith("scan"):
                traced = (paths > 0) & (B > 0)
                other = "before" if label == "after" else "after"
                changed = traced & (np.abs(q - values[(name, other)]) > 1e-7 * np.maximum(q, 1e-9)) \
                    if (name, other) in values else traced
                for part, m in (("handed over", changed), ("the rest", traced & ~changed)):
                    if m.sum():
                        d = q[m] - B[m]
                        row["errors"][part] = {"vertices": int(m.sum()), "bias": float(d.sum() / B[m].sum()),
                                               "rms_of_mean": float(np.sqrt((d ** 2).mean()) / B[m].mean()),
                                               "reference_noise_of_mean": float(np.sqrt((se[m] ** 2).mean()) / B[m].mean())}
            else:
                ok = B > 1e-3 * B.max()
                rel = (q[ok] - B[ok]) / B[ok]
                row["errors"]["all vertices"] = {"vertices": int(ok.sum()), "relative_rms": float(np.sqrt((rel ** 2).mean()))}
                for part, ids in groups.items():
                    ids = np.array([i for i in ids if B[i] > 0])
                    d = q[ids] - B[ids]
                    row["errors"][part] = {"vertices": len(ids), "bias": float(d.sum() / B[ids].sum()),
                                           "worst_of_mean": float(np.abs(d).max() / B[ids].mean())}
            out["rows"].append(row)
            print(json.dumps(row), flush=True)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print("written", a.out)


if __name__ == "__main__":
    main()
