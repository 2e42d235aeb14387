#!/usr/bin/env python3
"""`gi batch` on a collection of meshes: every mesh baked once, results next
to their names with a summary, a failing mesh reported without stopping the
others, resumable after a kill, shards that share the collection without
overlap, and a report that adds up.

Cases (all by default):
  basic   manifest with per-line overrides, a missing and a damaged mesh, a
          rerun that recomputes nothing, a parameter change that recomputes all
  kill    killed half-way (SIGKILL) and rerun: nothing done is recomputed,
          nothing is lost, every mesh counted once
  shards  --shard I/N and a Slurm array's environment: each mesh in exactly
          one shard; --report-only over all of them
  inputs  --dir/--glob, a JSON parameter file, and one-line errors
  keep    a failing re-run keeps the earlier results; a reference file is an
          input of the error map (relative to the manifest, in the hash); a
          file at one path is refused; --report-only beside a mesh "report"

usage: batch_test.py --gi GI --meshes TEST_MESHES_DIR [case ...]
"""
import argparse
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

FAILED = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILED.append(what)


def run(cmd, env=None, expect=None):
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    if expect is not None and p.returncode != expect:
        print("command:", " ".join(cmd), "\nstdout:", p.stdout[-2000:], "\nstderr:", p.stderr[-2000:])
    return p


def load(path):
    with open(path) as f:
        return json.load(f)


def stamp(path):
    st = os.stat(path)
    return (st.st_ino, st.st_mtime_ns)


# Meshes that bake in well under a second with a few rays.
SMALL = ["cornell_box", "closed_box", "floor_wall", "bowl", "cylinder_hole", "open_plane", "parallel_plates",
         "perpendicular_plates"]


def copy_meshes(src, dst, names, copies=1):
    os.makedirs(dst, exist_ok=True)
    out = []
    for k in range(copies):
        for n in names:
            name = n if copies == 1 else "%s_%d" % (n, k)
            shutil.copy(os.path.join(src, n + ".ply"), os.path.join(dst, name + ".ply"))
            out.append(name)
    return out


