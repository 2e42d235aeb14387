#!/usr/bin/env python3
"""The ray-traced view (GI: Ray Traced View): error versus time of its modes
side by side on the caustic Cornell box with the glossy block (glass sphere,
mirror, GGX block; `gi-scenes caustic_cornell_glossy`), the filter's framing
camera, against a long path-traced render (cached in results/refs/).

Error of an image: relative RMS of the luminance against the reference over
the pixels that show no light source, directly or in the mirror or glass
(those and their neighbours are the same in every mode but for
antialiasing), relative to the reference's mean; reported raw and with the
reference's own variance (its per-pixel standard errors) taken out: an
unbiased estimate of the error against the exact image. Times: the
engine's own (first pass included for two-pass), medians of repeats with
different seeds, run round robin (seed k of every setting in pass k, so
that a machine's changing load weighs on every mode alike); errors are
medians too.

Time to reach 2% (the goal) and 2.5% (corrected error): log-log
interpolation between the two settings that bracket it; the ratio of path
tracing's time to the faster two-pass variant's. The path tracer is unbiased with independent
samples, so its mean squared error is c / N exactly: its time to 2% is also
extrapolated from every run (c from error^2 N, time per sample from time / N)
when no run reaches 2%.

Throughput: primary rays (a tile's sample as one batch: single rays, 8-wide
packets, a stream) and the path tracer's secondary rays (recorded, then
replayed) against a bare Embree loop over the very same rays.

Writes results/render_bench.{json,csv,md,png}.
usage: /usr/bin/python3 bench/render_bench.py [--build build] [--quick] [--repeats N] [--report]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET = 0.02
TARGETS = (0.02, 0.025)


def run_json(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(cmd), p.stderr))
    return json.loads(p.stdout)


def median(v):
    v = sorted(v)
    return v[len(v) // 2]


def settings(quick):
    # (mode, a, b): pt a = spp; twopass / gather a = photons, b = eye samples per pixel;
    # distributed / whitted a = spp.
    if quick:
        return [("pt", 16, 0), ("pt", 64, 0), ("pt", 256, 0),
                ("twopass", 50000, 4), ("twopass", 200000, 16),
                ("gather", 50000, 4), ("distributed", 16, 0), ("whitted", 4, 0)]
    return ([("pt", n, 0) for n in (16, 64, 256, 1024)]
            + [("twopass", p, n) for p, n in ((50000, 4), (100000, 8), (200000, 16), (500000, 32), (1000000, 64))]
            + [("gather", p, n) for p, n in ((50000, 4), (100000, 8), (200000, 16), (500000, 32), (1000000, 64),
                                            (1000000, 128), (1000000, 256))]
            + [("distributed", n, 0) for n in (4, 16, 64)] + [("whitted", 4, 0)])


LABELS = {"pt": "Path traced", "twopass": "Two-pass (photon map + caustic map)",
          "gather": "Two-pass, final gather", "distributed": "Distributed", "whitted": "Whitted"}


def time_to(points, target=TARGET):
    """First crossing of target by (time, error) points sorted by time, log-log interpolated."""
    pts = sorted(points)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 > target >= e1 and e0 > 0 and e1 > 0:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    if pts and pts[0][1] <= target:
        return pts[0][0]
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(os.path.dirname(HERE), "build"))
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=0, help="seeds per setting (default 3; --quick 1)")
    ap.add_argument("--report", action="store_true", help="only rewrite the tables and plot from results/render_bench.json")
    a = ap.parse_args()
    if a.report:
        with open(os.path.join(a.out, "render_bench.json")) as f:
            return report(json.load(f), a.out)
    exe = os.path.join(a.build, "bench", "render_bench")
    # The reference's own relative RMS error: about 2.2% at 64 x 64 x 32768 (13 minutes on 2 cores).
    w, h, ref_spp, repeats = (32, 32, 4096, 1) if a.quick else (64, 64, 32768, 3)
    repeats = a.repeats or repeats
    refs = os.path.join(a.out, "refs")
    os.makedirs(refs, exist_ok=True)
    stem = os.path.join(refs, "render_ref_%dx%d_%d" % (w, h, ref_spp))
    if os.path.exists(stem + ".pfm") and os.path.exists(stem + ".json"):
        with open(stem + ".json") as f:
            ref = json.load(f)
    else:
        print("reference: %d x %d, %d paths per pixel (once; cached in %s)" % (w, h, ref_spp, refs), flush=True)
        ref = run_json([exe, "reference", str(w), str(h), str(ref_spp), "1000", stem])
        with open(stem + ".json", "w") as f:
            json.dump(ref, f)
    rows = []
    # Round robin: every setting's seed k runs in pass k, so that a load that
    # changes during the run (other jobs on the machine) weighs on every mode alike.
    todo = settings(a.quick)
    runs_of = {st: [] for st in todo}
    for seed in range(1, repeats + 1):
        for mode, x, y in todo:
            r = run_json([exe, "run", str(w), str(h), stem, mode, str(x), str(y), str(seed)])
            r["load_average"] = os.getloadavg()[0]
            runs_of[(mode, x, y)].append(r)
            print("  pass %d: %-12s %8d %4d  %8.2f s  error %.4f (corrected %.4f), load %.1f"
                  % (seed, mode, x, y, r["seconds"], r["relative_rms_error"], r["relative_rms_error_corrected"],
                     r["load_average"]), flush=True)
    for mode, x, y in todo:
        runs = runs_of[(mode, x, y)]
        row = {"mode": mode, "a": x, "b": y, "seconds": median([r["seconds"] for r in runs]),
               "first_pass_seconds": median([r["first_pass_seconds"] for r in runs]),
               "rays": runs[0]["rays"], "error": median([r["relative_rms_error"] for r in runs]),
               "error_corrected": median([r["relative_rms_error_corrected"] for r in runs]),
               "pixels": runs[0]["pixels_measured"], "repeats": repeats,
               "load_average": sum(r["load_average"] for r in runs) / len(runs)}
        rows.append(row)
        print("%-12s %8d %4d  %8.2f s  error %.4f (corrected %.4f)" % (mode, x, y, row["seconds"], row["error"],
                                                                     row["error_corrected"]), flush=True)
    thr = run_json([exe, "throughput", str(w), str(h), "16" if a.quick else "64", "3" if a.quick else "5"])
    report({"width": w, "height": h, "reference": ref, "rows": rows, "throughput": thr, "quick": a.quick,
            "targets": list(TARGETS)}, a.out)


def summary(result):
    rows = result["rows"]
    out = {}
    for target in TARGETS:
        key = "%g" % target
        res = {}
        for mode in LABELS:
            pts = [(r["seconds"], r["error_corrected"]) for r in rows if r["mode"] == mode]
            if not pts:
                continue
            t = time_to(pts, target)
            entry = {"time_to_target": t, "best_error": min(e for _, e in pts), "measured": t is not None}
            if mode == "pt":
                # MSE = c / N: c and the time per path from every run.
                c = median([r["error_corrected"] ** 2 * r["a"] for r in rows if r["mode"] == "pt"])
                per_path = median([r["seconds"] / r["a"] for r in rows if r["mode"] == "pt"])
                n = c / target ** 2
                entry.update({"extrapolated_paths_per_pixel": n, "extrapolated_time_to_target": n * per_path})
                if t is None:
                    entry["time_to_target"] = n * per_path
            res[mode] = entry
        two = [(res[m]["time_to_target"], m) for m in ("twopass", "gather") if m in res and res[m]["time_to_target"]]
        if "pt" in res and two:
            t, m = min(two)
            res["ratio_pt_to_two_pass"] = res["pt"]["time_to_target"] / t
            res["fastest_two_pass"] = m
        out[key] = res
    return out


def report(result, outdir):
    os.makedirs(outdir, exist_ok=True)
    result["summary"] = summary(result)
    with open(os.path.join(outdir, "render_bench.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(outdir, "render_bench.csv"), "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(["mode", "a", "b", "seconds", "first_pass_seconds", "rays", "error", "error_corrected", "pixels", "repeats"])
        for r in result["rows"]:
            wr.writerow([r[k] for k in ("mode", "a", "b", "seconds", "first_pass_seconds", "rays", "error", "error_corrected",
                                        "pixels", "repeats")])
    s, ref, thr = result["summary"], result["reference"], result["throughput"]
    L = ["# Ray-traced view: error versus time (caustic Cornell box with the glossy block)", "",
         "%d x %d pixels; reference: path traced, %d paths per pixel, %.0f s, its own relative RMS error %.2f%%."
         % (result["width"], result["height"], ref["spp"], ref["seconds"], 100 * ref["relative_rms_std_error"]), "",
         "| mode | setting | time (s) | of which first pass | relative RMS error | without the reference's noise | load average |",
         "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        setting = ("%d photons, %d spp" % (r["a"], r["b"])) if r["mode"] in ("twopass", "gather") else "%d spp" % r["a"]
        L.append("| %s | %s | %.2f | %.2f | %.2f%% | %.2f%% | %s |" % (LABELS[r["mode"]], setting, r["seconds"],
                                                                  r["first_pass_seconds"], 100 * r["error"],
                                                                  100 * r["error_corrected"],
                                                                  "%.1f" % r["load_average"] if "load_average" in r else ""))
    for key, res in s.items():
        target = float(key)
        L += ["", "Time to %g%% (corrected error):" % (100 * target), "", "| mode | time to %g%% (s) | best error |" % (100 * target),
              "|---|---|---|"]
        for mode in LABELS:
            if mode not in res:
                continue
            e = res[mode]
            t = e["time_to_target"]
            how = "" if e["measured"] else " (extrapolated: %.0f paths per pixel)" % e["extrapolated_paths_per_pixel"] \
                if "extrapolated_paths_per_pixel" in e else ""
            L.append("| %s | %s%s | %.2f%% |" % (LABELS[mode], "%.1f" % t if t else "not reached", how, 100 * e["best_error"]))
        if "ratio_pt_to_two_pass" in res:
            L += ["", "Path tracing needs %.1f times the time of the faster two-pass variant (%s) to reach %g%%."
                  % (res["ratio_pt_to_two_pass"], LABELS[res["fastest_two_pass"]], 100 * target)]
    L += ["", "Throughput (%d threads; rays per second):" % thr["threads"], "",
          "| rays | bare Embree | ours |", "|---|---|---|",
          "| primary, single rays | %.2f M (rtcIntersect1) | %.2f M |" % (thr["bare_intersect1_primary_rays_per_second"] / 1e6,
                                                                         thr["ours_single_primary_rays_per_second"] / 1e6),
          "| primary, 8-wide packets | %.2f M (rtcIntersect8) | %.2f M |" % (thr["bare_intersect8_primary_rays_per_second"] / 1e6,
                                                                            thr["ours_packet8_primary_rays_per_second"] / 1e6),
          "| primary, stream | | %.2f M (rtcIntersect1M) |" % (thr["ours_stream_primary_rays_per_second"] / 1e6),
          "| secondary (path traced: continuations and shadow rays) | %.2f M (rtcIntersect1 / rtcOccluded1) | %.2f M (with shading and sampling) |"
          % (thr["bare_secondary_rays_per_second"] / 1e6, thr["ours_secondary_rays_per_second"] / 1e6)]
    with open(os.path.join(outdir, "render_bench.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    print("\n".join(L))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(7, 5))
    for mode in LABELS:
        pts = sorted((r["seconds"], r["error_corrected"]) for r in result["rows"] if r["mode"] == mode)
        if pts:
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-4) for p in pts], "o-", label=LABELS[mode])
    for target in TARGETS:
        ax.axhline(target, color="grey", ls="--", lw=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("relative RMS error (reference noise removed)")
    ax.set_title("Ray-traced view, caustic Cornell box with a glossy block")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "render_bench.png"), dpi=110)


if __name__ == "__main__":
    main()
