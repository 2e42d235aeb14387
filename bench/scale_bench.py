#!/usr/bin/env python3
"""Hierarchical radiosity at scale (README, "Hierarchical radiosity"): time,
CPU time, peak memory and error against triangles on generated scan rooms.

Each scene is `gi-scenes scanroom BASE N` (a Loop-subdivided, displaced scan
standing in a room with a ceiling light and a window; gi/scan.h), run as
`gi radiosity ROOM.ply --solver Hierarchical --vertex_output 'Final gather'
--json` with a sky seen through the window and the goal's memory budget; the
child's wall time, CPU time (user + system, from wait4) and peak resident
memory are recorded. The error: `gi reference --traced_vertices` on a random
sample of the vertices (1% by default, at least --min_sample), the relative
RMS difference there (bench/hr_bench.py's measure), and the same relative to
max(B_ref, a tenth of the sample's mean B_ref) (the reference's own floor for
dark vertices: a handful of vertices in the scan's shadowed crevices next to
the floor, nearly black, would otherwise weigh as much as a wall), each with
the reference's own noise (the RMS of its standard errors on the same scale)
removed in quadrature. The runs are hr_bench.py's.

Writes the results as JSON and a log-log plot of time and memory against
triangles with the fitted slopes (numpy, matplotlib: /usr/bin/python3).

usage: python3 bench/scale_bench.py [--build build] [--sizes 10000,30000,100000,300000,1000000]
                                    [--out bench/scale_bench_results.json] [--plot docs/img/scale_bench.png]
                                    [--ref_paths 4096] [--radiosity_args "..."] [--replot]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hr_bench  # noqa: E402

GOAL = {"triangles": 1000000, "seconds": 60.0, "MB": 2048.0, "error": 0.02}


def measure(a, tmp, target):
    mesh = os.path.join(tmp, "scanroom.ply")
    subprocess.run([os.path.join(a.build, "tools", "gi-scenes"), "scanroom", a.base, str(target), mesh],
                   check=True, stdout=subprocess.DEVNULL)
    lights = ["--sky_irradiance", str(a.sky)]
    out = os.path.join(tmp, "out.ply")
    usage, load0 = [], os.getloadavg()[0]
    gi = os.path.join(a.build, "tools", "gi")
    extra = a.radiosity_args.split() if a.radiosity_args else []
    j, wall, rss = hr_bench.run(gi, mesh, out, "Hierarchical", lights + ["--memory_budget_mb", str(a.budget)] + extra,
                                "Final gather", usage)
    st = j.get("stats", j)
    row = {"target": target, "triangles": int(j["scene"]["faces"]), "vertices": int(j["scene"]["vertices"]),
           "seconds": wall, "cpu_seconds": usage[0], "peak_MB": rss, "load_before": load0,
           "memory_budget_mb": a.budget, "sample": a.sample, "radiosity_args": a.radiosity_args,
           "load_after": os.getloadavg()[0],
           "stats": {k: st.get(k) for k in ("hierarchy_levels", "links", "links_patch_to_patch", "link_splits",
                                            "refinement_rounds", "link_rays", "gather_rays", "shadow_rays",
                                            "hierarchy_MB", "memory_estimate_MB", "direct_light_seconds",
                                            "link_form_factor_seconds", "hierarchy_seconds",
                                            "vertex_output_seconds", "link_refinement_seconds",
                                            "hierarchy_sweep_seconds", "vertex_direct_seconds",
                                            "vertex_sky_sun_seconds", "final_gather_seconds", "sky_portals",
                                            "seconds")}}
    print("%8d triangles: %7.1f s wall, %7.1f s CPU, %6.0f MB (load %.1f)"
          % (row["triangles"], wall, usage[0], rss, load0), file=sys.stderr, flush=True)
    values = hr_bench.vertex_values(out)
    count = max(a.min_sample, int(round(a.sample * row["vertices"])))
    idx, ref, ref_err, ref_wall = hr_bench.reference_at_sample(gi, mesh, tmp, count, a.ref_paths, a.seed, lights)
    e = hr_bench.error_at(values, idx, ref, ref_err)
    e["noise_removed"] = math.sqrt(max(0.0, e["rms_relative_error"] ** 2 - e["reference_rms_relative_std_error"] ** 2))
    floor = 0.1 * sum(ref) / len(ref)
    d = [(values[i] - r) / max(r, floor) for i, r in zip(idx, ref)]
    n = [s / max(r, floor) for r, s in zip(ref, ref_err)]
    e["floored_rms"] = math.sqrt(sum(x * x for x in d) / len(d))
    e["floored_noise"] = math.sqrt(sum(x * x for x in n) / len(n))
    e["floored_noise_removed"] = math.sqrt(max(0.0, e["floored_rms"] ** 2 - e["floored_noise"] ** 2))
    e["reference_seconds"], e["reference_paths"] = ref_wall, a.ref_paths
    row["error"] = e
    print("%8d triangles: error %.4f (reference noise %.4f; removed: %.4f), floored %.4f (noise %.4f; removed: "
          "%.4f) at %d vertices" % (row["triangles"], e["rms_relative_error"], e["reference_rms_relative_std_error"],
                                    e["noise_removed"], e["floored_rms"], e["floored_noise"],
                                    e["floored_noise_removed"], e["vertices"]), file=sys.stderr, flush=True)
    return row


def plot(summary, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    rows = summary["runs"]
    x = np.array([r["triangles"] for r in rows], float)
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    series = (("seconds", "wall time (s)", ax[0], "o-"), ("cpu_seconds", "CPU time (s)", ax[0], "s--"),
              ("peak_MB", "peak memory (MB)", ax[1], "o-"))
    for key, label, axis, style in series:
        y = np.array([r[key] for r in rows], float)
        fit = "" if len(rows) < 2 else ", slope %.2f" % hr_bench.slope(x, y)
        axis.loglog(x, y, style, label=label + fit)
    ax[0].plot([GOAL["triangles"]], [GOAL["seconds"]], "r*", ms=12, label="goal: 1M in 60 s")
    ax[1].plot([GOAL["triangles"]], [GOAL["MB"]], "r*", ms=12, label="goal: 1M in 2 GB")
    for axis, title in zip(ax, ("time (2 cores, shared)", "memory")):
        axis.set_xlabel("triangles")
        axis.set_title("hierarchical radiosity on scan rooms: " + title, fontsize=9)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--base", default="test_meshes/bunny.ply")
    ap.add_argument("--sizes", default="10000,30000,100000,300000,1000000")
    ap.add_argument("--sky", type=float, default=20.0, help="sky irradiance (W/m^2) seen through the window")
    ap.add_argument("--budget", type=float, default=2048.0,
                    help="memory_budget_mb (the goal's 2 GB; each run records its own: 5M triangles need more)")
    ap.add_argument("--sample", type=float, default=0.01, help="share of the vertices the reference traces")
    ap.add_argument("--min_sample", type=int, default=200)
    ap.add_argument("--ref_paths", type=int, default=4096)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--radiosity_args", default="",
                    help="more `gi radiosity` options for every run, e.g. \"--gather_rays 128 --gather_share_rings 2\" "
                         "(recorded in each row; give such runs their own --out and --plot)")
    ap.add_argument("--out", default="bench/scale_bench_results.json")
    ap.add_argument("--plot", default="docs/img/scale_bench.png")
    ap.add_argument("--replot", action="store_true", help="only redraw the plot from --out")
    a = ap.parse_args()
    if a.replot:
        with open(a.out) as f:
            plot(json.load(f), a.plot)
        return
    rows = []
    if os.path.exists(a.out):  # sizes measured earlier are kept unless measured again
        with open(a.out) as f:
            rows = json.load(f)["runs"]
    with tempfile.TemporaryDirectory() as tmp:
        for target in [int(s) for s in a.sizes.split(",")]:
            row = measure(a, tmp, target)
            row["date_utc"] = time.strftime("%Y-%m-%d %H:%M", time.gmtime())
            row["source_commit"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                                  text=True).stdout.strip()
            rows = sorted([r for r in rows if r["target"] != target] + [row], key=lambda r: r["target"])
            summary = {"goal": GOAL, "settings": {"sky_irradiance": a.sky, "memory_budget_mb": 2048.0,
                                                  "sample": 0.01, "reference_paths": a.ref_paths,
                                                  "note": "defaults; a run with its own memory_budget_mb and "
                                                          "sample records them",
                                                  "base": os.path.basename(a.base)}, "runs": rows}
            if len(rows) >= 2:
                xs = [r["triangles"] for r in rows]
                for key in ("seconds", "cpu_seconds", "peak_MB"):
                    summary[key + "_slope"] = hr_bench.slope(xs, [r[key] for r in rows])
            with open(a.out, "w") as f:
                json.dump(summary, f, indent=1)
            plot(summary, a.plot)
    print(json.dumps({k: v for k, v in summary.items() if k != "runs"}, indent=1))


if __name__ == "__main__":
    main()