def case_basic(a, tmp):
    meshes = os.path.join(tmp, "basic_meshes")
    names = copy_meshes(a.meshes, meshes, SMALL)
    with open(os.path.join(meshes, "damaged.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0\n")
    manifest = os.path.join(meshes, "list.txt")
    with open(manifest, "w") as f:
        f.write("# one mesh a line, relative to this file; parameters after the name\n\n")
        for n in names:
            f.write(n + ".ply" + ("  --rays_per_vertex 8 --seed=3" if n == "bowl" else "") + "\n")
        f.write("damaged.ply\n")
        f.write("'not there.ply'\n")
    out = os.path.join(tmp, "basic_out")
    cmd = [a.gi, "batch", "ao", "--manifest", manifest, "-o", out, "--rays_per_vertex", "16", "--json"]
    p = run(cmd)
    check(p.returncode == 1, "a batch with failing meshes exits 1 (%d)" % p.returncode)
    rep = json.loads(p.stdout)
    total = len(names) + 2
    check(rep["meshes"] == total and rep["baked"] == len(names) and rep["failed"] == 2 and rep["done_before"] == 0,
          "report counts: %d meshes, %d baked, 2 failed (%s)" % (total, len(names), {k: rep[k] for k in ("meshes", "baked", "failed", "done_before")}))
    reasons = {os.path.basename(f["input"]): f["error"] for f in rep["failures"]}
    check("damaged.ply" in reasons and "\n" not in reasons["damaged.ply"] and "damaged.ply" in reasons["damaged.ply"],
          "the damaged mesh's one-line reason names it: %s" % reasons.get("damaged.ply"))
    check("not there.ply" in reasons, "the missing mesh is reported: %s" % reasons.get("not there.ply"))
    rays = 0
    for n in names:
        s = load(os.path.join(out, n + ".json"))
        rays += s["rays"]
        check(s["status"] == "ok" and os.path.getsize(os.path.join(out, n + ".ply")) > 0 and s["rays"] > 0,
              "%s: PLY and summary (%g rays)" % (n, s["rays"]))
    bowl = load(os.path.join(out, "bowl.json"))
    check(bowl["parameters"]["rays_per_vertex"] == "8" and "seed=3" in bowl["resolved"],
          "a manifest line's parameters override the command line's (%s)" % bowl["parameters"])
    check(abs(rep["rays"] - rays) <= 1e-6 * rays, "report's rays are the meshes' sum (%g)" % rays)
    check(load(os.path.join(out, "damaged.json"))["status"] == "failed", "a failed mesh has a summary saying so")
    check(os.path.exists(os.path.join(out, "report-0-of-1.json")), "report file written")

    stamps = {n: stamp(os.path.join(out, n + ".ply")) for n in names}
    p = run(cmd)
    rep = json.loads(p.stdout)
    check(rep["baked"] == 0 and rep["done_before"] == len(names) and rep["failed"] == 2,
          "rerun: nothing recomputed, failures retried (%s)" % {k: rep[k] for k in ("baked", "done_before", "failed")})
    check(all(stamp(os.path.join(out, n + ".ply")) == stamps[n] for n in names), "rerun: no PLY rewritten")
    check(abs(rep["rays_all"] - rays) <= 1e-6 * rays, "rerun: rays of the results done before still counted")

    # A result cut short (or edited) since its summary was written is not
    # done: its size and hash differ from the summary's (it was counted as
    # done before; an outside audit).
    victim = os.path.join(out, names[0] + ".ply")
    with open(victim, "r+b") as f:
        f.truncate(1000)
    rep = json.loads(run(cmd).stdout)
    check(rep["baked"] == 1 and rep["done_before"] == len(names) - 1,
          "a truncated result is baked again, the others not (%s)" % {k: rep[k] for k in ("baked", "done_before")})
    check(os.path.getsize(victim) > 1000, "the truncated result was rewritten whole")

    # An input edited in place, its size and time kept (a tool that restores
    # times, a copy with -p): its result is not done (compared by size and
    # time, it was; an outside audit).
    edited = os.path.join(meshes, names[0] + ".ply")
    st = os.stat(edited)
    with open(edited, "r+b") as f:
        data = f.read()
        at = data.index(b"end_header\n") + len(b"end_header\n")
        if b"format ascii" in data[:at]:
            while not data[at:at + 1].isdigit():
                at += 1
            f.seek(at)
            f.write(b"1" if data[at:at + 1] != b"1" else b"2")
        else:  # the lowest byte of the first coordinate: a nudge
            at += 3 if b"binary_big_endian" in data[:at] else 0
            f.seek(at)
            f.write(bytes([data[at] ^ 1]))
    os.utime(edited, ns=(st.st_atime_ns, st.st_mtime_ns))
    check(os.path.getsize(edited) == st.st_size and os.stat(edited).st_mtime_ns == st.st_mtime_ns,
          "the edited input keeps its size and time")
    rep = json.loads(run(cmd).stdout)
    check(rep["baked"] == 1 and rep["done_before"] == len(names) - 1,
          "an input edited in place, size and time kept, is baked again, the others not (%s)" %
          {k: rep[k] for k in ("baked", "done_before")})

    # A result's new layer (photon mapping's photons beside it) is in the digest too.
    lit = os.path.join(tmp, "lit_meshes")
    copy_meshes(a.meshes, lit, ["cornell_box"])
    lout = os.path.join(tmp, "lit_out")
    lcmd = [a.gi, "batch", "photonmap", "--dir", lit, "-o", lout, "--photons", "2000", "--light_samples", "4",
            "--photon_layer", "true", "--json"]
    rep = json.loads(run(lcmd).stdout)
    layer = os.path.join(lout, "cornell_box.Photons.ply")
    check(rep["baked"] == 1 and os.path.exists(layer), "photon mapping with its layer baked (%s)" % rep)
    with open(layer, "r+b") as f:
        f.truncate(100)
    rep = json.loads(run(lcmd).stdout)
    check(rep["baked"] == 1 and rep["done_before"] == 0 and os.path.getsize(layer) > 100,
          "a truncated layer file is baked again (%s)" % {k: rep[k] for k in ("baked", "done_before")})

    cmd[cmd.index("16")] = "12"
    rep = json.loads(run(cmd).stdout)
    check(rep["baked"] == len(names) - 1 and rep["done_before"] == 1,
          "another value of a common parameter recomputes every mesh but bowl, whose line sets its own (%s)" %
          {k: rep[k] for k in ("baked", "done_before")})


def case_kill(a, tmp):
    meshes = os.path.join(tmp, "kill_meshes")
    names = copy_meshes(a.meshes, meshes, ["bunny"], copies=8)
    manifest = os.path.join(meshes, "list.txt")
    with open(manifest, "w") as f:
        f.write("\n".join(n + ".ply" for n in names) + "\n")
    out = os.path.join(tmp, "kill_out")
    cmd = [a.gi, "batch", "ao", "--manifest", manifest, "-o", out, "--rays_per_vertex", "1024", "--threads", "1", "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300
    done = []
    def finished():  # a summary is written first, saying "running", then again when the mesh is done
        out_ = []
        for p in glob.glob(os.path.join(out, "bunny_*.json")):
            try:
                if load(p)["status"] == "ok":
                    out_.append(os.path.basename(p)[:-5])
            except (OSError, ValueError, KeyError):
                pass
        return sorted(out_)

    while time.time() < deadline and proc.poll() is None:
        done = finished()
        if len(done) >= 2:
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = finished()
    check(2 <= len(done) < len(names), "killed half-way: %d of %d meshes finished" % (len(done), len(names)))
    stamps = {n: (stamp(os.path.join(out, n + ".ply")), stamp(os.path.join(out, n + ".json"))) for n in done}
    p = run(cmd)
    rep = json.loads(p.stdout)
    check(p.returncode == 0, "rerun after the kill succeeds")
    check(rep["done_before"] == len(done) and rep["baked"] == len(names) - len(done) and rep["failed"] == 0
          and rep["meshes"] == len(names),
          "rerun counts every mesh once: %d done before + %d baked = %d" % (rep["done_before"], rep["baked"], len(names)))
    check(all((stamp(os.path.join(out, n + ".ply")), stamp(os.path.join(out, n + ".json"))) == stamps[n] for n in done),
          "nothing finished before the kill was recomputed or rewritten")
    check(all(load(os.path.join(out, n + ".json"))["status"] == "ok" for n in names), "every mesh has its result")
    check(not glob.glob(os.path.join(out, "*.part")), "no partial files left")
    # The results equal a batch that was never interrupted.
    clean = os.path.join(tmp, "kill_clean")
    run(cmd[:cmd.index(out)] + [clean] + cmd[cmd.index(out) + 1:])
    same = all(open(os.path.join(out, n + ".ply"), "rb").read() == open(os.path.join(clean, n + ".ply"), "rb").read()
               for n in names)
    check(same, "results after kill and rerun are bit-identical to an uninterrupted batch")


def case_shards(a, tmp):
    meshes = os.path.join(tmp, "shard_meshes")
    names = copy_meshes(a.meshes, meshes, SMALL)
    manifest = os.path.join(meshes, "list.txt")
    with open(manifest, "w") as f:
        f.write("\n".join(n + ".ply" for n in names) + "\n")
    out = os.path.join(tmp, "shard_out")
    base = [a.gi, "batch", "ao", "--manifest", manifest, "-o", out, "--rays_per_vertex", "8", "--json"]
    n = 3
    counts = 0
    for i in range(n):
        if i == 1:  # as a Slurm array task would see it: --array=4-6, task 5 is the second shard
            env = dict(os.environ, SLURM_ARRAY_TASK_ID="5", SLURM_ARRAY_TASK_MIN="4", SLURM_ARRAY_TASK_COUNT="3")
            rep = json.loads(run(base, env=env).stdout)
        else:
            rep = json.loads(run(base + ["--shard", "%d/%d" % (i, n)]).stdout)
        check(rep["shard"] == "%d/%d" % (i, n), "shard %d/%d chosen (%s)" % (i, n, rep["shard"]))
        counts += rep["baked"]
    check(counts == len(names), "the shards baked %d meshes, each once (%d)" % (len(names), counts))
    for k, name in enumerate(names):
        s = load(os.path.join(out, name + ".json"))
        check(s["shard"] == "%d/%d" % (k % n, n), "%s baked by shard %d" % (name, k % n))
    rep = json.loads(run(base + ["--report-only"]).stdout)
    check(rep["meshes"] == len(names) and rep["done"] == len(names) and rep["failed"] == 0 and rep["missing"] == 0,
          "--report-only over all shards: %d done" % rep["done"])
    env = dict(os.environ, SLURM_ARRAY_TASK_ID="3", SLURM_ARRAY_TASK_MIN="0", SLURM_ARRAY_TASK_COUNT="3")
    p = run(base, env=env)
    check(p.returncode == 1 and p.stderr.count("\n") == 1 and "--array=0-2" in p.stderr,
          "a task id outside the array's count: one line (%s)" % p.stderr.strip())


def case_inputs(a, tmp):
    meshes = os.path.join(tmp, "input_meshes")
    names = copy_meshes(a.meshes, meshes, SMALL[:4])
    shutil.copy(os.path.join(a.meshes, "bowl.ply"), os.path.join(meshes, "ignored.off.txt"))
    params = os.path.join(tmp, "params.json")
    with open(params, "w") as f:
        json.dump({"filter": "GI: Ambient Obscurance", "parameters": {"rays_per_vertex": 8, "max_distance": "5%"}}, f)
    out = os.path.join(tmp, "input_out")
    p = run([a.gi, "batch", "--dir", meshes, "--glob", "*.ply", "--params", params, "-o", out, "--json"])
    rep = json.loads(p.stdout)
    check(p.returncode == 0 and rep["meshes"] == len(names) and rep["baked"] == len(names),
          "--dir/--glob and a parameter file naming the filter: %d baked" % rep.get("baked", -1))
    s = load(os.path.join(out, "bowl.json"))
    check(s["filter"] == "GI: Ambient Obscurance" and "rays_per_vertex=8" in s["resolved"], "parameter file applied")
    # A whole number written as a JSON float is that integer (8.0 was
    # refused as "expected an integer"; an outside audit).
    with open(params, "w") as f:
        f.write('{"filter": "ao", "parameters": {"rays_per_vertex": 8.0, "max_rays": 1e2}}')
    out2 = os.path.join(tmp, "input_out_float")
    p = run([a.gi, "batch", "--dir", meshes, "--glob", "bowl.ply", "--params", params, "-o", out2, "--json"])
    s = load(os.path.join(out2, "bowl.json")) if p.returncode == 0 else {"resolved": ""}
    check(p.returncode == 0 and "rays_per_vertex=8," in s["resolved"] + "," and "max_rays=100" in s["resolved"],
          "integral JSON floats taken as integers (%s)" % p.stderr.strip())

    def one_line(args, needle, what):
        p = run([a.gi, "batch"] + args)
        check(p.returncode == 1 and p.stderr.count("\n") == 1 and needle in p.stderr,
              "%s: one line (%s)" % (what, p.stderr.strip()))

    bad = os.path.join(tmp, "bad_list.txt")
    with open(bad, "w") as f:
        f.write("bowl.ply\nbowl.ply --no_such 3\n")
    one_line(["ao", "--manifest", bad, "-o", out], "line 2", "an unknown parameter in a manifest line")
    with open(bad, "w") as f:
        f.write(os.path.join(meshes, "bowl.ply") + "\n" + os.path.join(a.meshes, "bowl.ply") + "\n")
    one_line(["ao", "--manifest", bad, "-o", out], "bowl.ply", "two meshes of one name")
    one_line(["ao", "-o", out], "--manifest", "neither manifest nor folder")
    # A mesh whose summary would take a report's name, whatever the shard
    # count: refused with one shard too (only the count that made the same
    # name clashed; an outside audit).
    for stem in ("report-0-of-2", "report-only-1-of-3", "report"):
        with open(bad, "w") as f:
            f.write(os.path.join(a.meshes, "bowl.ply") + "\n" + os.path.join(tmp, stem + ".ply") + "\n")
        shutil.copy(os.path.join(a.meshes, "bowl.ply"), os.path.join(tmp, stem + ".ply"))
        one_line(["ao", "--manifest", bad, "-o", out], stem + ".json", "a mesh named %s.ply" % stem)
    shutil.copy(os.path.join(a.meshes, "bowl.ply"), os.path.join(tmp, "report-0-of-2x.ply"))
    with open(bad, "w") as f:
        f.write(os.path.join(tmp, "report-0-of-2x.ply") + "\n")
    p = run([a.gi, "batch", "ao", "--manifest", bad, "-o", os.path.join(tmp, "report_like_out"), "--rays_per_vertex",
             "8", "--json"])
    check(p.returncode == 0 and json.loads(p.stdout)["baked"] == 1, "a name only like a report's is baked (%s)" %
          p.stderr.strip())
    one_line(["ao", "--dir", meshes, "-o", out, "--shard", "3/3"], "--shard", "a shard outside 0..N-1")
    one_line(["render", "--dir", meshes, "-o", out, "--image_path", os.path.join(tmp, "v.png")], "image_path",
             "a filter that writes an image at one path")
    # Without an image path such a filter bakes each mesh's own results (it
    # was refused whatever its parameters; an outside audit).
    p = run([a.gi, "batch", "hemicube", "--dir", meshes, "--glob", "bowl.ply", "-o", os.path.join(tmp, "hemi_out"),
             "--face_index", "0", "--hemicube_resolution", "16", "--json"])
    check(p.returncode == 0 and json.loads(p.stdout)["baked"] == 1, "hemicube without an image in a batch (%s)" % p.stderr.strip())
    # Entries of the folder that are no regular file fail as their meshes
    # (a link in a loop stopped the whole batch with the library's message;
    # a dangling link was skipped in silence; an outside audit).
    odd = os.path.join(tmp, "odd_meshes")
    os.makedirs(odd)
    shutil.copy(os.path.join(a.meshes, "bowl.ply"), odd)
    os.symlink("loop.ply", os.path.join(odd, "loop.ply"))
    os.symlink("nowhere.ply", os.path.join(odd, "dangling.ply"))
    p = run([a.gi, "batch", "ao", "--dir", odd, "-o", os.path.join(tmp, "odd_out"), "--rays_per_vertex", "8", "--json"])
    rep = json.loads(p.stdout) if p.stdout.strip() else {}
    check(p.returncode == 1 and rep.get("baked") == 1 and rep.get("failed") == 2,
          "a link in a loop and a dangling link fail as meshes, the rest is baked (rc %d, %s)" % (p.returncode, rep))
    one_line(["ao", "--dir", meshes, "-o", out, "--rays_per_vertex"], "needs a value", "a parameter without value")
    one_line(["ao", "--dir", meshes, "-o", meshes], "overwrite", "results that would overwrite their inputs")
    one_line(["ao", "--manifest", meshes, "-o", out], "is a folder", "a folder as the manifest")
    one_line(["ao", "--dir", meshes, "--glob", "*.xyz", "-o", out], "*.xyz", "a pattern that matches no mesh")
    with open(bad, "w") as f:
        f.write("# only a comment\n")
    one_line(["ao", "--manifest", bad, "-o", out], "lists no mesh", "a manifest that lists no mesh")
    # Under mpirun a build without MPI would run the whole job in every
    # process (two processes baked one shard at once): refused in one line.
    # (A build with MPI is tested under a real mpirun by mpi_test.py: its
    # MPI_Init would look for the launcher this variable names.)
    linked = subprocess.run(["ldd", a.gi], capture_output=True, text=True).stdout
    if "libmpi" not in linked:
        env = dict(os.environ, OMPI_COMM_WORLD_SIZE="2")
        p = run([a.gi, "batch", "ao", "--dir", meshes, "-o", os.path.join(tmp, "never_mpi")], env=env)
        check(p.returncode == 1 and p.stderr.count("\n") == 1 and "built without MPI" in p.stderr,
              "several processes of mpirun, a build without MPI: one line (%s)" % p.stderr.strip())
    # A value no mesh can take is said once, before any mesh is loaded.
    fresh = os.path.join(tmp, "never_written")
    one_line(["ao", "--dir", meshes, "-o", fresh, "--rays_per_vertex", "nan"], "rays_per_vertex",
             "a value no mesh can take")
    check(not os.path.exists(os.path.join(fresh, "bowl.json")), "no per-mesh summary for a bad common value")
    # A parameter file nested deeper than any of ours (it crashed the tool
    # at 200,000 levels: nlohmann's copies recurse per level).
    deep = os.path.join(tmp, "deep_params.json")
    with open(deep, "w") as f:
        f.write('{"filter": "ao", "parameters": {"rays_per_vertex": ' + "[" * 200000 + "]" * 200000 + "}}")
    one_line(["--params", deep, "--dir", meshes, "-o", out], "nested deeper", "a parameter file nested 200,000 deep")
    # A key the file format does not have (a typo) is refused: the whole set
    # of parameters was dropped in silence (an outside audit).
    for doc in ('{"filter": "ao", "paramters": {"rays_per_vertex": 8}}', '{"Filter": "sky", "parameters": {}}'):
        with open(params, "w") as f:
            f.write(doc)
        one_line(["--params", params, "--dir", meshes, "-o", out], "it does not know", "a parameter file " + doc)
    # A key given twice: nlohmann kept the last in silence (an outside audit).
    with open(params, "w") as f:
        f.write('{"filter": "ao", "parameters": {"rays_per_vertex": 8, "rays_per_vertex": 64}}')
    one_line(["--params", params, "--dir", meshes, "-o", out], "twice", "a parameter file giving a key twice")
    one_line(["ao", "--dir", meshes, "-o", out, "--shard", ""], "--shard", "an empty --shard (it meant no shard)")
    one_line(["ao", "--dir", meshes, "-o", out, "--shard", "0/%d" % 2 ** 40], "2^40", "--shard N of 2^40")
    # A hidden file is matched only by a pattern starting with a dot, as in
    # a shell (*.ply took an editor's .bowl.ply).
    shutil.copy(os.path.join(meshes, "bowl.ply"), os.path.join(meshes, ".hidden.ply"))
    rep = json.loads(run([a.gi, "batch", "ao", "--dir", meshes, "-o", os.path.join(tmp, "hidden_out"),
                          "--rays_per_vertex", "8", "--json"], expect=0).stdout)
    check(rep["meshes"] == len(names), "*.ply leaves .hidden.ply out (%d meshes)" % rep["meshes"])
    os.remove(os.path.join(meshes, ".hidden.ply"))
    # A file of the user's at a result's, a summary's or the report's path
    # is refused before any work: with -o the meshes' folder, a.ply beside
    # a.obj was replaced by a.obj's result (an outside audit). A batch's own
    # files are replaced by a re-run, also after a kill between the summary
    # and the result (the summary, saying "running", is written first).
    own = os.path.join(tmp, "own_files")
    os.makedirs(own)
    with open(os.path.join(own, "tent.obj"), "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.5\nf 1 2 3\nf 1 3 4\nf 1 2 5\nf 2 3 5\n")
    base = ["ao", "--dir", own, "--glob", "*.obj", "-o", own, "--rays_per_vertex", "8"]
    for name, content in (("tent.ply", "my scan\n"), ("tent.json", '{"mine": true}'), ("report-0-of-1.json", "[]")):
        path = os.path.join(own, name)
        with open(path, "w") as f:
            f.write(content)
        one_line(base, name, "a file of the user's at the batch's path " + name)
        check(open(path).read() == content, name + " is kept")
        os.remove(path)
    run([a.gi, "batch"] + base, expect=0)
    with open(os.path.join(own, "tent.json")) as f:
        summary = json.load(f)
    summary["status"] = "running"  # as a kill between the summary and the result leaves it
    with open(os.path.join(own, "tent.json"), "w") as f:
        json.dump(summary, f)
    rep = json.loads(run([a.gi, "batch"] + base + ["--json"], expect=0).stdout)
    check(rep["baked"] == 1 and load(os.path.join(own, "tent.json"))["status"] == "ok",
          "a result whose summary says running is the batch's: baked again (%s)" % rep)


def case_keep(a, tmp):
    meshes = os.path.join(tmp, "keep_meshes")
    names = copy_meshes(a.meshes, meshes, SMALL[:3])
    out = os.path.join(tmp, "keep_out")
    cmd = [a.gi, "batch", "ao", "--dir", meshes, "-o", out, "--rays_per_vertex", "8", "--json"]
    rep = json.loads(run(cmd, expect=0).stdout)
    check(rep["baked"] == len(names), "baked %d" % rep["baked"])
    plys = {n: os.path.join(out, n + ".ply") for n in names}
    stamps = {n: stamp(p) for n, p in plys.items()}
    # A typo in a value every mesh takes: refused before any work (each mesh
    # failed in turn and its finished result was deleted; an outside audit).
    bad = cmd[:]
    bad[bad.index("8")] = "0"
    p = run(bad)
    check(p.returncode == 1 and p.stderr.count("\n") == 1 and "rays_per_vertex" in p.stderr,
          "an out-of-range common value: one line before any work (%s)" % p.stderr.strip())
    check(all(os.path.exists(p) and stamp(p) == stamps[n] for n, p in plys.items()), "every result kept")
    # A mesh that fails in a later run (its input gone): its earlier result stays, the summary says so.
    gone = os.path.join(meshes, names[0] + ".ply")
    os.rename(gone, gone + ".away")
    other = cmd[:]
    other[other.index("8")] = "9"
    other[other.index("--dir"):other.index("--dir") + 2] = ["--manifest", os.path.join(meshes, "list.txt")]
    with open(os.path.join(meshes, "list.txt"), "w") as f:
        f.write("".join("%s.ply   # mesh %d\n" % (n, k) for k, n in enumerate(names)))
    p = run(other)
    rep = json.loads(p.stdout)
    check(p.returncode == 1 and rep["failed"] == 1 and rep["baked"] == len(names) - 1,
          "one mesh failed, the others baked; a comment after a line's name is no parameter (%s)" %
          {k: rep[k] for k in ("failed", "baked")})
    s = load(os.path.join(out, names[0] + ".json"))
    check(os.path.exists(plys[names[0]]) and stamp(plys[names[0]]) == stamps[names[0]],
          "the failed mesh's earlier result is kept")
    check(s["status"] == "failed" and "is kept" in s["error"] and s.get("earlier_run", {}).get("status") == "ok" and
          s["earlier_run"]["parameters"]["rays_per_vertex"] == "8",
          "its summary says so and keeps the earlier run's (%s)" % s["error"])
    os.rename(gone + ".away", gone)
    # A value may start with # (a colour): only a # where a name would come is a comment.
    sky = os.path.join(meshes, "sky.txt")
    with open(sky, "w") as f:
        f.write("%s.ply --sky_color #ff8800   # orange sky\n" % names[1])
    rep = json.loads(run([a.gi, "batch", "sky", "--manifest", sky, "-o", os.path.join(tmp, "keep_sky"), "--rays_per_vertex",
                          "8", "--json"], expect=0).stdout)
    s = load(os.path.join(tmp, "keep_sky", names[1] + ".json"))
    check(rep["baked"] == 1 and s["parameters"].get("sky_color") == "#ff8800",
          "a colour #ff8800 on a manifest line is a value, the # after it a comment (%s)" % s.get("parameters"))
    # A quoted name may start with # (only a line whose first character is #
    # is a comment): "#1.ply" was dropped in silence.
    hashed = os.path.join(tmp, "hash_names")
    os.makedirs(hashed)
    shutil.copy(os.path.join(meshes, names[1] + ".ply"), os.path.join(hashed, "#1.ply"))
    with open(os.path.join(hashed, "list.txt"), "w") as f:
        f.write('# a comment\n  # an indented comment\n"#1.ply"\n')
    rep = json.loads(run([a.gi, "batch", "sky", "--manifest", os.path.join(hashed, "list.txt"), "-o",
                          os.path.join(tmp, "hash_out"), "--rays_per_vertex", "8", "--json"], expect=0).stdout)
    check(rep["baked"] == 1 and os.path.exists(os.path.join(tmp, "hash_out", "#1.ply")),
          "a quoted name starting with # is a mesh, the lines starting with # comments (%s)" %
          {k: rep[k] for k in ("baked", "failed")})
    # The error map's reference file: relative to the manifest, and part of
    # the hash (a reference computed anew was taken as done before).
    refdir = os.path.join(tmp, "keep_ref")
    os.makedirs(refdir)
    shutil.copy(os.path.join(a.meshes, "cornell_box.ply"), os.path.join(refdir, "box.ply"))
    box = os.path.join(refdir, "box.ply")
    ref = os.path.join(refdir, "ref.ply")
    run([a.gi, "reference", box, "-o", ref, "--samples_per_vertex", "4", "--seed", "1"], expect=0)
    run([a.gi, "radiosity", box, "-o", os.path.join(refdir, "lit.ply")], expect=0)
    with open(os.path.join(refdir, "list.txt"), "w") as f:
        f.write('lit.ply --reference_source "PLY file" --reference_file ref.ply --reference_attribute Reference\n')
    emout = os.path.join(tmp, "keep_em")
    em = [a.gi, "batch", "errormap", "--manifest", os.path.join(refdir, "list.txt"), "-o", emout, "--json"]
    rep = json.loads(run(em, expect=0).stdout)
    check(rep["baked"] == 1, "the error map's reference_file is found beside the manifest (%s)" % rep)
    first = load(os.path.join(emout, "lit.json"))["stats"]["rms_error"]
    time.sleep(0.05)
    run([a.gi, "reference", box, "-o", ref, "--samples_per_vertex", "4", "--seed", "2"], expect=0)
    rep = json.loads(run(em, expect=0).stdout)
    second = load(os.path.join(emout, "lit.json"))["stats"]["rms_error"]
    check(rep["baked"] == 1 and rep["done_before"] == 0 and second != first,
          "a reference computed anew is compared anew (rms %g, then %g)" % (first, second))
    # A parameter that writes one file for every mesh is refused.
    p = run([a.gi, "batch", "radiosity", "--dir", meshes, "-o", os.path.join(tmp, "keep_csv"), "--residual_csv", "r.csv"])
    check(p.returncode == 1 and p.stderr.count("\n") == 1 and "residual_csv" in p.stderr,
          "residual_csv in a batch: one line (%s)" % p.stderr.strip())
    # --report-only writes report.json: a mesh named report, whose summary
    # would be report.json, is refused by the baking run and by
    # --report-only alike (the baking run took it until 7 December 2026),
    # in one line, before anything is written.
    shutil.copy(os.path.join(meshes, names[1] + ".ply"), os.path.join(meshes, "report.ply"))
    summary = os.path.join(out, "report.json")
    for extra in ([], ["--report-only"]):
        p = run(cmd + extra)
        check(p.returncode == 1 and p.stderr.count("\n") == 1 and "report.json" in p.stderr and
              not os.path.exists(summary), "a mesh named report%s: refused in one line, nothing written (%s)" %
              (" with --report-only" if extra else "", p.stderr.strip()))
    os.remove(os.path.join(meshes, "report.ply"))


CASES = {"basic": case_basic, "kill": case_kill, "shards": case_shards, "inputs": case_inputs, "keep": case_keep}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", required=True)
    ap.add_argument("--meshes", required=True)
    ap.add_argument("cases", nargs="*")
    a = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="gi_batch_")
    try:
        for c in a.cases or CASES:
            print("== " + c, flush=True)
            CASES[c](a, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILED:
        print("%d checks failed" % len(FAILED))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
