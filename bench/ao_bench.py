#!/usr/bin/env python3
"""Ambient occlusion benchmark: error versus time, ours against MeshLab's own
"Ambient Occlusion" filter (depth maps, CPU mode), in the same run.

For each scene a converged reference (our estimator, 16384 rays per vertex,
another seed) is computed once and cached. Then:
  - ours through the CLI (`gi ao`) at several ray counts,
  - ours through the staged meshlabserver (`GI: Ambient Occlusion`),
  - MeshLab's "Ambient Occlusion" through meshlabserver at several reqViews
    (its values are x4 to compare: it averages V max(0, n.d) over directions
    spread on the whole sphere, so an open vertex scores 0.25),
each repeated, median time taken. Times are the filter's own (from its log
line), so meshlabserver start-up and file IO do not count; wall times are
kept too. Also: rays per second against a bare Embree loop (ao_throughput),
and time / peak memory of the CLI on 10k..1M-triangle meshes.

Writes results/ao_bench.{json,csv,md,png}.
usage: python3 bench/ao_bench.py [--build build] [--quick]
"""
import argparse
import csv
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from plyread import read_ply  # noqa: E402

MESHLAB_AO_SCRIPT = """<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="Ambient Occlusion">
  <Param type="RichEnum" value="0" enum_cardinality="2" enum_val0="per-Vertex" enum_val1="per-Face (deprecated)" name="occMode"/>
  <Param type="RichFloat" value="0" name="dirBias"/>
  <Param type="RichInt" value="{views}" name="reqViews"/>
  <Param type="RichPoint3f" x="0" y="1" z="0" name="coneDir"/>
  <Param type="RichFloat" value="30" name="coneAngle"/>
  <Param type="RichBool" value="false" name="useGPU"/>
  <Param type="RichInt" value="{tex}" name="depthTexSize"/>
 </filter>
</FilterScript>
"""


def quality(path):
    return [r["quality"] for r in read_ply(path)["vertex"]]


def rms(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / len(a))


