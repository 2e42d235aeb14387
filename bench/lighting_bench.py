#!/usr/bin/env python3
"""Radiosity and photon mapping: error versus time against the cached
path-traced reference (`gi reference`, docs/design.md: the yardstick), and time /
memory of radiosity against the patch count.

Error: RMS over the non-emitting vertices of (B - B_ref), weighted by vertex
area, relative to the reference's area-weighted mean B. The reference's own
error bars (relative standard error 1% per vertex) are reported beside it.

Also: radiosity with adaptive mesh refinement (error on the input's
vertices, which the refined mesh keeps first and in order); the analytic and
hemicube form factors on the 10k-patch box (full run only); and time / peak
memory of the beyond-budget path (a 1 MB memory budget: progressive
refinement with form-factor rows computed on the fly) against the patch count.

Writes results/lighting_bench.{json,csv,md,png}.
usage: python3 bench/lighting_bench.py [--build build] [--quick]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from plyread import read_ply  # noqa: E402



def reference_arrays(ref):
    """A cached `gi reference` result (gi-result JSON) with its arrays under short names."""
    at = ref["attributes"]
    ref["B"], ref["std_error_B"] = at["Radiosity"]["values"], at["StdError"]["values"]
    ref["samples"] = [int(x) for x in at["Paths"]["values"]]
    return ref

def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError("failed: %s\n%s" % (" ".join(cmd), p.stderr[-2000:]))
    return p.stdout


def run_measured(cmd):
    """Wall time and peak RSS (MB) of one process."""
    t0 = time.perf_counter()
    pid = os.spawnv(os.P_NOWAIT, cmd[0], cmd)
    _, status, usage = os.wait4(pid, 0)
    if status != 0:
        raise RuntimeError("failed: " + " ".join(cmd))
    return time.perf_counter() - t0, usage.ru_maxrss / 1024.0


def vertex_weights(mesh):
    """Vertex areas (a third of each incident face), 0 for emitter vertices;
    and the same restricted to vertices off the sheets' borders (creases,
    mesh borders), where per-vertex values and patch averages legitimately differ."""
    ply = read_ply(mesh)
    v, f = ply["vertex"], ply["face"]
    w = [0.0] * len(v)
    emit = [False] * len(v)
    edges = {}
    for t in f:
        ids = t["vertex_indices"]
        for k in range(3):
            e = (min(ids[k], ids[(k + 1) % 3]), max(ids[k], ids[(k + 1) % 3]))
            edges[e] = edges.get(e, 0) + 1
    border = [False] * len(v)
    for (a, b), n in edges.items():
        if n == 1:
            border[a] = border[b] = True
    for t in f:
        a, b, c = (v[i] for i in t["vertex_indices"])
        u = (b["x"] - a["x"], b["y"] - a["y"], b["z"] - a["z"])
        s = (c["x"] - a["x"], c["y"] - a["y"], c["z"] - a["z"])
        cr = (u[1] * s[2] - u[2] * s[1], u[2] * s[0] - u[0] * s[2], u[0] * s[1] - u[1] * s[0])
        area = 0.5 * math.sqrt(sum(x * x for x in cr))
        for i in t["vertex_indices"]:
            w[i] += area / 3
            if t.get("quality", 0) > 0.5:
                emit[i] = True
    wall = [0.0 if e else x for x, e in zip(w, emit)]
    return wall, [0.0 if b else x for x, b in zip(wall, border)]


def lum(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


class Bench:
    def __init__(self, build, out, repeats):
        self.gi = os.path.join(build, "tools", "gi")
        self.scenes = os.path.join(build, "tools", "gi-scenes")
        self.out, self.repeats = out, repeats
        self.tmp = os.path.join(out, "tmp")
        os.makedirs(self.tmp, exist_ok=True)
        self.rows = []

    def mesh(self, name):
        path = os.path.join(self.tmp, name + ".ply")
        if not os.path.exists(path):
            run([self.scenes, self.tmp, name])
        return path

    def reference(self, mesh, target):
        cache = os.path.join(self.out, "refs")
        os.makedirs(cache, exist_ok=True)
        j = json.loads(run([self.gi, "reference", mesh, "-q", "--json", "--emitter_source", "1", "--cache", cache,
                            "--target_relative_error", str(target), "--min_samples", "64", "--max_samples", "262144"]))
        note = [n for n in j["notes"] if "cached" in n][0]
        path = note.split(" ")[-1]
        with open(path) as f:
            ref = json.load(f)
        ref = reference_arrays(ref)
        B = [lum(ref["B"][3 * i:3 * i + 3]) for i in range(ref["vertices"])]
        return B, ref, path

    def error(self, B, ref, w):
        mean = sum(wi * r for wi, r in zip(w, ref)) / sum(w)
        e2 = sum(wi * (b - r) ** 2 for wi, b, r in zip(w, B, ref)) / sum(w)
        return math.sqrt(e2) / mean

    def noise(self, se, ref, w):
        """The reference's own RMS standard error, relative, with the same weights."""
        mean = sum(wi * r for wi, r in zip(w, ref)) / sum(w)
        return math.sqrt(sum(wi * s * s for wi, s in zip(w, se)) / sum(w)) / mean

    def method(self, scene, mesh, ref, w, label, args, noise=(0.0, 0.0)):
        out = os.path.join(self.tmp, "out.ply")
        times = []
        for _ in range(self.repeats):
            j = json.loads(run([self.gi] + args + [mesh, "-o", out, "-q", "--json", "--emitter_source", "1"]))
            times.append(j["stats"]["seconds"])
        # A refined mesh keeps the input's vertices first, in order.
        B = [r["quality"] for r in read_ply(out)["vertex"]][:len(ref)]
        row = {"scene": scene, "method": label, "args": " ".join(args[1:]), "seconds": sorted(times)[len(times) // 2],
               "relative_rms_error": self.error(B, ref, w[0]), "relative_rms_error_interior": self.error(B, ref, w[1])}
        # Without the reference's own noise (independent errors add in quadrature).
        row["interior_error_minus_reference_noise"] = math.sqrt(max(0.0, row["relative_rms_error_interior"] ** 2 - noise[1] ** 2))
        self.rows.append(row)
        print("%-16s %-34s %-28s %8.3f s  rel. RMS %.4f (interior %.4f)" % (
            scene, label, row["args"], row["seconds"], row["relative_rms_error"], row["relative_rms_error_interior"]),
            flush=True)


def plot(rows, refinfo, scenes, path):
    """Error versus time per scene; one colour per method in every panel."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    methods = sorted({r["method"] for r in rows})
    colour = {m: "C%d" % (i % 10) for i, m in enumerate(methods)}
    marker = {m: "os^vD"[i // 10] for i, m in enumerate(methods)}
    fig, axes = plt.subplots(1, len(scenes), figsize=(6.5 * len(scenes), 5.2))
    axes = axes if len(scenes) > 1 else [axes]
    for ax, scene in zip(axes, scenes):
        for m in methods:
            pts = sorted((r["seconds"], r["relative_rms_error_interior"]) for r in rows if r["scene"] == scene and r["method"] == m)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker[m] + "-", color=colour[m], label=m)
        ax.axhline(refinfo[scene]["relative_noise_interior"], color="grey", ls="--", lw=0.7,
                   label="the reference's own noise")
        ax.set_title(scene)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("relative RMS error vs path-traced reference (interior vertices)")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def large(a):
    """The 100k-patch Cornell box: error and time of the Monte Carlo form factors (the n^2 methods would take
    about 25 minutes a run here) against a path-traced reference of 2% per vertex."""
    b = Bench(a.build, a.out, 1)
    mesh = b.mesh("cornell_box_100k")
    ref, refjson, refpath = b.reference(mesh, 0.02)
    w = vertex_weights(mesh)
    noise = (b.noise(refjson["std_error_B"], ref, w[0]), b.noise(refjson["std_error_B"], ref, w[1]))
    print("reference cornell_100k: %s (%.1f s), noise interior %.4f" % (refpath, refjson["seconds"], noise[1]), flush=True)
    for solver in ["Gauss-Seidel", "Jacobi"]:
        for rays, light, gather in [(256, 256, 256), (1024, 1024, 512)]:
            b.method("cornell_100k", mesh, ref, w, "radiosity, " + solver,
                     ["radiosity", "--solver", solver, "--rays_per_patch", str(rays), "--light_samples", str(light),
                      "--gather_rays", str(gather)], noise)
    info = {"file": os.path.relpath(refpath, ROOT), "seconds": refjson["seconds"], "relative_noise_interior": noise[1],
            "relative_noise_all": noise[0]}
    with open(os.path.join(a.out, "lighting_bench_100k.json"), "w") as f:
        json.dump({"rows": b.rows, "reference": info}, f, indent=1)
    lines = ["| method | settings | time (s) | rel. RMS error, all vertices | interior | interior minus reference noise |",
             "|---|---|---|---|---|---|"]
    for r in b.rows:
        lines.append("| %s | %s | %.2f | %.4f | %.4f | %.4f |" % (r["method"], r["args"], r["seconds"], r["relative_rms_error"],
                                                              r["relative_rms_error_interior"],
                                                              r["interior_error_minus_reference_noise"]))
    lines.append("reference: %s, %.1f s, interior noise %.4f" % (info["file"], info["seconds"], noise[1]))
    with open(os.path.join(a.out, "lighting_bench_100k.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--replot", action="store_true", help="only redraw the plot from results/lighting_bench.json")
    ap.add_argument("--large", action="store_true",
                    help="only the 100k-patch box: a 2%% reference, Gauss-Seidel and Jacobi at two settings "
                         "(results/lighting_bench_100k.{json,md})")
    a = ap.parse_args()
    if a.large:
        large(a)
        return
    if a.replot:
        with open(os.path.join(a.out, "lighting_bench.json")) as f:
            r = json.load(f)
        plot(r["rows"], r["references"], list(r["references"]), os.path.join(a.out, "lighting_bench.png"))
        return
    os.makedirs(a.out, exist_ok=True)
    b = Bench(a.build, a.out, 1 if a.quick else 3)
    scenes = {"cornell_1.5k": "cornell_box"} if a.quick else {"cornell_1.5k": "cornell_box", "cornell_10k": "cornell_box_10k"}
    refinfo = {}
    for scene, name in scenes.items():
        mesh = b.mesh(name)
        t0 = time.perf_counter()
        ref, refjson, refpath = b.reference(mesh, 0.02 if a.quick else 0.01)
        rel = [s / max(x, 1e-12) for s, x in zip(refjson["std_error_B"], ref)]
        refinfo[scene] = {"file": os.path.relpath(refpath, ROOT), "seconds": refjson["seconds"],
                          "paths": sum(refjson["samples"]), "mean_relative_std_error": sum(rel) / len(rel),
                          "wall_seconds_this_run": time.perf_counter() - t0}
        print("reference %s: %s (%.1f s, mean relative standard error %.4f)" % (
            scene, refinfo[scene]["file"], refjson["seconds"], refinfo[scene]["mean_relative_std_error"]), flush=True)
        w = vertex_weights(mesh)
        noise = (b.noise(refjson["std_error_B"], ref, w[0]), b.noise(refjson["std_error_B"], ref, w[1]))
        refinfo[scene]["relative_noise_all"], refinfo[scene]["relative_noise_interior"] = noise
        # (form-factor rays per patch, shadow rays per vertex/patch, final-gather rays per vertex)
        configs = [(64, 64, 64), (1024, 1024, 512)] if a.quick else [(64, 64, 64), (256, 256, 256), (1024, 1024, 512),
                                                                      (4096, 2048, 1024)]
        for solver in ["Jacobi", "Gauss-Seidel", "Progressive refinement"]:
            for rays, light, gather in configs:
                b.method(scene, mesh, ref, w, "radiosity, " + solver,
                         ["radiosity", "--solver", solver, "--rays_per_patch", str(rays), "--light_samples", str(light),
                          "--gather_rays", str(gather)], noise)
        if scene == "cornell_1.5k":
            for depth in ([1] if a.quick else [1, 2, 3]):
                b.method(scene, mesh, ref, w, "radiosity, adaptive refinement",
                         ["radiosity", "--refine", "true", "--refine_max_depth", str(depth), "--light_samples", "1024",
                          "--gather_rays", "512"], noise)
        if scene == "cornell_10k":  # n^2 methods at 10k patches: fewer settings
            for pts in [1, 4]:
                b.method(scene, mesh, ref, w, "radiosity, analytic point-to-polygon",
                         ["radiosity", "--form_factor_method", "Analytic point-to-polygon", "--analytic_points", str(pts),
                          "--light_samples", "1024", "--gather_rays", "512"], noise)
            for res in [64, 128]:
                b.method(scene, mesh, ref, w, "radiosity, hemicube",
                         ["radiosity", "--form_factor_method", "Hemicube", "--hemicube_resolution", str(res),
                          "--light_samples", "1024", "--gather_rays", "512"], noise)
        if scene == "cornell_1.5k":  # n^2 methods: the small box only
            for pts in ([4] if a.quick else [1, 4, 16]):
                b.method(scene, mesh, ref, w, "radiosity, analytic point-to-polygon",
                         ["radiosity", "--form_factor_method", "Analytic point-to-polygon", "--analytic_points", str(pts),
                          "--light_samples", "1024", "--gather_rays", "512"], noise)
            for res in ([64] if a.quick else [64, 128, 256]):
                b.method(scene, mesh, ref, w, "radiosity, hemicube",
                         ["radiosity", "--form_factor_method", "Hemicube", "--hemicube_resolution", str(res),
                          "--light_samples", "1024", "--gather_rays", "512"], noise)
        for photons in ([100000, 1000000] if a.quick else [100000, 300000, 1000000, 3000000]):
            b.method(scene, mesh, ref, w, "photon mapping, photons only (k=100)",
                     ["photonmap", "--photons", str(photons), "--k_nearest", "100", "--direct_light", "false"], noise)
            b.method(scene, mesh, ref, w, "photon mapping, direct apart (k=100)",
                     ["photonmap", "--photons", str(photons), "--k_nearest", "100", "--light_samples", "1024"], noise)
            if scene != "cornell_1.5k":
                continue  # the final gather's k-nearest lookups per ray: the small box only
            b.method(scene, mesh, ref, w, "photon mapping, final gather (k=100, 256 rays)",
                     ["photonmap", "--photons", str(photons), "--k_nearest", "100", "--light_samples", "1024",
                      "--final_gather", "true", "--gather_rays", "256"], noise)
    # Time and memory against the patch count (Gauss-Seidel, 1024 rays per patch).
    sizes = ["cornell_box", "cornell_box_10k"] + ([] if a.quick else ["cornell_box_100k"])
    scaling = []
    for name in sizes:
        mesh = b.mesh(name)
        patches = read_ply(mesh)["face"]
        wall, rss = run_measured([b.gi, "radiosity", mesh, "-q", "--emitter_source", "1", "--rays_per_patch", "1024",
                                  "-o", os.path.join(b.tmp, "s.ply")])
        # Beyond the budget: progressive refinement, rows on the fly (memory linear in patches). The budget
        # holds everything but the matrix (the solver's estimate: 400 bytes per patch and a row per thread).
        budget = str(math.ceil(len(patches) * 600 / 1048576) + 1)
        wall_b, rss_b = run_measured([b.gi, "radiosity", mesh, "-q", "--emitter_source", "1", "--rays_per_patch", "1024",
                                      "--memory_budget_mb", budget, "-o", os.path.join(b.tmp, "s.ply")])
        scaling.append({"patches": len(patches), "wall_seconds": wall, "peak_rss_mb": rss,
                        "beyond_budget_wall_seconds": wall_b, "beyond_budget_peak_rss_mb": rss_b})
        print("scaling: %7d patches  %7.2f s  %7.1f MB; beyond the budget (rows on the fly) %7.2f s  %7.1f MB" % (
            len(patches), wall, rss, wall_b, rss_b), flush=True)
    xs = [math.log(r["patches"]) for r in scaling]
    def slope(key):
        ys = [math.log(r[key]) for r in scaling]
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    result = {"rows": b.rows, "references": refinfo, "scaling": scaling,
              "scaling_time_slope": slope("wall_seconds"), "scaling_memory_slope": slope("peak_rss_mb"),
              "beyond_budget_time_slope": slope("beyond_budget_wall_seconds"),
              "beyond_budget_memory_slope": slope("beyond_budget_peak_rss_mb")}
    with open(os.path.join(a.out, "lighting_bench.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(a.out, "lighting_bench.csv"), "w", newline="") as f:
        wr = csv.DictWriter(f, fieldnames=list(b.rows[0].keys()))
        wr.writeheader()
        wr.writerows(b.rows)
    lines = ["| scene | method | settings | time (s) | rel. RMS error, all vertices | interior | interior minus reference noise |",
             "|---|---|---|---|---|---|---|"]
    for r in b.rows:
        lines.append("| %s | %s | %s | %.3f | %.4f | %.4f | %.4f |" % (
            r["scene"], r["method"], r["args"], r["seconds"], r["relative_rms_error"], r["relative_rms_error_interior"],
            r["interior_error_minus_reference_noise"]))
    lines += ["", "| patches | time (s) | peak RSS (MB) | beyond budget: time (s) | peak RSS (MB) |", "|---|---|---|---|---|"]
    for r in scaling:
        lines.append("| %d | %.2f | %.1f | %.2f | %.1f |" % (r["patches"], r["wall_seconds"], r["peak_rss_mb"],
                                                         r["beyond_budget_wall_seconds"], r["beyond_budget_peak_rss_mb"]))
    lines.append("")
    lines.append("log-log slopes against patches: time %.2f, memory %.2f; beyond the budget: time %.2f, memory %.2f" % (
        result["scaling_time_slope"], result["scaling_memory_slope"], result["beyond_budget_time_slope"],
        result["beyond_budget_memory_slope"]))
    for s, info in refinfo.items():
        lines.append("reference %s: %d paths, %.1f s, mean relative standard error %.4f (%s)" % (
            s, info["paths"], info["seconds"], info["mean_relative_std_error"], info["file"]))
    with open(os.path.join(a.out, "lighting_bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    plot(b.rows, refinfo, list(scenes), os.path.join(a.out, "lighting_bench.png"))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
