#!/usr/bin/env python3
"""Photon mapping: error versus time against the cached path-traced
reference on the diffuse Cornell box and on the caustic Cornell box (glass
sphere and mirror, three layers), with the path tracer itself as the peer on
the caustic: its error at equal time, interpolated log-log. Also photons per
second, kd-tree build and query times, and 10M photons (time, memory).

Error: RMS over vertices of (B - B_ref) relative to the mean B_ref, over the
caustic region (floor vertices within 60 mm of the focus predicted by the
line from the light's centre through the sphere's centre) and over the
vertices off the sheets' borders, weighted by area (as lighting_bench.py); the reference's own noise is reported and removed in quadrature.
Times are the filters' own `seconds` (medians of repeats).

Writes results/photon_bench.{json,csv,md,png}.
usage: /usr/bin/python3 bench/photon_bench.py [--build build] [--quick]
"""
import argparse
import csv
import json
import math
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from lighting_bench import lum, reference_arrays, run, run_measured, vertex_weights  # noqa: E402
from plyread import read_ply  # noqa: E402

MESHES = os.path.join(ROOT, "test_meshes")
CAUSTIC = [os.path.join(MESHES, "caustic_cornell_%s.ply" % n) for n in ("box", "glass_sphere", "mirror")]
LIGHT, GLASS = (278.0, 548.7, 279.5), (185.0, 180.0, 200.0)
T = LIGHT[1] / (LIGHT[1] - GLASS[1])
FOCUS = (LIGHT[0] + (GLASS[0] - LIGHT[0]) * T, LIGHT[2] + (GLASS[2] - LIGHT[2]) * T)