def run(cmd, timeout=1800):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
    wall = time.perf_counter() - t0
    out = p.stdout.decode("utf-8", "replace")
    if p.returncode != 0:
        raise RuntimeError("command failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), out[-2000:]))
    return out, wall


class Bench:
    def __init__(self, build, results, repeats):
        self.build, self.results, self.repeats = build, results, repeats
        self.gi = os.path.join(build, "tools", "gi")
        self.mlx = os.path.join(build, "mlx-run")
        self.tmp = tempfile.mkdtemp(prefix="ao_bench_")
        self.rows = []

    def reference(self, mesh, rays=16384):
        name = os.path.splitext(os.path.basename(mesh))[0]
        st = os.stat(mesh)
        path = os.path.join(self.results, "ref_%s_%d.json" % (name, rays))
        key = "%d-%d" % (st.st_size, int(st.st_mtime))
        if os.path.exists(path):
            with open(path) as f:
                ref = json.load(f)
            if ref.get("key") == key:
                return ref["quality"]
        out = os.path.join(self.tmp, "ref.ply")
        text, wall = run([self.gi, "ao", mesh, "-o", out, "-q", "--json", "--rays_per_vertex", str(rays), "--seed", "987654"])
        q = quality(out)
        with open(path, "w") as f:
            json.dump({"key": key, "rays_per_vertex": rays, "seconds": wall, "quality": q,
                       "rms_error_estimate": json.loads(text)["stats"]["rms_error_estimate"]}, f)
        return q

    def cross_check(self, scene, mesh, ref, spp=1024):
        """Our AO reference against the independent path tracer (`gi reference`, cached): a uniform white sky of
        irradiance 1, black surfaces, no bounce, so its irradiance H is the AO. Returns the RMS of the z-scores
        (about 1 when the two agree within the path tracer's honest error bars) and the RMS difference."""
        cache = os.path.join(self.results, "refs")
        os.makedirs(cache, exist_ok=True)
        text, _ = run([self.gi, "reference", mesh, "-q", "--json", "--cache", cache, "--emitter_source", "None",
                       "--reflectance_source", "Constant", "--reflectance", "0,0,0", "--sky_irradiance", "1",
                       "--max_depth", "0", "--samples_per_vertex", str(spp)])
        note = [n for n in json.loads(text)["notes"] if "cached" in n][0]
        with open(note.split(" ")[-1]) as f:
            pt = json.load(f)
        H = [pt["H"][3 * i + 1] for i in range(pt["vertices"])]
        se = pt["std_error_H"]
        z = [(a - h) / s for a, h, s in zip(ref, H, se) if s > 0]
        out = {"scene": scene, "path_tracer_paths_per_vertex": spp, "rms_z": math.sqrt(sum(x * x for x in z) / len(z)),
               "rms_difference": rms(ref, H), "cached_file": os.path.relpath(note.split(" ")[-1], ROOT)}
        print("cross-check %s: our AO reference vs the path tracer: RMS z %.3f, RMS difference %.4f" % (
            scene, out["rms_z"], out["rms_difference"]), flush=True)
        return out

    def ours_cli(self, scene, mesh, ref, rays_list):
        for n in rays_list:
            times, walls = [], []
            for _ in range(self.repeats):
                out = os.path.join(self.tmp, "cli.ply")
                text, wall = run([self.gi, "ao", mesh, "-o", out, "-q", "--json", "--rays_per_vertex", str(n), "--seed", "1"])
                times.append(json.loads(text)["stats"]["seconds"])
                walls.append(wall)
            self.add(scene, "ours (CLI)", "rays_per_vertex", n, statistics.median(times), statistics.median(walls),
                     rms(quality(out), ref))

    def ours_server(self, scene, mesh, ref, rays_list):
        for n in rays_list:
            script = os.path.join(self.tmp, "ours.mlx")
            run([self.gi, "script", "ao", "--mesh", mesh, "-o", script, "--rays_per_vertex", str(n), "--seed", "1"])
            times, walls = [], []
            for _ in range(self.repeats):
                out = os.path.join(self.tmp, "srv.ply")
                text, wall = run([self.mlx, "-i", mesh, "-o", out, "-m", "vq", "-s", script])
                m = re.search(r"GI: Ambient Occlusion: .*?seconds=([0-9.e+-]+)", text)
                times.append(float(m.group(1)))
                walls.append(wall)
            self.add(scene, "ours (meshlabserver)", "rays_per_vertex", n, statistics.median(times),
                     statistics.median(walls), rms(quality(out), ref))

    def meshlab_ao(self, scene, mesh, ref, views_list, tex=512):
        for v in views_list:
            script = os.path.join(self.tmp, "mlao.mlx")
            with open(script, "w") as f:
                f.write(MESHLAB_AO_SCRIPT.format(views=v, tex=tex))
            times, walls = [], []
            for _ in range(self.repeats):
                out = os.path.join(self.tmp, "mlao.ply")
                text, wall = run([self.mlx, "-i", mesh, "-o", out, "-m", "vq", "-s", script])
                m = re.search(r"Successfully calculated A\.O\. after ([0-9.]+) sec", text)
                times.append(float(m.group(1)) if m else float("nan"))
                walls.append(wall)
            q = [4.0 * x for x in quality(out)]
            self.add(scene, "MeshLab Ambient Occlusion (CPU, depth %d)" % tex, "reqViews", v,
                     statistics.median(times), statistics.median(walls), rms(q, ref))

    def add(self, scene, method, knob, value, seconds, wall, err):
        row = {"scene": scene, "method": method, "knob": knob, "value": value, "filter_seconds": seconds,
               "wall_seconds": wall, "rms_error": err}
        self.rows.append(row)
        print("%-14s %-44s %s=%-6d %8.4f s (wall %6.2f s)  RMS %.5f" % (scene, method, knob, value, seconds, wall, err),
              flush=True)


def time_to_reach(rows, target):
    """Time at which RMS error first reaches `target` (log-log interpolation), or None."""
    pts = sorted((r["filter_seconds"], r["rms_error"]) for r in rows)
    best = None
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 > 0 and e1 > 0 and t0 > 0 and t1 > 0 and e0 != e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            best = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
            break
    if best is None and pts and pts[0][1] <= target:
        best = pts[0][0]  # already below the target at the cheapest setting
    return best


def terrain(path, n):
    """A bumpy n x n heightfield (2 n^2 triangles) as binary PLY."""
    import struct
    verts = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = i / n, j / n
            z = 0.08 * math.sin(11 * x) * math.cos(7 * y) + 0.05 * math.sin(31 * x + 17 * y)
            verts.append((x, y, z))
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(verts), 2 * n * n)).encode())
        f.write(b"".join(struct.pack("<3f", *v) for v in verts))
        w = n + 1
        buf = bytearray()
        for j in range(n):
            for i in range(n):
                a = j * w + i
                buf += struct.pack("<B3i", 3, a, a + 1, a + w + 1)
                buf += struct.pack("<B3i", 3, a, a + w + 1, a + w)
        f.write(buf)


