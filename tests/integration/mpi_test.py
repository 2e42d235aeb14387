#!/usr/bin/env python3
"""One mesh split over MPI ranks (the GI_MPI build): `mpirun -np N gi FILTER`
writes the same bytes as the plain run, for every filter that can be split
(ambient occlusion, obscurance, sky, the reference, radiosity's final
gather), for 1, 2 and 4 ranks (oversubscribed on a small machine), both
ways of splitting, and chunks smaller and larger than a rank's share. The
JSON summary's "mpi" part must account for every vertex once. A parameter
error under mpirun is one line; a filter that cannot be split says so; the
ranks on one machine each take their share of its memory.

usage: mpi_test.py --gi GI --mpirun MPIRUN --meshes TEST_MESHES_DIR
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

FAILED = []

# Per filter: mesh and parameters (few samples: the test is about equality).
CASES = [
    ("ao", "bunny", ["--rays_per_vertex", "16", "--max_distance", "10%", "--bent_normals", "true"]),
    ("ao", "cornell_box", ["--target_error", "0.05", "--max_rays", "128"]),
    ("obscurance", "bunny", ["--rays_per_vertex", "16"]),
    ("sky", "floor_wall", ["--rays_per_vertex", "16", "--sun_rays", "4"]),
    ("reference", "cornell_box", ["--emitter_source", "1", "--samples_per_vertex", "4"]),
    ("reference", "cornell_box", ["--emitter_source", "1", "--target_relative_error", "0.3", "--min_samples", "4",
                                  "--max_samples", "32"]),
    ("radiosity", "cornell_box", ["--emitter_source", "1", "--rays_per_patch", "64", "--light_samples", "16",
                                  "--gather_rays", "16", "--face_output", "true"]),
    ("radiosity", "cornell_box", ["--emitter_source", "1", "--rays_per_patch", "64", "--light_samples", "16",
                                  "--gather_rays", "8", "--refine", "true", "--refine_max_depth", "1"]),
]


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILED.append(what)


def mpirun(a, n):
    cmd = [a.mpirun, "-np", str(n), "--oversubscribe", "--bind-to", "none"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    return cmd


def env():
    # Shared memory between the ranks of one machine; no single-copy (CMA
    # needs ptrace rights that containers often lack).
    return dict(os.environ, OMPI_MCA_btl="self,vader", OMPI_MCA_btl_vader_single_copy_mechanism="none",
                OMPI_MCA_rmaps_base_oversubscribe="1")


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, env=env(), timeout=600)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", required=True)
    ap.add_argument("--mpirun", required=True)
    ap.add_argument("--meshes", required=True)
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="gi_mpi_")
    try:
        for k, (filt, mesh, params) in enumerate(CASES):
            src = os.path.join(a.meshes, mesh + ".ply")
            plain = os.path.join(tmp, "plain%d.ply" % k)
            p = run([a.gi, filt, src, "-o", plain, "-q"] + params)
            check(p.returncode == 0, "%s %s: plain run" % (filt, " ".join(params)))
            if p.returncode != 0:
                print(p.stderr)
                continue
            want = open(plain, "rb").read()
            for n, split in ((1, []), (2, ["--chunk", "97"]), (4, ["--split", "contiguous"]),
                             (4, ["--chunk", "64"])):
                out = os.path.join(tmp, "mpi%d_%d.ply" % (k, n))
                p = run(mpirun(a, n) + [a.gi, filt, src, "-o", out, "--json", "-q"] + params + split)
                what = "%s on %s, %d ranks %s" % (filt, mesh, n, " ".join(split))
                if p.returncode != 0:
                    check(False, what + ": exit %d: %s" % (p.returncode, p.stderr[-1500:]))
                    continue
                check(open(out, "rb").read() == want, what + ": same bytes as the plain run")
                j = json.loads(p.stdout)
                m = j.get("mpi") or {}
                ranks = m.get("per_rank", [])
                nv = j["scene"]["vertices"] if not j["parameters"].get("refine") else None
                counted = sum(r["vertices"] for r in ranks)
                check(m.get("ranks") == n and len(ranks) == n and (nv is None or counted == nv),
                      what + ": %d ranks computed %d vertices, each once" % (len(ranks), counted))
                check(m.get("imbalance", 0) >= 1.0 and m.get("gather_MB", -1) >= 0,
                      what + ": slowest/mean %.3g, gather %.3g MB in %.3g s" %
                      (m.get("imbalance", 0), m.get("gather_MB", -1), m.get("gather_seconds", -1)))
        cornell = os.path.join(a.meshes, "cornell_box.ply")
        p = run(mpirun(a, 2) + [a.gi, "ao", cornell, "--rays_per_vertex", "0"])
        lines = [l for l in p.stderr.splitlines() if l.startswith("gi:")]
        check(p.returncode != 0 and len(lines) == 1, "a parameter error under mpirun: one line (%s)" % lines)
        # The ranks on this machine share its memory: a radiosity budget
        # beyond it is lowered to each rank's share, and the log says so.
        p = run(mpirun(a, 4) + [a.gi, "radiosity", cornell, "--emitter_source", "1", "--rays_per_patch", "16",
                                "--memory_budget_mb", "10000000", "-o", os.path.join(tmp, "share.ply"), "--json",
                                "-q"])
        warnings = json.loads(p.stdout).get("warnings", []) if p.returncode == 0 else [p.stderr[-500:]]
        check(any("to each of the 4 ranks on this machine" in w for w in warnings),
              "4 ranks share the machine's memory: %s" % warnings)
        # Ranks given different jobs (another --chunk on one, another filter
        # on one) are refused in one line: they wrote wrong values, or
        # overran rank 0's buffer (an outside audit).
        base = [a.gi, "ao", cornell, "--rays_per_vertex", "8", "-o", os.path.join(tmp, "mixed.ply"), "-q"]
        one = mpirun(a, 1)
        for what, other in (("another --chunk", base + ["--chunk", "100"]),
                            ("another filter", [a.gi, "sky"] + base[2:])):
            p = run(one + base + ["--chunk", "7", ":", "-np", "1"] + other)
            lines = [l for l in p.stderr.splitlines() if l.startswith("gi:")]
            check(p.returncode != 0 and len(lines) == 1 and "different jobs" in lines[0] and
                  not os.path.exists(os.path.join(tmp, "mixed.ply")),
                  "ranks given %s: one line, no file (%s)" % (what, lines))
        p = run(mpirun(a, 2) + [a.gi, "photonmap", cornell, "--emitter_source", "1", "--photons", "1000"])
        lines = [l for l in p.stderr.splitlines() if l.startswith("gi:")]
        check(p.returncode != 0 and len(lines) == 1 and "split" in lines[0],
              "a filter that cannot be split: one line (%s)" % lines)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILED:
        print("%d checks failed" % len(FAILED))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
