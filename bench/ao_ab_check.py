#!/usr/bin/env python3
"""Two builds of `gi` against each other on the AO benchmark's meshes, in the same hour as MeshLab.

For a change that should make ours faster without changing its error: the shared adaptive estimator of each
binary at a few targets around MeshLab's error, runs alternated (before, after, before, ...) so that the
machine's drift hits both alike, medians of the repeats; each binary's time at MeshLab's RMS error by log-log
interpolation (as ao_bench.py), and MeshLab's filter (512 views, 512^2 maps, CPU) run once per mesh in the same
session. References and error definitions are ao_bench.py's (the same cached references under bench/results).

    python3 bench/ao_ab_check.py --before OLD/tools/gi --after build/tools/gi \
        --before-label COMMIT --after-label "what changed" \
        --scenes scan_118k,scan_470k,scan_1.9M --out bench/results/ao_ab_check.json

OLD is a build of the commit before the change (e.g. a `git worktree` of it, configured with
-DGI_BUILD_MESHLAB=OFF: only its `gi` is needed).
"""
import argparse
import json
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import ao_bench  # noqa: E402  (the benchmark's references, runs and interpolation)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True, help="the gi binary before the change")
    ap.add_argument("--after", required=True, help="the gi binary after it")
    ap.add_argument("--before-label", default="", help="what the first binary is (a commit), for the results")
    ap.add_argument("--after-label", default="", help="what the second binary is")
    ap.add_argument("--build", default=os.path.join(ao_bench.ROOT, "build"), help="for meshlabserver and ao_reference")
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--scenes", default="scan_118k,scan_470k,scan_1.9M")
    ap.add_argument("--targets", default="0.04,0.03,0.02,0.015")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-meshlab", action="store_true", help="take MeshLab's time from the benchmark's cache instead")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "ao_ab_check.json"))
    a = ap.parse_args()
    b = ao_bench.Bench(a.build, a.results, False)
    wanted = a.scenes.split(",")
    sizes = "large" if all(s.startswith("scan_") for s in wanted) else "all"
    meshes = ao_bench.scenes(a.build, a.results, sizes, wanted)
    targets = [float(t) for t in a.targets.split(",")]
    out = {"what": "Shared adaptive AO (--estimator 1 --min_rays 8 --seed 1), two binaries alternated, "
                   "%d runs each (medians; time = seconds + bvh_seconds as in ao_bench.py); MeshLab's filter "
                   "(512 views, 512^2, CPU) %s; RMS against ao_bench.py's angle-normal references (MeshLab's "
                   "against the area-normal ones), their own noise removed in quadrature."
                   % (a.repeats, "cached" if a.no_meshlab else "once per mesh in the same session"),
           "before": a.before_label or os.path.basename(a.before), "after": a.after_label or os.path.basename(a.after),
           "started": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()), "rows": [], "summary": []}
    for scene, mesh in meshes.items():
        nv = len(ao_bench.vertex_property(mesh, "x"))
        ref_rays = ao_bench.reference_rays(nv)
        ref = b.reference(scene, mesh, "angle", ref_rays)
        ref_ml = b.reference(scene, mesh, "area", ref_rays)
        rows = {"before": [], "after": []}
        for t in targets:
            runs = {"before": [], "after": []}
            last = {}
            for _ in range(a.repeats):
                for code, gi in (("before", a.before), ("after", a.after)):
                    path = os.path.join(b.tmp, code + ".ply")
                    text, _ = ao_bench.run([gi, "ao", mesh, "-o", path, "-q", "--json", "--estimator", "1",
                                            "--target_error", str(t), "--min_rays", "8", "--seed", "1"])
                    st = json.loads(text)["stats"]
                    runs[code].append(st["seconds"] + st["bvh_seconds"])
                    last[code] = (path, st)
            for code in ("before", "after"):
                _, err = b.error(ao_bench.vertex_property(last[code][0], "quality"), ref)
                row = {"code": code, "mesh": scene, "target_error": t,
                       "seconds_runs": [round(x, 3) for x in runs[code]],
                       "seconds_median": round(statistics.median(runs[code]), 3),
                       "rays_per_vertex": round(last[code][1]["rays"] / nv, 1), "rms_error": round(err, 5)}
                rows[code].append(row)
                out["rows"].append(row)
                print("%-10s %-6s target %.3f: %s s (median %.3f), %.1f rays/vertex, RMS %.5f" % (
                    scene, code, t, " ".join("%.2f" % x for x in runs[code]), row["seconds_median"],
                    row["rays_per_vertex"], err), flush=True)
        if a.no_meshlab:
            if not b.meshlab(scene, mesh, nv, ref_ml, 512, 512, 1, cached_only=True):
                continue
        else:
            b.meshlab(scene, mesh, nv, ref_ml, 512, 512, 1, fresh=True)
        ml = b.rows[-1]
        s = {"mesh": scene, "vertices": nv, "meshlab_seconds": ml["filter_seconds"], "meshlab_rms": round(ml["rms_error"], 5)}
        for code in ("before", "after"):
            pts = [{"filter_seconds": r["seconds_median"], "rms_error": r["rms_error"]} for r in rows[code]]
            at = ao_bench.time_to_reach(pts, ml["rms_error"])
            s[code + "_seconds"] = round(at, 3) if at else None
            s[code + "_speedup"] = round(ml["filter_seconds"] / at, 1) if at else None
        out["summary"].append(s)
        print("%-10s MeshLab %.1f s, RMS %.5f; before %s s (%sx), after %s s (%sx)" % (
            scene, s["meshlab_seconds"], s["meshlab_rms"], s["before_seconds"], s["before_speedup"],
            s["after_seconds"], s["after_speedup"]), flush=True)
    out["finished"] = time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime())
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