def subdivided(src, dst, levels):
    """Midpoint (1-to-4) subdivision, flat: the same surface with more vertices."""
    import struct
    ply = read_ply(src)
    verts = [(r["x"], r["y"], r["z"]) for r in ply["vertex"]]
    faces = [tuple(r["vertex_indices"]) for r in ply["face"]]
    for _ in range(levels):
        mid = {}
        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                mid[k] = len(verts)
                verts.append(tuple((p + q) / 2 for p, q in zip(verts[a], verts[b])))
            return mid[k]
        nf = []
        for a, b, c in faces:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        faces = nf
    with open(dst, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                 "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
                 % (len(verts), len(faces))).encode())
        f.write(b"".join(struct.pack("<3f", *v) for v in verts))
        f.write(b"".join(struct.pack("<B3i", 3, *t) for t in faces))


def scaling(b, sizes, rays):
    rows = []
    for n in sizes:
        path = os.path.join(b.tmp, "terrain_%d.ply" % n)
        terrain(path, n)
        out = os.path.join(b.tmp, "terrain_out.ply")
        t0 = time.perf_counter()
        pid = os.spawnv(os.P_NOWAIT, b.gi, [b.gi, "ao", path, "-o", out, "-q", "--rays_per_vertex", str(rays)])
        _, status, usage = os.wait4(pid, 0)
        wall = time.perf_counter() - t0
        if status != 0:
            raise RuntimeError("gi ao failed on %s" % path)
        rows.append({"triangles": 2 * n * n, "vertices": (n + 1) ** 2, "rays_per_vertex": rays, "wall_seconds": wall,
                     "peak_rss_mb": usage.ru_maxrss / 1024.0})
        print("scaling: %8d triangles  %7.2f s  peak RSS %7.1f MB" % (2 * n * n, wall, usage.ru_maxrss / 1024.0), flush=True)
    def slope(key):
        xs = [math.log(r["triangles"]) for r in rows]
        ys = [math.log(r[key]) for r in rows]
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return {"rows": rows, "time_loglog_slope": slope("wall_seconds"), "memory_loglog_slope": slope("peak_rss_mb")}


