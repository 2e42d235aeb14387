#!/usr/bin/env python3
"""Ambient occlusion benchmark: error versus time, ours against MeshLab's own
"Ambient Occlusion" filter (depth maps, CPU mode), in the same run, on meshes
of 1.8k to 1.9M vertices.

Scenes: the npm bunny (1,839 vertices), its flat 2x midpoint subdivision
(29,394), three generated scans (`gi-scenes scan`: the bunny Loop-subdivided
3, 4 and 5 times and displaced by gradient noise: 117,570, 470,274 and
1,881,090 vertices), and two open scenes (a cylinder hole, a floor by a wall).

Each method is measured against a reference with its own vertex normals:
ours computes angle-weighted normals, MeshLab's filter recomputes
area-weighted ones (vcglib PerVertexNormalizedPerFaceNormalized), and AO
depends on the normal. A reference is the mean of two independent runs of our
per-vertex estimator (bench/ao_reference, seeds A and B); its own RMS error
is RMS(A - B) / 2, and it is removed from each method's measured RMS in
quadrature (reported beside the raw value).

Methods (filter time = the filter's own log time, loading and saving
excluded; ours adds its BVH build):
  - ours through the CLI, per-vertex estimator, over ray counts;
  - ours, the shared estimator (neighbours' rays pooled), over ray counts and
    adaptive targets; one setting also through meshlabserver;
  - MeshLab's "Ambient Occlusion" (CPU) at 512 and 1024 views with depth maps
    of 512^2 and 2048^2 (and a sweep of views on the small meshes), values x4.
Times are medians of 3 on meshes below 50k vertices, single runs above.
Results are cached (results/ao_cache.json: MeshLab runs by mesh, ours by
mesh and binary), so a rerun after a rebuild recomputes only ours.

Writes results/ao_bench.{json,csv,md,png} and ao_speedup.png.
usage: /usr/bin/python3 bench/ao_bench.py [--build build] [--quick] [--sizes small|large|all]
"""
import argparse
import csv
import fcntl
import hashlib
import json
import math
import os
import re
import select
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "integration"))
from plyread import read_ply  # noqa: E402
from ao_report import OURS, plot, speedup_table  # noqa: E402

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

LARGE = 50000  # vertices: single runs above, medians of 3 below

_PLY_TYPES = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "<i2", "ushort": "<u2",
              "int16": "<i2", "uint16": "<u2", "int": "<i4", "uint": "<u4", "int32": "<i4", "uint32": "<u4",
              "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8"}


