#!/usr/bin/env python3
"""The Slurm job array of examples/slurm/ on a real, single-node Slurm that
this test starts and stops itself (Debian's slurm-wlm and munge): munged,
slurmctld and slurmd on this machine with a tiny slurm.conf in a temporary
folder (free ports, no accounting, no cgroups). It submits
bake_array.sbatch as a 4-task array over a manifest of meshes, waits, then
bake_report.sbatch after it (--dependency=afterany), and checks that every
mesh was baked exactly once, by the task its index belongs to, and that the
tasks' reports and the final report add up. Submitting the array again bakes
nothing. Needs root (slurmd launches jobs as their user).

usage: slurm_test.py --gi GI --meshes TEST_MESHES_DIR --examples EXAMPLES_DIR
"""
import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

FAILED = []
MESHES = ["cornell_box", "closed_box", "floor_wall", "bowl", "cylinder_hole", "open_plane", "parallel_plates",
          "perpendicular_plates", "bunny"]
TASKS = 4


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILED.append(what)


def memory_mb():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemTotal:"):
                return max(1, int(line.split()[1]) // 1024 // 2)
    return 1024


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Slurm:
    """munged + slurmctld + slurmd in `root`, stopped by stop()."""

    def __init__(self, root):
        self.root = root
        self.pids = []
        self.env = dict(os.environ, SLURM_CONF=os.path.join(root, "slurm.conf"))

    def fail(self, step, detail):
        logs = ""
        for f in ("munged.log", "slurmctld.log", "slurmd.log"):
            p = os.path.join(self.root, f)
            if os.path.exists(p):
                logs += "\n--- %s (last lines)\n%s" % (f, "".join(open(p, errors="replace").readlines()[-15:]))
        raise RuntimeError("cannot start a single-node Slurm: %s: %s%s" % (step, detail, logs))

    def daemon(self, step, cmd, pidfile):
        p = subprocess.run(cmd, capture_output=True, text=True, env=self.env, timeout=60)
        if p.returncode != 0:
            self.fail(step, (p.stderr or p.stdout).strip())
        for _ in range(100):
            if os.path.exists(pidfile) and open(pidfile).read().strip():
                self.pids.append(int(open(pidfile).read().split()[0]))
                return
            time.sleep(0.1)
        self.fail(step, "no pid file " + pidfile)

    def start(self):
        r = self.root
        for tool in ("munged", "slurmctld", "slurmd", "sbatch", "sinfo"):
            if not shutil.which(tool) and not os.path.exists("/usr/sbin/" + tool):
                self.fail("looking for " + tool, "not installed (scripts/setup.sh installs slurm-wlm and munge)")
        if os.geteuid() != 0:
            self.fail("checking the user", "slurmd must run as root to launch jobs (CI runs the tests as root)")
        os.makedirs(os.path.join(r, "munge"), mode=0o700)
        key = os.path.join(r, "munge", "munge.key")
        with open(key, "wb") as f:
            f.write(os.urandom(1024))
        os.chmod(key, 0o400)
        sock = os.path.join(r, "munge", "munge.socket")
        self.daemon("munged", ["munged", "--force", "--socket=" + sock, "--key-file=" + key,
                               "--pid-file=" + os.path.join(r, "munged.pid"), "--log-file=" + os.path.join(r, "munged.log"),
                               "--seed-file=" + os.path.join(r, "munge", "seed")], os.path.join(r, "munged.pid"))
        host = socket.gethostname().split(".")[0]
        for d in ("state", "spool"):
            os.makedirs(os.path.join(r, d))
        conf = f"""ClusterName=gitest
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
StateSaveLocation={r}/state
SlurmdSpoolDir={r}/spool
SlurmctldPidFile={r}/slurmctld.pid
SlurmdPidFile={r}/slurmd.pid
SlurmctldLogFile={r}/slurmctld.log
SlurmdLogFile={r}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
NodeName={host} NodeAddr=127.0.0.1 CPUs={os.cpu_count()} RealMemory={memory_mb()} State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:4
"""
        with open(self.env["SLURM_CONF"], "w") as f:
            f.write(conf)
        self.daemon("slurmctld", ["slurmctld", "-f", self.env["SLURM_CONF"]], os.path.join(r, "slurmctld.pid"))
        self.daemon("slurmd", ["slurmd", "-f", self.env["SLURM_CONF"], "-N", host], os.path.join(r, "slurmd.pid"))
        deadline = time.time() + 60
        while time.time() < deadline:
            p = self.run(["sinfo", "-h", "-o", "%T"])
            if p.returncode == 0 and p.stdout.strip() in ("idle", "mixed", "allocated"):
                return
            time.sleep(0.5)
        self.fail("waiting for the node", "sinfo says %r" % self.run(["sinfo", "-h", "-o", "%T"]).stdout.strip())

    def run(self, cmd, **kw):
        return subprocess.run(cmd, capture_output=True, text=True, env=self.env, timeout=600, **kw)

    def stop(self):
        self.run(["scancel", "--user=root"])
        for pid in reversed(self.pids):  # slurmd, slurmctld, munged: the ones this test started
            try:
                os.kill(pid, 15)
            except ProcessLookupError:
                pass
        for pid in self.pids:
            for _ in range(50):
                try:
                    os.kill(pid, 0)
                except ProcessLookupError:
                    break
                time.sleep(0.1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", required=True)
    ap.add_argument("--meshes", required=True)
    ap.add_argument("--examples", required=True)
    a = ap.parse_args()
    a.examples, a.meshes = os.path.abspath(a.examples), os.path.abspath(a.meshes)
    tmp = tempfile.mkdtemp(prefix="gi_slurm_")
    os.chmod(tmp, 0o755)
    slurm = Slurm(os.path.join(tmp, "slurm"))
    os.makedirs(slurm.root)
    try:
        slurm.start()
        check(True, "single-node Slurm started (munged, slurmctld, slurmd)")
        work = os.path.join(tmp, "work")
        os.makedirs(os.path.join(work, "meshes"))
        for m in MESHES:
            shutil.copy(os.path.join(a.meshes, m + ".ply"), os.path.join(work, "meshes", m + ".ply"))
        with open(os.path.join(work, "meshes", "list.txt"), "w") as f:
            f.write("\n".join(m + ".ply" for m in MESHES) + "\n")
        slurm.env["GI"] = os.path.abspath(a.gi)
        array = os.path.join(a.examples, "slurm", "bake_array.sbatch")
        report = os.path.join(a.examples, "slurm", "bake_report.sbatch")
        args = ["meshes/list.txt", "out", "ao", "--rays_per_vertex", "16"]

        def submit_array():
            p = slurm.run(["sbatch", "--parsable", "--array=0-%d" % (TASKS - 1), "--cpus-per-task=1", "--mem-per-cpu=256M",
                           "--output=%A_%a.log", array] + args, cwd=work)
            check(p.returncode == 0, "array submitted (%s)" % (p.stderr.strip() or p.stdout.strip()))
            job = p.stdout.strip().split(";")[0]
            p = slurm.run(["sbatch", "--parsable", "--wait", "--dependency=afterany:" + job, "--output=report_%j.log",
                           report] + args, cwd=work)
            check(p.returncode == 0, "report job ran after the array (%s)" % (p.stderr.strip() or p.stdout.strip()))
            logs = "".join(open(os.path.join(work, f)).read() for f in sorted(os.listdir(work)) if f.endswith(".log"))
            return job, logs

        job, logs = submit_array()
        out = os.path.join(work, "out")
        baked = 0
        for i in range(TASKS):
            path = os.path.join(out, "report-%d-of-%d.json" % (i, TASKS))
            if not os.path.exists(path):
                check(False, "task %d wrote its report; logs:\n%s" % (i, logs[-3000:]))
                continue
            rep = json.load(open(path))
            want = len(range(i, len(MESHES), TASKS))
            check(rep["meshes"] == want and rep["baked"] == want and rep["failed"] == 0,
                  "task %d baked its %d meshes (%d)" % (i, want, rep["baked"]))
            baked += rep["baked"]
        check(baked == len(MESHES), "the tasks baked %d meshes in all, each once (%d)" % (len(MESHES), baked))
        rays = 0
        if baked != len(MESHES):
            raise RuntimeError("the array did not bake the collection; logs:\n" + logs[-3000:])
        for k, m in enumerate(MESHES):
            s = json.load(open(os.path.join(out, m + ".json")))
            rays += s["rays"]
            check(s["status"] == "ok" and s["shard"] == "%d/%d" % (k % TASKS, TASKS) and
                  os.path.getsize(os.path.join(out, m + ".ply")) > 0, "%s baked by task %d" % (m, k % TASKS))
        rep = json.load(open(os.path.join(out, "report.json")))
        check(rep["meshes"] == len(MESHES) and rep["done"] == len(MESHES) and rep["failed"] == 0 and rep["missing"] == 0
              and abs(rep["rays_all"] - rays) <= 1e-6 * rays,
              "final report: %d meshes done, %.4g rays (sum of the summaries %.4g)" % (rep["done"], rep["rays_all"], rays))

        submit_array()  # again: everything is there already
        again = sum(json.load(open(os.path.join(out, "report-%d-of-%d.json" % (i, TASKS))))["done_before"]
                    for i in range(TASKS))
        check(again == len(MESHES), "the array submitted again skips all %d meshes (%d)" % (len(MESHES), again))
    except (RuntimeError, OSError, ValueError, KeyError) as e:
        check(False, str(e))
    finally:
        slurm.stop()
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILED:
        print("%d checks failed" % len(FAILED))
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