def plot(rows, scenes, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4))
    if len(scenes) == 1:
        axes = [axes]
    for ax, scene in zip(axes, scenes):
        for method in sorted({r["method"] for r in rows if r["scene"] == scene}):
            pts = sorted((r["filter_seconds"], r["rms_error"]) for r in rows if r["scene"] == scene and r["method"] == method)
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=method)
        for t in (0.01, 0.005):
            ax.axhline(t, color="grey", lw=0.6, ls="--")
        ax.set_title(scene)
        ax.set_xlabel("filter time (s)")
        ax.set_ylabel("RMS error vs converged reference")
        ax.grid(True, which="both", lw=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--quick", action="store_true", help="fewer settings and repeats (a smoke run)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    repeats = 1 if a.quick else 3
    b = Bench(a.build, a.out, repeats)
    meshes = os.path.join(ROOT, "test_meshes")
    fine = os.path.join(a.out, "bunny_fine.ply")
    if not os.path.exists(fine):
        subdivided(os.path.join(meshes, "bunny.ply"), fine, 2)  # 29,394 vertices, like the 37k-vertex Stanford bunny
    scenes = {"bunny_fine": fine, "bunny": os.path.join(meshes, "bunny.ply"),
              "cylinder_hole": os.path.join(meshes, "cylinder_hole.ply"), "floor_wall": os.path.join(meshes, "floor_wall.ply")}
    rays = [16, 64, 256, 1024] if a.quick else [8, 16, 32, 64, 128, 256, 512, 1024, 2048]
    server_rays = [16, 256] if a.quick else [16, 64, 256, 1024]
    views = [16, 64] if a.quick else [8, 16, 32, 64, 128, 256, 512, 1024]
    checks = []
    for scene, mesh in scenes.items():
        ref = b.reference(mesh, 4096 if a.quick else 16384)
        checks.append(b.cross_check(scene, mesh, ref, 256 if a.quick else 1024))
        b.ours_cli(scene, mesh, ref, rays)
        b.ours_server(scene, mesh, ref, server_rays)
        b.meshlab_ao(scene, mesh, ref, views)
        if not a.quick:
            b.meshlab_ao(scene, mesh, ref, [128, 512], tex=2048)
    summary = []
    for scene in scenes:
        ours = [r for r in b.rows if r["scene"] == scene and r["method"] == "ours (CLI)"]
        ml = [r for r in b.rows if r["scene"] == scene and r["method"].startswith("MeshLab")]
        best = min(ml, key=lambda r: r["rms_error"])
        for target in (0.01, 0.005, best["rms_error"]):
            to, tm = time_to_reach(ours, target), time_to_reach(ml, target)
            if target == best["rms_error"]:
                tm = min(r["filter_seconds"] for r in ml if r["rms_error"] <= target * 1.000001)
            summary.append({"scene": scene, "target_rms": target, "ours_seconds": to, "meshlab_seconds": tm,
                            "speedup": (tm / to) if (to and tm) else None,
                            "meshlab_best_rms": best["rms_error"],
                            "at_meshlab_best": target == best["rms_error"]})
    throughput = {}
    for scene, mesh in scenes.items():
        text, _ = run([os.path.join(a.build, "bench", "ao_throughput"), mesh, "256", "3" if a.quick else "7"])
        throughput[scene] = json.loads(text)
    scale = scaling(b, [70, 224, 708] if not a.quick else [70, 224], 64)
    result = {"rows": b.rows, "summary": summary, "throughput": throughput, "scaling": scale, "reference_cross_check": checks,
              "machine": {"cpus": os.cpu_count()}}
    with open(os.path.join(a.out, "ao_bench.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(a.out, "ao_bench.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(b.rows[0].keys()))
        w.writeheader()
        w.writerows(b.rows)
    fmt = lambda x: "never (best %.4f)" if x is None else "%.3f s" % x
    lines = ["| scene | target RMS | ours (CLI) | MeshLab AO | speed-up |", "|---|---|---|---|---|"]
    for s in summary:
        lines.append("| %s | %s | %s | %s | %s |" % (
            s["scene"], ("%.4f (MeshLab's best)" % s["target_rms"]) if s["at_meshlab_best"] else "%.3f" % s["target_rms"], "n/a" if s["ours_seconds"] is None else "%.3f s" % s["ours_seconds"],
            ("not reached (best %.4f)" % s["meshlab_best_rms"]) if s["meshlab_seconds"] is None else "%.3f s" % s["meshlab_seconds"],
            "%.0fx" % s["speedup"] if s["speedup"] else "-"))
    lines += ["", "| scene | bare Embree rays/s | bare robust rays/s | ours rays/s | ours / bare | ours / bare robust |",
              "|---|---|---|---|---|---|"]
    for scene, t in throughput.items():
        lines.append("| %s | %.3g | %.3g | %.3g | %.2f | %.2f |" % (
            scene, t["bare_embree_occluded1_rays_per_second"], t["bare_embree_robust_occluded1_rays_per_second"],
            t["ours_single_rays_per_second"], t["ratio_ours_single_to_bare"], t["ratio_ours_single_to_bare_robust"]))
    lines += ["", "| triangles | time (s) | peak RSS (MB) |", "|---|---|---|"]
    for r in scale["rows"]:
        lines.append("| %d | %.2f | %.1f |" % (r["triangles"], r["wall_seconds"], r["peak_rss_mb"]))
    lines.append("")
    lines.append("log-log slopes against triangle count: time %.2f, memory %.2f" % (scale["time_loglog_slope"], scale["memory_loglog_slope"]))
    lines += ["", "| scene | path tracer paths | RMS z-score (ours vs path tracer) | RMS difference |", "|---|---|---|---|"]
    for c in checks:
        lines.append("| %s | %d | %.3f | %.4f |" % (c["scene"], c["path_tracer_paths_per_vertex"], c["rms_z"], c["rms_difference"]))
    with open(os.path.join(a.out, "ao_bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    plot(b.rows, list(scenes), os.path.join(a.out, "ao_bench.png"))
    print("\n".join(lines))
    print("wrote %s/ao_bench.{json,csv,md,png}" % a.out)


if __name__ == "__main__":
    main()