def vertex_property(path, name):
    """One vertex property of a binary little-endian PLY whose vertex element comes first, as float64."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    while data[end:end + 1] in (b"\r", b"\n"):
        end += 1
    header = data[:end].decode("ascii", "replace").splitlines()
    if "binary_little_endian" not in header[1]:
        return np.array([r[name] for r in read_ply(path)["vertex"]], dtype=np.float64)
    fields, count, in_vertex = [], 0, False
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "element":
            in_vertex = w[1] == "vertex"
            if in_vertex:
                count = int(w[2])
            elif fields:
                break
        elif w[0] == "property" and in_vertex:
            fields.append((w[2], _PLY_TYPES[w[1]]))
    rec = np.frombuffer(data, dtype=np.dtype(fields), count=count, offset=end)
    return rec[name].astype(np.float64)


def run(cmd, timeout=7200, log=None):
    """Runs cmd, returns (output, wall seconds); raises on a non-zero exit. With `log`, the output is also written
    there as it comes, each chunk stamped with the seconds since the start: MeshLab's progress per view can be read
    there while it runs (or after it was stopped)."""
    t0 = time.perf_counter()
    if log is None:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        returncode, out = p.returncode, p.stdout.decode("utf-8", "replace")
    else:
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        chunks = []
        with open(log, "a") as f:
            f.write("\n=== %s: %s\n" % (time.strftime("%Y-%m-%d %H:%M:%S"), " ".join(cmd)))
            while True:
                if time.perf_counter() - t0 > timeout:
                    p.kill()
                    raise RuntimeError("command timed out: %s" % " ".join(cmd))
                ready, _, _ = select.select([p.stdout], [], [], 5.0)
                if not ready:
                    continue
                data = os.read(p.stdout.fileno(), 65536)
                if not data:
                    break
                chunks.append(data)
                f.write("[%9.2f s] %s\n" % (time.perf_counter() - t0, data.decode("utf-8", "replace").rstrip()))
                f.flush()
        returncode, out = p.wait(), b"".join(chunks).decode("utf-8", "replace")
    wall = time.perf_counter() - t0
    if returncode != 0:
        raise RuntimeError("command failed (%d): %s\n%s" % (returncode, " ".join(cmd), out[-2000:]))
    return out, wall


def load_average():
    try:
        with open("/proc/loadavg") as f:
            return [float(x) for x in f.read().split()[:3]]
    except OSError:
        return None


def signature(path):
    st = os.stat(path)
    return "%d-%d" % (st.st_size, int(st.st_mtime))


class Bench:
    def __init__(self, build, results, quick):
        self.build, self.results, self.quick = build, results, quick
        self.gi = os.path.join(build, "tools", "gi")
        self.mlx = os.path.join(build, "mlx-run")
        self.aoref = os.path.join(build, "bench", "ao_reference")
        self.tmp = tempfile.mkdtemp(prefix="ao_bench_")
        self.rows = []
        self.cache_path = os.path.join(results, "ao_cache.json")
        self.cache = {}
        if os.path.exists(self.cache_path):
            with open(self.cache_path) as f:
                self.cache = json.load(f)
        self.ours_sig = signature(self.gi)

    def save_cache(self):
        """Merges this run's entries into the file under a lock, so that runs on different meshes (one per
        process, e.g. MeshLab on two large scans) can fill the same cache side by side."""
        with open(self.cache_path + ".lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            disk = {}
            if os.path.exists(self.cache_path):
                with open(self.cache_path) as f:
                    disk = json.load(f)
            disk.update(self.cache)
            self.cache = disk
            tmp = "%s.%d.tmp" % (self.cache_path, os.getpid())
            with open(tmp, "w") as f:
                json.dump(self.cache, f)
            os.replace(tmp, self.cache_path)

    def reference(self, scene, mesh, normals, rays):
        """Mean of two independent per-vertex runs (seeds 987654 and 987655) and its own RMS error."""
        runs = []
        for seed in (987654, 987655):
            path = os.path.join(self.results, "ref_%s_%s_%d_%d.npy" % (scene, normals, rays, seed))
            meta = path[:-4] + ".json"
            if os.path.exists(path) and os.path.exists(meta):
                with open(meta) as f:
                    if json.load(f).get("mesh") == signature(mesh):
                        runs.append(np.load(path))
                        continue
            out = os.path.join(self.tmp, "ref.ply")
            text, wall = run([self.aoref, mesh, out, str(rays), str(seed), normals])
            q = vertex_property(out, "quality")
            np.save(path, q)
            with open(meta, "w") as f:
                json.dump({"mesh": signature(mesh), "wall_seconds": wall, "stats": json.loads(text)}, f)
            runs.append(q)
            print("reference %s (%s normals, %d rays, seed %d): %.1f s" % (scene, normals, rays, seed, wall), flush=True)
        a, b = runs
        noise = float(np.sqrt(np.mean((a - b) ** 2)) / 2)
        return {"q": (a + b) / 2, "noise": noise, "rays": rays}

    def cross_check(self, scene, mesh, ref, spp):
        """The reference against the independent path tracer (`gi reference`, cached): a uniform white sky of
        irradiance 1, black surfaces, no bounce, so its irradiance H is the AO. Returns the RMS of the z-scores
        (about 1 when the two agree within the path tracer's error bars)."""
        cache = os.path.join(self.results, "refs")
        os.makedirs(cache, exist_ok=True)
        text, _ = run([self.gi, "reference", mesh, "-q", "--json", "--cache", cache, "--emitter_source", "None",
                       "--reflectance_source", "Constant", "--reflectance", "0,0,0", "--sky_irradiance", "1",
                       "--max_depth", "0", "--samples_per_vertex", str(spp)])
        note = [n for n in json.loads(text)["notes"] if "cached" in n][0]
        with open(note.split(" ")[-1]) as f:
            pt = json.load(f)
        H = np.array([pt["H"][3 * i + 1] for i in range(pt["vertices"])])
        se = np.array(pt["std_error_H"])
        ok = se > 0
        out = {"scene": scene, "path_tracer_paths_per_vertex": spp,
               "rms_z": float(np.sqrt(np.mean(((ref["q"] - H)[ok] / se[ok]) ** 2))),
               "rms_difference": float(np.sqrt(np.mean((ref["q"] - H) ** 2)))}
        print("cross-check %s: reference vs the path tracer: RMS z %.3f" % (scene, out["rms_z"]), flush=True)
        return out

    def error(self, q, ref):
        raw = float(np.sqrt(np.mean((q - ref["q"]) ** 2)))
        return raw, math.sqrt(max(0.0, raw * raw - ref["noise"] ** 2))

    def add(self, scene, nv, method, knob, value, seconds, wall, q, ref, extra=None):
        raw, err = self.error(q, ref)
        row = {"scene": scene, "vertices": nv, "method": method, "knob": knob, "value": value,
               "filter_seconds": seconds, "wall_seconds": wall, "rms_error": err, "rms_error_raw": raw,
               "reference_noise": ref["noise"]}
        row.update(extra or {})
        self.rows.append(row)
        print("%-14s %-46s %s=%-7s %9.3f s (wall %7.2f s)  RMS %.5f (raw %.5f)%s" % (
            scene, method, knob, value, seconds, wall, err, raw,
            "  rays/vertex %.1f" % row["rays_per_vertex"] if "rays_per_vertex" in row else ""), flush=True)

    def ours(self, scene, mesh, nv, ref, label, args, knob, value, repeats, server=False):
        key = "|".join(["ours", scene, signature(mesh), self.ours_sig, label, " ".join(args), str(server)])
        if key not in self.cache:
            times, walls, stats, loads = [], [], None, []
            out = os.path.join(self.tmp, "ours.ply")
            for _ in range(repeats):
                loads.append(load_average())
                if server:
                    script = os.path.join(self.tmp, "ours.mlx")
                    run([self.gi, "script", "ao", "--mesh", mesh, "-o", script] + args)
                    text, wall = run([self.mlx, "-i", mesh, "-o", out, "-m", "vq", "-s", script])
                    line = re.search(r"GI: Ambient Occlusion: .*", text).group(0)
                    get = lambda k: float(re.search(k + r"=([0-9.e+-]+)", line).group(1))
                    stats = {"seconds": get("seconds"), "bvh_seconds": get("bvh_seconds"), "rays": get("rays"),
                             "rays_per_second": get("rays_per_second")}
                else:
                    text, wall = run([self.gi, "ao", mesh, "-o", out, "-q", "--json"] + args)
                    stats = json.loads(text)["stats"]
                times.append(stats["seconds"] + stats["bvh_seconds"])
                walls.append(wall)
            q = vertex_property(out, "quality")
            np.save(os.path.join(self.tmp, "q.npy"), q)
            self.cache[key] = {"seconds": statistics.median(times), "wall": statistics.median(walls),
                               "rays_per_vertex": stats["rays"] / nv, "rays_per_second": stats["rays_per_second"],
                               "load_average": loads, "finished": time.strftime("%Y-%m-%d %H:%M:%S"),
                               "quality_file": self.keep(q, key)}
            self.save_cache()
        c = self.cache[key]
        q = np.load(c["quality_file"])
        self.add(scene, nv, label, knob, value, c["seconds"], c["wall"], q, ref,
                 {"rays_per_vertex": c["rays_per_vertex"], "rays_per_second": c["rays_per_second"],
                  "load_average": c.get("load_average")})

    def cached_ours(self, scene, mesh):
        """The settings of ours in the cache for this mesh and binary: ray counts per vertex, shared ray counts,
        adaptive targets, adaptive strata counts and targets, and whether the meshlabserver run is there."""
        prefix = "|".join(["ours", scene, signature(mesh), self.ours_sig]) + "|"
        per_vertex, shared, targets, strata, strata_targets, server = set(), set(), set(), set(), set(), False
        for key in self.cache:
            if not key.startswith(prefix):
                continue
            label, args, via_server = key[len(prefix):].split("|")
            words = args.split()
            if via_server == "True":
                server = True
            elif label == "ours, per vertex":
                per_vertex.add(int(words[words.index("--rays_per_vertex") + 1]))
            elif label == "ours, shared":
                shared.add(int(words[words.index("--rays_per_vertex") + 1]))
            elif label == "ours, shared, adaptive":
                targets.add(float(words[words.index("--target_error") + 1]))
            elif label == "ours, adaptive strata":
                strata.add(int(words[words.index("--rays_per_vertex") + 1]))
            elif label == "ours, adaptive strata, adaptive":
                strata_targets.add(float(words[words.index("--target_error") + 1]))
        return (sorted(per_vertex), sorted(shared), sorted(targets, reverse=True), sorted(strata),
                sorted(strata_targets, reverse=True), server)

    def keep(self, q, key):
        d = os.path.join(self.results, "ao_runs")
        os.makedirs(d, exist_ok=True)
        path = os.path.join(d, hashlib.sha1(key.encode()).hexdigest()[:16] + ".npy")
        np.save(path, q.astype(np.float32))
        return path

    def meshlab(self, scene, mesh, nv, ref, views, tex, repeats, cached_only=False, fresh=False):
        """MeshLab's filter at one setting (cached by mesh); with `cached_only` a setting not in the cache is left
        out (returns False) instead of run; with `fresh` it is run now whatever the cache holds, and the cache is
        left as it was."""
        key = "|".join(["meshlab", scene, signature(mesh), str(views), str(tex)])
        if key not in self.cache and cached_only:
            print("%-14s MeshLab %d views, %d^2: not in the cache, left out" % (scene, views, tex), flush=True)
            return False
        kept = self.cache.get(key)
        if key not in self.cache or fresh:
            script = os.path.join(self.tmp, "mlao.mlx")
            with open(script, "w") as f:
                f.write(MESHLAB_AO_SCRIPT.format(views=views, tex=tex))
            times, walls = [], []
            out = os.path.join(self.tmp, "mlao.ply")
            logs = os.path.join(self.results, "meshlab_logs")
            os.makedirs(logs, exist_ok=True)
            log = os.path.join(logs, "%s_%dx%d.log" % (scene, views, tex))
            loads = []
            for _ in range(repeats):
                loads.append(load_average())
                text, wall = run([self.mlx, "-i", mesh, "-o", out, "-m", "vq", "-s", script], log=log)
                m = re.search(r"Successfully calculated A\.O\. after ([0-9.]+) sec", text)
                times.append(float(m.group(1)) if m else float("nan"))
                walls.append(wall)
                loads[-1] = {"before": loads[-1], "after": load_average()}
            q = 4.0 * vertex_property(out, "quality")  # MeshLab averages V max(0, n.d) over the sphere: open = 0.25
            self.cache[key] = {"seconds": statistics.median(times), "wall": statistics.median(walls),
                               "runs": repeats, "load_average": loads,
                               "quality_file": self.keep(q, key + ("|fresh" if fresh else ""))}
            if not fresh:
                self.save_cache()
        c = self.cache[key]
        if fresh:  # this run's values, the cache's entry back
            if kept is None:
                del self.cache[key]
            else:
                self.cache[key] = kept
        if ref is not None:  # None: filling the cache only (--peers-only)
            self.add(scene, nv, "MeshLab AO (CPU, depth %d)" % tex, "reqViews", views, c["seconds"], c["wall"],
                     np.load(c["quality_file"]), ref, {"load_average": c.get("load_average")})
        return True


def reference_rays(nv, quick=False):
    """Rays per run of a mesh's reference (two runs are averaged): fewer on larger meshes."""
    rays = 8192 if nv < 5000 else 4096 if nv < LARGE else 1024 if nv < 300000 else 512 if nv < 1000000 else 256
    return min(rays, 1024) if quick else rays


def time_to_reach(rows, target, key="filter_seconds"):
    """Filter time (or another cost, `key`) at which the RMS error reaches `target` (log-log interpolation between
    the two settings around it, each curve sorted by cost), or None if it never does."""
    pts = sorted((r[key], r["rms_error"]) for r in rows)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and min(e0, e1, t0, t1) > 0 and e0 != e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    if pts and pts[0][1] <= target:
        return pts[0][0]  # already below the target at the cheapest setting
    return None


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


def scenes(build, out, sizes, wanted=None):
    """The benchmark's meshes of `sizes` (or only those named in `wanted`), generating the missing ones."""
    meshes = os.path.join(ROOT, "test_meshes")
    s = {}
    if sizes in ("small", "all"):
        fine = os.path.join(out, "bunny_fine.ply")
        if not os.path.exists(fine):
            subdivided(os.path.join(meshes, "bunny.ply"), fine, 2)  # 29,394 vertices
        s.update({"bunny": os.path.join(meshes, "bunny.ply"), "bunny_fine": fine})
    if sizes in ("large", "all"):
        for level, name in ((3, "scan_118k"), (4, "scan_470k"), (5, "scan_1.9M")):
            path = os.path.join(out, name + ".ply")
            if wanted and name not in wanted:
                continue
            if not os.path.exists(path):
                run([os.path.join(build, "tools", "gi-scenes"), "scan", os.path.join(meshes, "bunny.ply"), str(level), path])
            s[name] = path
    if sizes in ("small", "all"):
        s.update({"cylinder_hole": os.path.join(meshes, "cylinder_hole.ply"),
                  "floor_wall": os.path.join(meshes, "floor_wall.ply")})
    return {k: v for k, v in s.items() if not wanted or k in wanted}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    ap.add_argument("--quick", action="store_true", help="fewer settings, single runs (a smoke run)")
    ap.add_argument("--sizes", default="all", choices=["small", "large", "all"])
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: all of --sizes)")
    ap.add_argument("--meshlab", default="512x512,1024x512,512x2048,1024x2048",
                    help="MeshLab settings VIEWSxDEPTHMAP to run on every scene (the first is the goal's)")
    ap.add_argument("--meshlab-repeats", type=int, default=0,
                    help="runs of MeshLab per setting (0: medians of 3 below 50k vertices, single runs above)")
    ap.add_argument("--cached-ours-only", action="store_true",
                    help="the settings of ours are those already in the cache for each mesh and this binary")
    ap.add_argument("--cached-meshlab-only", action="store_true",
                    help="MeshLab settings not already in the cache are left out instead of run (the tables say so)")
    ap.add_argument("--refs-only", action="store_true", help="only the references (no cache writes: can run beside)")
    ap.add_argument("--max-rays-total", type=float, default=3e8,
                    help="largest rays per run on the large meshes (ray counts n with n x vertices above it are left out)")
    ap.add_argument("--max-ref-rays-total", type=float, default=0,
                    help="halve a reference's rays per vertex while rays x vertices exceed this (0: no cap); its own "
                         "error, larger then, is still measured and removed in quadrature")
    ap.add_argument("--ref-rays", default="", help="reference rays per vertex (each of the two runs) by scene, "
                    "e.g. scan_470k=128,scan_1.9M=32 (overrides the defaults and --max-ref-rays-total)")
    ap.add_argument("--per-vertex-rays", default="", help="ray counts of ours per vertex (a,b,c; default by size)")
    ap.add_argument("--shared-rays", default="", help="ray counts of ours shared (default by size)")
    ap.add_argument("--strata-rays", default="", help="rays_per_vertex (strata) of ours, adaptive strata (default by size)")
    ap.add_argument("--strata-targets", default="",
                    help="adaptive targets of ours, adaptive strata (default: 0.02,0.01,0.005 below 50k vertices)")
    ap.add_argument("--targets", default="", help="adaptive targets of ours shared (default 0.04,0.02,0.01,0.005)")
    ap.add_argument("--repeats", type=int, default=0, help="runs of ours per setting (0: 3 below 50k vertices, else 1)")
    ap.add_argument("--no-server", action="store_true", help="leave out the run of ours through meshlabserver")
    ap.add_argument("--no-throughput", action="store_true", help="skip the throughput runs (ao_throughput)")
    ap.add_argument("--no-cross-check", action="store_true", help="skip the reference's check by the path tracer")
    ap.add_argument("--no-sweep", action="store_true", help="no sweep of MeshLab's views on the small meshes")
    ap.add_argument("--peers-only", action="store_true",
                    help="only the references and MeshLab's runs (filling the cache), no tables")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    b = Bench(a.build, a.out, a.quick)
    conditions = {"cpus": os.cpu_count(), "load_average_start": load_average(), "started": time.ctime()}
    sc = scenes(a.build, a.out, a.sizes, a.scenes.split(",") if a.scenes else None)
    main_configs = [tuple(int(x) for x in c.split("x")) for c in a.meshlab.split(",")]
    summary, throughput, checks = [], {}, []
    for scene, mesh in sc.items():
        nv = len(vertex_property(mesh, "x"))
        large = nv > LARGE
        repeats = 1 if (a.quick or large) else 3
        ml_repeats = a.meshlab_repeats or repeats
        ref_rays = reference_rays(nv, a.quick)
        if a.max_ref_rays_total:  # a power of two with rays x vertices within the cap, at least 16
            while ref_rays > 16 and ref_rays * nv > a.max_ref_rays_total:
                ref_rays //= 2
        ref_rays = dict((k, int(v)) for k, v in (x.split("=") for x in a.ref_rays.split(",") if x)).get(scene, ref_rays)
        ml_configs = list(main_configs)
        if not large and not a.quick and not a.no_sweep:
            ml_configs += [(v, 512) for v in (16, 32, 64, 128, 256)]
        if a.peers_only:  # MeshLab's runs first (the longest), then the references, filling the caches
            for views, tex in ml_configs:
                b.meshlab(scene, mesh, nv, None, views, tex, ml_repeats)
        ref = b.reference(scene, mesh, "angle", ref_rays)
        ref_ml = b.reference(scene, mesh, "area", ref_rays)
        if a.refs_only:
            continue
        print("%s: %d vertices; references (%d rays, two seeds): own RMS error %.5f (angle), %.5f (area)" % (
            scene, nv, 2 * ref_rays, ref["noise"], ref_ml["noise"]), flush=True)
        # Ray counts up to about 3e8 rays per run on the large meshes (the machine has 2 cores).
        per_vertex = [n for n in (8, 16, 32, 64, 128, 256, 512, 1024, 2048) if n * nv <= max(a.max_rays_total, 2048 * 5e4)]
        shared = [n for n in (4, 8, 16, 32, 64, 128, 256, 512) if n * nv <= max(a.max_rays_total, 512 * 5e4)]
        targets = [0.04, 0.02, 0.01, 0.005]
        strata = [n for n in (32, 50, 72, 98, 128, 162, 200, 288, 512) if n * nv <= max(a.max_rays_total, 512 * 5e4)]
        strata_targets = [] if large else [0.02, 0.01, 0.005]
        # explicit settings (a loaded machine: the few around MeshLab's error)
        per_vertex = [int(x) for x in a.per_vertex_rays.split(",") if x] if a.per_vertex_rays else per_vertex
        shared = [int(x) for x in a.shared_rays.split(",") if x] if a.shared_rays else shared
        targets = [float(x) for x in a.targets.split(",") if x] if a.targets else targets
        strata = [int(x) for x in a.strata_rays.split(",") if x] if a.strata_rays else strata
        strata_targets = [float(x) for x in a.strata_targets.split(",") if x] if a.strata_targets else strata_targets
        if a.repeats:
            repeats = a.repeats
        if a.quick:
            per_vertex, shared, targets, strata, strata_targets = [16, 64, 256], [8, 32, 128], [0.01], [32, 128], [0.01]
        if a.peers_only:
            continue
        if a.cached_ours_only:  # every setting of ours already measured on this mesh with this binary
            per_vertex, shared, targets, strata, strata_targets, server = b.cached_ours(scene, mesh)
            a.no_server = not server
        for n in per_vertex:
            b.ours(scene, mesh, nv, ref, "ours, per vertex", ["--rays_per_vertex", str(n), "--seed", "1"],
                   "rays_per_vertex", n, repeats)
        for n in shared:
            b.ours(scene, mesh, nv, ref, "ours, shared", ["--estimator", "1", "--rays_per_vertex", str(n), "--seed", "1"],
                   "rays_per_vertex", n, repeats)
        for n in strata:
            b.ours(scene, mesh, nv, ref, "ours, adaptive strata",
                   ["--estimator", "2", "--rays_per_vertex", str(n), "--seed", "1"], "rays_per_vertex", n, repeats)
        for t in strata_targets:
            b.ours(scene, mesh, nv, ref, "ours, adaptive strata, adaptive",
                   ["--estimator", "2", "--target_error", str(t), "--seed", "1"], "target_error", t, repeats)
        for t in targets:
            b.ours(scene, mesh, nv, ref, "ours, shared, adaptive",
                   ["--estimator", "1", "--target_error", str(t), "--min_rays", "8", "--seed", "1"], "target_error", t, repeats)
        if not a.no_server:
            b.ours(scene, mesh, nv, ref, "ours, shared (meshlabserver)",
                   ["--estimator", "1", "--rays_per_vertex", "32", "--seed", "1"], "rays_per_vertex", 32, repeats,
                   server=True)
        ran = {(views, tex): b.meshlab(scene, mesh, nv, ref_ml, views, tex, ml_repeats, a.cached_meshlab_only)
               for views, tex in ml_configs}
        rows = [r for r in b.rows if r["scene"] == scene]
        for ours in OURS + ("ours, adaptive strata, adaptive",):  # the last in the results only, not the table
            mine = [r for r in rows if r["method"] == ours]
            for views, tex in main_configs:
                if not ran[(views, tex)]:
                    continue
                ml = [r for r in rows if r["method"] == "MeshLab AO (CPU, depth %d)" % tex and r["value"] == views][0]
                to = time_to_reach(mine, ml["rms_error"])
                summary.append({"scene": scene, "vertices": nv, "ours": ours, "views": views, "tex": tex,
                                "meshlab_rms": ml["rms_error"], "meshlab_rms_raw": ml["rms_error_raw"],
                                "reference_noise": ml["reference_noise"], "meshlab_seconds": ml["filter_seconds"],
                                "meshlab_load_average": ml["load_average"],
                                "ours_load_average": [l for r in mine for l in (r["load_average"] or [])],
                                "ours_rays_per_vertex": time_to_reach(mine, ml["rms_error"], "rays_per_vertex"),
                                "ours_seconds": to, "speedup": ml["filter_seconds"] / to if to else None})
        if scene in ("bunny", "bunny_fine", "scan_118k") and not a.no_throughput:
            text, _ = run([os.path.join(a.build, "bench", "ao_throughput"), mesh, "64" if large else "256",
                           "1" if a.quick else "3"])
            throughput[scene] = json.loads(text)
            throughput[scene]["mesh"] = os.path.relpath(mesh, ROOT)  # results name no machine's folders
        if scene in ("bunny", "floor_wall") and not a.quick and not a.no_cross_check:
            checks.append(b.cross_check(scene, mesh, ref, 1024))
    if a.peers_only or a.refs_only:
        return
    conditions["load_average_end"] = load_average()
    conditions["finished"] = time.ctime()
    result = {"rows": b.rows, "summary": summary, "throughput": throughput, "reference_cross_check": checks,
              "conditions": conditions}
    with open(os.path.join(a.out, "ao_bench.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(a.out, "ao_bench.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=sorted({k for r in b.rows for k in r}))
        w.writeheader()
        w.writerows(b.rows)
    lines = speedup_table(summary)
    lines += ["", "| scene | bare Embree rays/s | bare robust rays/s | ours rays/s | ours / bare | ours / bare robust |",
              "|---|---|---|---|---|---|"]
    for scene, t in throughput.items():
        lines.append("| %s | %.3g | %.3g | %.3g | %.2f | %.2f |" % (
            scene, t["bare_embree_occluded1_rays_per_second"], t["bare_embree_robust_occluded1_rays_per_second"],
            t["ours_single_rays_per_second"], t["ratio_ours_single_to_bare"], t["ratio_ours_single_to_bare_robust"]))
    lines += ["", "| scene | path tracer paths | RMS z-score (reference vs path tracer) |", "|---|---|---|"]
    for c in checks:
        lines.append("| %s | %d | %.3f |" % (c["scene"], c["path_tracer_paths_per_vertex"], c["rms_z"]))
    lines += ["", "conditions: %s" % json.dumps(conditions)]
    with open(os.path.join(a.out, "ao_bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    plot(b.rows, list(sc), summary, os.path.join(a.out, "ao_bench.png"), os.path.join(a.out, "ao_speedup.png"))
    print("\n".join(lines))
    print("wrote %s/ao_bench.{json,csv,md,png}, ao_speedup.png" % a.out)


if __name__ == "__main__":
    main()