class Bench:
    def __init__(self, build, out, repeats):
        self.gi = os.path.join(build, "tools", "gi")
        self.scenes = os.path.join(build, "tools", "gi-scenes")
        self.out, self.repeats = out, repeats
        self.tmp = os.path.join(out, "tmp")
        os.makedirs(self.tmp, exist_ok=True)
        self.rows = []

    def inputs(self, scene):
        if scene == "caustic_cornell":
            return [CAUSTIC[0], "--layer", CAUSTIC[1], "--layer", CAUSTIC[2]]
        return [os.path.join(MESHES, scene + ".ply")]

    def reference(self, scene, target):
        cache = os.path.join(self.out, "refs")
        os.makedirs(cache, exist_ok=True)
        t0 = time.perf_counter()
        j = json.loads(run([self.gi, "reference"] + self.inputs(scene) + [
            "-q", "--json", "--emitter_source", "1", "--cache", cache, "--target_relative_error", str(target),
            "--min_samples", "64", "--max_samples", "262144"]))
        path = [n for n in j["notes"] if "cached" in n][0].split(" ")[-1]
        with open(path) as f:
            ref = json.load(f)
        ref = reference_arrays(ref)
        ref["wall_seconds_this_run"] = time.perf_counter() - t0
        ref["file"] = os.path.relpath(path, ROOT)
        return ref

    def regions(self, scene, ref):
        """Weighted vertex sets: 'interior' (vertex areas, 0 on emitters and on the sheets' borders, where
        per-vertex values of a crease or a light's rim depend on the estimator's footprint) and, on the
        caustic box, 'caustic' (floor vertices within 60 mm of the focus, equal weights)."""
        mesh = self.inputs(scene)[0]
        w = vertex_weights(mesh)[1]
        out = {"interior": [(i, x) for i, x in enumerate(w) if x > 0]}
        if scene == "caustic_cornell":
            v = read_ply(mesh)["vertex"]
            out["caustic"] = [(i, 1.0) for i, r in enumerate(v) if abs(r["y"]) < 1e-3 and
                              math.hypot(r["x"] - FOCUS[0], r["z"] - FOCUS[1]) < 60.0]
        return out

    def run_method(self, scene, label, sub, args, ref, regions, tag):
        out = os.path.join(self.tmp, "out.ply")
        times, stats = [], None
        for _ in range(self.repeats):
            j = json.loads(run([self.gi, sub] + self.inputs(scene) + args + ["-o", out, "-q", "--json", "--emitter_source", "1"]))
            times.append(j["stats"]["seconds"])
            stats = j["stats"]
        B = [r["quality"] for r in read_ply(out)["vertex"]]
        Bref = [lum(ref["B"][3 * i:3 * i + 3]) for i in range(ref["vertices"])]
        se = ref["std_error_B"]
        row = {"scene": scene, "method": label, "tag": tag, "args": " ".join(args),
               "seconds": sorted(times)[len(times) // 2]}
        for name, iw in regions.items():
            W = sum(x for _, x in iw)
            mean = sum(x * Bref[i] for i, x in iw) / W
            err = math.sqrt(sum(x * (B[i] - Bref[i]) ** 2 for i, x in iw) / W) / mean
            noise = math.sqrt(sum(x * se[i] ** 2 for i, x in iw) / W) / mean
            row["error_" + name] = err
            row["error_%s_minus_reference_noise" % name] = math.sqrt(max(0.0, err * err - noise * noise))
            row["reference_noise_" + name] = noise
        for k in ("photons_per_second", "kdtree_build_seconds", "query_seconds", "trace_seconds", "photon_memory_mb",
                  "photons_stored", "photons_caustic_map", "rays_per_second"):
            if k in stats:
                row[k] = stats[k]
        self.rows.append(row)
        main = "caustic" if "caustic" in regions else "interior"
        print("%-16s %-40s %-44s %8.3f s  error %s %.4f" % (scene, label, row["args"][:44], row["seconds"], main,
                                                            row["error_" + main]), flush=True)



def loglog_at(pts, t):
    """Error at time t by log-log interpolation of (time, error) points (extrapolated at the ends)."""
    pts = sorted(pts)
    if len(pts) < 2:
        return float("nan")
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if t <= t1 or (t1, e1) == pts[-1]:
            s = (math.log(e1) - math.log(e0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + s * (math.log(t) - math.log(t0)))
    return float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--report", action="store_true", help="only rewrite the tables and plot from results/photon_bench.json")
    a = ap.parse_args()
    if a.report:
        with open(os.path.join(a.out, "photon_bench.json")) as f:
            report(json.load(f), a.out)
        return
    os.makedirs(a.out, exist_ok=True)
    b = Bench(a.build, a.out, 1 if a.quick else 3)
    q = a.quick
    refs = {}
    for scene in ["cornell_box", "caustic_cornell"]:
        ref = b.reference(scene, 0.02 if q else 0.01)
        rel = [s / max(x, 1e-12) for s, x in zip(ref["std_error_B"], [lum(ref["B"][3 * i:3 * i + 3]) for i in range(ref["vertices"])])]
        refs[scene] = {"file": ref["file"], "seconds": ref["seconds"], "paths": sum(ref["samples"]),
                       "mean_relative_std_error": sum(rel) / len(rel), "wall_seconds_this_run": ref["wall_seconds_this_run"]}
        print("reference %s: %s (%.1f s)" % (scene, ref["file"], ref["seconds"]), flush=True)
        regions = b.regions(scene, ref)
        photons = [100000, 1000000] if q else [100000, 300000, 1000000, 3000000]
        for n in photons:
            b.run_method(scene, "photon mapping", "photonmap", ["--photons", str(n), "--light_samples", "1024"], ref, regions, "pm")
        if not q:
            b.run_method(scene, "photon mapping, k = 512", "photonmap",
                         ["--photons", "3000000", "--k_nearest", "512", "--caustic_k", "512", "--light_samples", "1024"],
                         ref, regions, "pm_k512")
        for passes in ([4] if q else [4, 16, 64, 128]):
            b.run_method(scene, "progressive photon mapping (50k per pass)", "photonmap",
                         ["--photons", "50000", "--progressive", "true", "--passes", str(passes), "--light_samples", "1024"],
                         ref, regions, "ppm")
        if scene == "cornell_box":
            for n in ([300000] if q else [300000, 1000000]):
                b.run_method(scene, "photon mapping, final gather (256 rays)", "photonmap",
                             ["--photons", str(n), "--light_samples", "1024", "--final_gather", "true", "--gather_rays", "256"],
                             ref, regions, "pm_fg")
        # The peer: the path tracer itself (an independent seed), at growing path counts.
        for spp in ([16, 128] if q else [16, 64, 256, 1024, 4096]):
            b.run_method(scene, "path tracer", "reference", ["--samples_per_vertex", str(spp), "--seed", "1"], ref, regions, "pt")
    # 10M photons: time, peak memory, photon memory.
    big = {}
    if not q:
        out = os.path.join(b.tmp, "big.ply")
        cmd = [b.gi, "photonmap"] + b.inputs("caustic_cornell") + ["--photons", "10000000", "--emitter_source", "1", "-q",
                                                                     "-o", out]
        wall, rss = run_measured(cmd)
        j = json.loads(run(cmd + ["--json"]))
        big = {"photons": 10000000, "wall_seconds": wall, "peak_rss_mb": rss, "photon_memory_mb": j["stats"]["photon_memory_mb"],
               "photons_stored": j["stats"]["photons_stored"], "photons_per_second": j["stats"]["photons_per_second"],
               "kdtree_build_seconds": j["stats"]["kdtree_build_seconds"]}
        print("10M photons: %.1f s, peak RSS %.0f MB, photon maps %.0f MB" % (wall, rss, big["photon_memory_mb"]), flush=True)
    report({"rows": b.rows, "references": refs, "ten_million": big, "focus": FOCUS}, a.out)


def equal_time(rows):
    """On the caustic region, per photon-mapping run: the path tracer's error at the same time, and the
    time it needs for the same error (both by log-log interpolation of its runs, extrapolated at the ends)."""
    pt = [(r["seconds"], r["error_caustic"]) for r in rows if r["scene"] == "caustic_cornell" and r["tag"] == "pt"]
    inv = [(e, t) for t, e in pt]
    out = []
    for r in rows:
        if r["scene"] == "caustic_cornell" and r["tag"] in ("pm", "pm_k512", "ppm"):
            e_pt = loglog_at(pt, r["seconds"])
            t_pt = loglog_at(inv, r["error_caustic"])
            out.append({"method": r["method"], "args": r["args"], "seconds": r["seconds"], "error_pm": r["error_caustic"],
                        "error_pt_at_equal_time": e_pt, "ratio_pt_over_pm": e_pt / r["error_caustic"],
                        "pt_seconds_to_same_error": t_pt, "time_ratio": t_pt / r["seconds"]})
    return out


def report(result, outdir):
    """Writes photon_bench.{json,csv,md,png} from the measured rows."""
    b_rows, refs, big = result["rows"], result["references"], result["ten_million"]
    equal = result["equal_time"] = equal_time(b_rows)
    with open(os.path.join(outdir, "photon_bench.json"), "w") as f:
        json.dump(result, f, indent=1)
    keys = sorted({k for r in b_rows for k in r})
    with open(os.path.join(outdir, "photon_bench.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=keys)
        wr.writeheader()
        wr.writerows(b_rows)
    lines = ["| scene | method | settings | time (s) | error, caustic region | error, interior vertices | interior minus ref. noise | photons/s | kd-tree build (s) | query (s) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in b_rows:
        lines.append("| %s | %s | %s | %.2f | %s | %.4f | %.4f | %s | %s | %s |" % (
            r["scene"], r["method"], r["args"], r["seconds"],
            "%.4f" % r["error_caustic"] if "error_caustic" in r else "", r["error_interior"],
            r["error_interior_minus_reference_noise"],
            "%.2fM" % (r["photons_per_second"] / 1e6) if "photons_per_second" in r else "",
            "%.3f" % r["kdtree_build_seconds"] if "kdtree_build_seconds" in r else "",
            "%.3f" % r["query_seconds"] if "query_seconds" in r else ""))
    lines += ["", "| caustic region: method | settings | time (s) | error | path tracer's error at equal time | error ratio | path tracer's time to the same error (s) | time ratio |",
              "|---|---|---|---|---|---|---|---|"]
    for e in equal:
        lines.append("| %s | %s | %.2f | %.4f | %.4f | %.1f | %.1f | %.1f |" % (
            e["method"], e["args"], e["seconds"], e["error_pm"], e["error_pt_at_equal_time"], e["ratio_pt_over_pm"],
            e["pt_seconds_to_same_error"], e["time_ratio"]))
    if big:
        lines += ["", "10M photons on the caustic box: %.1f s, peak RSS %.0f MB (photon maps %.0f MB, %.1fM stored), %.2fM photons/s" % (
            big["wall_seconds"], big["peak_rss_mb"], big["photon_memory_mb"], big["photons_stored"] / 1e6,
            big["photons_per_second"] / 1e6)]
    for s, info in refs.items():
        lines.append("reference %s: %d paths, %.1f s, mean relative standard error %.4f (%s)" % (
            s, info["paths"], info["seconds"], info["mean_relative_std_error"], info["file"]))
    with open(os.path.join(outdir, "photon_bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    methods = sorted({r["method"] for r in b_rows})
    colour = {m: "C%d" % (i % 10) for i, m in enumerate(methods)}
    for ax, (scene, region) in zip(axes, [("cornell_box", "interior"), ("caustic_cornell", "caustic")]):
        for m in methods:
            pts = sorted((r["seconds"], r["error_" + region]) for r in b_rows if r["scene"] == scene and r["method"] == m)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", color=colour[m], label=m)
        noise = [r["reference_noise_" + region] for r in b_rows if r["scene"] == scene][0]
        ax.axhline(noise, color="grey", ls="--", lw=0.7, label="the reference's own noise")
        ax.set_title("%s (%s vertices)" % (scene, region))
        ax.set_xlabel("time (s)")
        ax.set_ylabel("relative RMS error vs path-traced reference")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "photon_bench.png"), dpi=110)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
