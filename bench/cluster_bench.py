#!/usr/bin/env python3
"""One mesh split over MPI ranks, measured as far as one machine allows
(README, "Beyond one machine"). Needs a build with -DGI_MPI=ON and Open MPI's
mpirun.

1. Per-vertex cost: `gi ao` (256 rays, the default) and `gi reference` (sky
   light, 64 paths) in one process on bumpy height fields of two sizes:
   core-seconds per vertex (wall x threads / vertices) and peak memory, the
   inputs of the README's estimate for a 50-million-triangle scan.
2. Ranks: the same runs under `mpirun -np 1, 2, 4` (one thread per rank;
   4 ranks oversubscribe a 2-core machine): each rank's time, the slowest
   against the mean, the gather's time, bytes and buffer, peak memory per
   rank, and that the output equals the plain run's bytes.
3. Load balance: a height field flat at one end and rough at the other,
   AO with a maximum distance (open vertices skip their rays), so that the
   cost per vertex follows the vertex order: contiguous ranges against
   interleaved chunks.

usage: python3 bench/cluster_bench.py [--gi build/tools/gi] [--mpirun mpirun] [--quick]
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time


def field(path, n, rough=None):
    """An n x n height field (2 n^2 triangles), binary PLY; rough(y) scales its bumps along y."""
    verts = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = i / n, j / n
            a = rough(y) if rough else 1.0
            verts.append((x, y, a * (0.08 * math.sin(11 * x) * math.cos(7 * y) + 0.05 * math.sin(31 * x + 17 * y))))
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


def env():
    return dict(os.environ, OMPI_MCA_btl="self,vader", OMPI_MCA_btl_vader_single_copy_mechanism="none")


def plain(b, args, out, threads):
    t0 = time.perf_counter()
    pid = os.spawnv(os.P_NOWAIT, b.gi, [b.gi] + args + ["-o", out, "-q", "--threads", str(threads)])
    _, status, usage = os.wait4(pid, 0)
    if status != 0:
        raise RuntimeError("gi failed: %s" % " ".join(args))
    return time.perf_counter() - t0, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def split(b, args, out, ranks, extra=()):
    cmd = [b.mpirun, "-np", str(ranks), "--oversubscribe", "--bind-to", "none"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    t0 = time.perf_counter()
    p = subprocess.run(cmd + [b.gi] + args + ["-o", out, "-q", "--json", "--threads", "1"] + list(extra),
                       capture_output=True, text=True, env=env())
    if p.returncode != 0:
        raise RuntimeError("mpirun failed: %s" % p.stderr[-2000:])
    j = json.loads(p.stdout)
    j["wall"] = time.perf_counter() - t0
    return j


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", default="build/tools/gi")
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--quick", action="store_true")
    b = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="gi_cluster_bench_")
    threads = os.cpu_count()
    res = {"cores": threads, "cost": [], "ranks": [], "balance": []}
    sizes = [100, 250] if b.quick else [250, 500]
    filters = {"ao": ["ao", "--rays_per_vertex", "256"],
               "reference": ["reference", "--sky_irradiance", "1", "--samples_per_vertex", "64", "--max_depth", "2"]}

    print("1. per-vertex cost, one process, %d threads" % threads)
    for n in sizes:
        mesh = os.path.join(tmp, "field_%d.ply" % n)
        field(mesh, n)
        for name, args in filters.items():
            out = os.path.join(tmp, "plain_%s_%d.ply" % (name, n))
            wall, cpu, rss = plain(b, [args[0], mesh] + args[1:], out, threads)
            nv = (n + 1) ** 2
            row = {"filter": name, "triangles": 2 * n * n, "vertices": nv, "wall": wall, "cpu": cpu, "peak_MB": rss,
                   "cpu_us_per_vertex": 1e6 * cpu / nv}
            res["cost"].append(row)
            print("  %-9s %8d triangles: %6.2f s wall, %6.2f s CPU: %7.1f CPU-us per vertex, peak %6.1f MB" %
                  (name, 2 * n * n, wall, cpu, row["cpu_us_per_vertex"], rss), flush=True)

    n = sizes[-1]
    mesh = os.path.join(tmp, "field_%d.ply" % n)
    print("2. ranks (one thread each) on %d triangles" % (2 * n * n))
    for name, args in filters.items():
        want = open(os.path.join(tmp, "plain_%s_%d.ply" % (name, n)), "rb").read()
        for ranks in (1, 2, 4):
            out = os.path.join(tmp, "split.ply")
            j = split(b, [args[0], mesh] + args[1:], out, ranks)
            m = j["mpi"]
            row = {"filter": name, "ranks": ranks, "wall": j["wall"], "same_bytes": open(out, "rb").read() == want,
                   "rank_seconds": [r["seconds"] for r in m["per_rank"]], "imbalance": m["imbalance"],
                   "rank_cpu": [r["cpu_seconds"] for r in m["per_rank"]],
                   "gather_seconds": m["gather_seconds"], "gather_MB": m["gather_MB"],
                   "gather_buffer_MB": m["gather_buffer_MB"], "peak_MB": [r["peak_memory_MB"] for r in m["per_rank"]]}
            res["ranks"].append(row)
            print("  %-9s %d ranks: wall %6.2f s, ranks %s s (CPU %s s), slowest/mean %.3f, gather %.3f s (%.2f MB, "
                  "buffer %.2f MB), peak %s MB, same bytes: %s" %
                  (name, ranks, j["wall"], ", ".join("%.2f" % s for s in row["rank_seconds"]),
                   ", ".join("%.2f" % s for s in row["rank_cpu"]), m["imbalance"],
                   m["gather_seconds"], m["gather_MB"], m["gather_buffer_MB"],
                   ", ".join("%.0f" % p for p in row["peak_MB"]), row["same_bytes"]), flush=True)

    print("3. load balance: flat at y = 0, rough at y = 1, adaptive AO (flat vertices stop at 32 rays)")
    uneven = os.path.join(tmp, "uneven.ply")
    field(uneven, n, rough=lambda y: 4 * y ** 3)
    args = ["ao", uneven, "--target_error", "0.01", "--max_rays", "1024"]
    for ranks in (2, 4):
        for how in (["--split", "contiguous"], ["--split", "interleaved"]):
            j = split(b, args, os.path.join(tmp, "u.ply"), ranks, how)
            m = j["mpi"]
            cpu = [r["cpu_seconds"] for r in m["per_rank"]]
            res["balance"].append({"ranks": ranks, "split": how[1], "imbalance": m["imbalance"],
                                   "cpu_imbalance": max(cpu) * len(cpu) / sum(cpu), "rank_cpu": cpu,
                                   "rank_rays": [r["rays"] for r in m["per_rank"]]})
            print("  %d ranks, %-11s: slowest/mean %.3f (CPU %.3f); rays per rank %s" %
                  (ranks, how[1], m["imbalance"], max(cpu) * len(cpu) / sum(cpu),
                   ", ".join("%.3g" % r["rays"] for r in m["per_rank"])), flush=True)
    os.makedirs(os.path.join(os.path.dirname(os.path.abspath(__file__)), "results"), exist_ok=True)
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results", "cluster_bench.json")
    with open(path, "w") as f:
        json.dump(res, f, indent=1)
    print("wrote", path)


if __name__ == "__main__":
    sys.exit(main())
