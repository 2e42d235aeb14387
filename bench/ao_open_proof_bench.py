#!/usr/bin/env python3
"""What the proof that a vertex is open within max_distance costs, against the rays it saves.

A vertex with no face above its tangent plane within reach of its rays gets AO 1 without rays
(`OpenSpaceTest` in core/include/gi/open_space.h). The proof must cost less than the rays it saves at
every max_distance, short or long. For each mesh and distance this runs ambient occlusion per vertex
(16 rays, where the proof weighs most against the rays) and obscurance at its default (10% of the
diagonal, 256 rays), with one binary or two alternated (`--before`, e.g. a build of the commit before a
change to the proof), and records the filter's own time (`seconds`, the BVH apart), the vertices proved
open, the rays and the mean; with two binaries, whether their outputs are byte-identical. A run past
`--timeout` is recorded as at least that long (the search this tree replaced took minutes).

    python3 bench/ao_open_proof_bench.py [--before OLD/tools/gi] [--scenes bunny_fine,scan_470k]
        [--distances 0,1%,5%,20%,100%] [--repeats 3] [--out bench/results/ao_open_proof_bench.json]
"""
import argparse
import filecmp
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import ao_bench  # noqa: E402  (the benchmark's meshes)


def one_run(gi, args, mesh, out, timeout):
    """The filter's log statistics of one run, or None past the timeout."""
    cmd = [gi] + args + [mesh, "-o", out, "--json", "-q"]
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    if p.returncode != 0:
        raise RuntimeError("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr.decode()[-2000:]))
    s = json.loads(p.stdout)["stats"]
    return {k: s.get(k) for k in ("seconds", "open_proof_seconds", "skipped_open", "rays", "mean", "bvh_seconds")}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--after", default=os.path.join(ao_bench.ROOT, "build", "tools", "gi"), help="the gi measured")
    ap.add_argument("--before", default="", help="optionally a second gi, alternated with the first")
    ap.add_argument("--build", default=os.path.join(ao_bench.ROOT, "build"), help="for gi-scenes")
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--scenes", default="bunny_fine,scan_470k")
    ap.add_argument("--distances", default="0,1%,5%,20%,100%")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds; a run past it counts as at least this")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "ao_open_proof_bench.json"))
    a = ap.parse_args()
    os.makedirs(a.results, exist_ok=True)
    wanted = a.scenes.split(",")
    sizes = "all" if any(not s.startswith("scan_") for s in wanted) else "large"
    meshes = ao_bench.scenes(a.build, a.results, sizes, wanted)
    binaries = [("after", a.after)] + ([("before", a.before)] if a.before else [])
    cases = [("ao", d, ["ao", "--rays_per_vertex", "16", "--max_distance", d]) for d in a.distances.split(",")]
    cases.append(("obscurance", "10% (default)", ["obscurance"]))
    out = {"what": "The open-within-reach proof: filter time (seconds, BVH apart; medians of the repeats, binaries "
                   "alternated), vertices proved open, rays and mean, per vertex: AO at 16 rays per vertex and "
                   "obscurance at its defaults; a run past the timeout is recorded as at least the timeout.",
           "started": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()), "load_before": ao_bench.load_average(),
           "binaries": dict(binaries), "timeout_s": a.timeout, "rows": []}
    tmp = tempfile.mkdtemp(prefix="ao_open_proof_")
    for scene, mesh in meshes.items():
        for filt, dist, args in cases:
            runs = {label: [] for label, _ in binaries}
            timed_out = {label: False for label, _ in binaries}
            stats = {}
            for _ in range(a.repeats):
                for label, gi in binaries:
                    if timed_out[label]:
                        continue
                    r = one_run(gi, args, mesh, os.path.join(tmp, label + ".ply"), a.timeout)
                    if r is None:
                        timed_out[label] = True
                        continue
                    runs[label].append(r["seconds"])
                    stats[label] = r
            row = {"scene": scene, "filter": filt, "max_distance": dist}
            for label, _ in binaries:
                row[label] = dict(stats.get(label, {}))
                row[label]["seconds"] = (">= %g" % a.timeout) if timed_out[label] else statistics.median(runs[label])
                row[label]["runs"] = len(runs[label])
            if len(binaries) == 2 and not any(timed_out.values()):
                row["same_output"] = filecmp.cmp(os.path.join(tmp, "after.ply"), os.path.join(tmp, "before.ply"),
                                                 shallow=False)
            out["rows"].append(row)
            print(json.dumps(row), flush=True)
    out["load_after"] = ao_bench.load_average()
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print("written", a.out)


if __name__ == "__main__":
    main()
