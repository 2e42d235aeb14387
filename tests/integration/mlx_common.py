"""The harness of the meshlabserver integration tests (mlx_test.py): the staged
meshlabserver under xvfb-run with a script written by `gi script`, the
command-line tool, checks that print what they verified, and readers of the
files both write (PLY vertices, PFM images)."""
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plyread import read_ply  # noqa: E402


class Ctx:
    def __init__(self, build, meshes, tmp):
        self.build, self.meshes, self.tmp = build, meshes, tmp
        self.gi = os.path.join(build, "tools", "gi")
        self.mlx_run = os.path.join(build, "mlx-run")

    def script(self, name, filt, *params):
        path = os.path.join(self.tmp, name + ".mlx")
        subprocess.run([self.gi, "script", filt, "-o", path] + list(params), check=True)
        return path

    def server(self, mesh, script, out=None, expect_ok=True, mask=("vc", "vq"), layer=None):
        cmd = [self.mlx_run]
        for m in (mesh if isinstance(mesh, list) else [mesh]):
            cmd += ["-i", m]
        if out:
            cmd += ["-o", out] + (["-l", str(layer)] if layer is not None else []) + ["-m"] + list(mask)
        cmd += ["-s", script]
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
        log = p.stdout.decode("utf-8", "replace")
        if expect_ok and p.returncode != 0:
            fail("meshlabserver exited %d:\n%s" % (p.returncode, log[-3000:]))
        if not expect_ok and p.returncode == 0:
            fail("meshlabserver should have failed but exited 0:\n%s" % log[-3000:])
        return log


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)
    print("ok: " + msg)


def vertices(path):
    v = read_ply(path)["vertex"]
    for row in v:
        for k in ("quality", "red", "green", "blue"):
            if k not in row:
                fail("%s lacks vertex property %s" % (path, k))
        if not math.isfinite(row["quality"]):
            fail("non-finite quality in " + path)
    return v


def nearest(verts, p, keep=lambda r: True):
    best = min((r for r in verts if keep(r)),
               key=lambda r: (r["x"] - p[0]) ** 2 + (r["y"] - p[1]) ** 2 + (r["z"] - p[2]) ** 2)
    return best


def run_gi(c, args):
    p = subprocess.run([c.gi] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return p


def read_pfm(path):
    """A colour PFM (as gi writes it: "PF", width height, -1 = little endian, rows bottom to top)."""
    import struct
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(b"\n", 3)
    check(parts[0] == b"PF", "%s is a colour PFM" % os.path.basename(path))
    w, h = (int(x) for x in parts[1].split())
    px = struct.unpack("<%df" % (w * h * 3), parts[3][:w * h * 12])
    return w, h, px


def scaled_box(path, k, n=3):
    """The cube [-k/2, k/2]^3 seen from inside, n x n quads a side, as ASCII PLY (face quality 0)."""
    verts, faces, index = [], [], {}

    def v(p):
        key = tuple(round(x * 2 * n) for x in p)
        if key not in index:
            index[key] = len(verts)
            verts.append(p)
        return index[key]
    for axis in range(3):
        for sign in (-1, 1):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    q = []
                    for (s, t) in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis], p[a], p[b] = 0.5 * sign, s / n - 0.5, t / n - 0.5
                        q.append(v(p))
                    if sign > 0:
                        q.reverse()
                    faces += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                "element face %d\nproperty list uchar int vertex_indices\nproperty float quality\nend_header\n" % (len(verts), len(faces)))
        for p in verts:
            f.write("%.9g %.9g %.9g\n" % tuple(x * k for x in p))
        for t in faces:
            f.write("3 %d %d %d 0\n" % t)
