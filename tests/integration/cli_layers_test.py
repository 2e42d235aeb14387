#!/usr/bin/env python3
"""The CLI's two passes over a scene of several layers: `gi photonmap` on the
caustic Cornell box (room, glass sphere and mirror as three files) writes
one PLY that records its layers, and `gi render --mode Two-pass` on that
file finds the glass and the mirror by their layer names again (before, the
one file was one layer and the view lost both). A one-file scene records
nothing. Radiosity's refined output (`--refine`) keeps both: the layers'
records, each with the faces refined from its own (new faces were
appended at the end and the records dropped), and the vertex normals the
input file had (a midpoint takes its edge's normalised sum; they were
dropped).

usage: cli_layers_test.py --gi GI --meshes TEST_MESHES_DIR
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plyread import read_ply  # noqa: E402


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("FAILED: %s\n%s" % (" ".join(cmd), p.stderr))
    return p.stdout


def header(path):
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    return data[:data.index(b"end_header\n")].decode()


def check_refined(a, tmp, files):
    refined = os.path.join(tmp, "refined.ply")
    run([a.gi, "radiosity", files[0], "--layer", files[2], "--refine", "true", "--refine_max_depth", "1", "-q",
         "-o", refined])
    recorded = [l.split(" ", 3) for l in header(refined).splitlines() if l.startswith("comment gi_layer ")]
    mesh = read_ply(refined)
    if [r[3] for r in recorded] != [os.path.basename(files[0]), os.path.basename(files[2])]:
        sys.exit("FAILED: the refined output records the layers %r" % recorded)
    counts = [int(r[2]) for r in recorded]
    if sum(counts) != len(mesh["face"]):
        sys.exit("FAILED: the refined layers' faces %r do not add up to its %d faces" % (counts, len(mesh["face"])))
    mirror = read_ply(files[2])["vertex"]
    lo = [min(v[c] for v in mirror) for c in "xyz"]
    hi = [max(v[c] for v in mirror) for c in "xyz"]
    tol = 1e-3 * max(h - l for l, h in zip(lo, hi))
    for face in mesh["face"][counts[0]:]:
        for i in face["vertex_indices"]:
            v = mesh["vertex"][i]
            if any(v[c] < lo[k] - tol or v[c] > hi[k] + tol for k, c in enumerate("xyz")):
                sys.exit("FAILED: a face recorded as the mirror's lies outside the mirror")
    # Vertex normals the input carried survive refinement.
    src = read_ply(os.path.join(a.meshes, "staircase.ply"))
    withNormals = os.path.join(tmp, "stair_normals.ply")
    with open(withNormals, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                "property float nx\nproperty float ny\nproperty float nz\nelement face %d\n"
                "property list uchar int vertex_indices\nproperty float quality\nend_header\n"
                % (len(src["vertex"]), len(src["face"])))
        for v in src["vertex"]:
            f.write("%r %r %r 0 0.6 0.8\n" % (v["x"], v["y"], v["z"]))
        for face in src["face"]:
            f.write("3 %s %r\n" % (" ".join(str(i) for i in face["vertex_indices"]), face.get("quality", 0.0)))
    out = os.path.join(tmp, "stair_refined.ply")
    run([a.gi, "radiosity", withNormals, "--refine", "true", "-q", "-o", out])
    r = read_ply(out)["vertex"]
    if len(r) <= len(src["vertex"]):
        sys.exit("FAILED: the staircase was not refined (%d vertices)" % len(r))
    if "nx" not in r[0]:
        sys.exit("FAILED: the refined staircase lost its vertex normals")
    for v in r:
        if abs(v["nx"]) > 1e-6 or abs(v["ny"] - 0.6) > 1e-6 or abs(v["nz"] - 0.8) > 1e-6:
            sys.exit("FAILED: a refined vertex's normal is (%g, %g, %g), not its parents' (0, 0.6, 0.8)"
                     % (v["nx"], v["ny"], v["nz"]))


def check_chain(a, tmp):
    """A chain of runs keeps what each earlier one left (as a MeshLab layer does): reference, then radiosity,
    then the error map of radiosity against the reference (the reference was lost on the way; an outside audit)."""
    box = os.path.join(a.meshes, "cornell_box.ply")
    ref, rad = os.path.join(tmp, "ref.ply"), os.path.join(tmp, "rad.ply")
    run([a.gi, "reference", box, "--samples_per_vertex", "16", "-q", "-o", ref])
    run([a.gi, "radiosity", ref, "--light_samples", "16", "--gather_rays", "16", "-q", "-o", rad])
    props = [l.split()[-1] for l in header(rad).splitlines() if l.startswith("property")]
    for want in ("Reference", "ReferenceStdError"):
        if want not in props:
            sys.exit("FAILED: radiosity over a reference's PLY dropped %s (%s)" % (want, props))
    # The reference's own error bars belong to its quality, which radiosity replaced.
    for stale in ("StdError", "StdErrorH", "Paths"):
        if stale in props:
            sys.exit("FAILED: radiosity's PLY carries the reference's %s beside its own quality (%s)" % (stale, props))
    out = json.loads(run([a.gi, "errormap", rad, "--error_measure", "2", "--json", "-q",
                          "-o", os.path.join(tmp, "err.ply")]))
    if not 0.0 < out["stats"]["rms_z"] < 50.0:
        sys.exit("FAILED: the error map of the chain: rms_z %r" % out["stats"].get("rms_z"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", required=True)
    ap.add_argument("--meshes", required=True)
    a = ap.parse_args()
    names = ["caustic_cornell_box.ply", "caustic_cornell_glass_sphere.ply", "caustic_cornell_mirror.ply"]
    files = [os.path.join(a.meshes, n) for n in names]
    with tempfile.TemporaryDirectory() as tmp:
        pass1 = os.path.join(tmp, "pass1.ply")
        run([a.gi, "photonmap", files[0], "--layer", files[1], "--layer", files[2], "--photons", "20000", "-q",
             "-o", pass1])
        recorded = [l.split(" ", 3)[3] for l in header(pass1).splitlines() if l.startswith("comment gi_layer ")]
        if recorded != names:
            sys.exit("FAILED: pass1.ply records the layers %r, not %r" % (recorded, names))
        out = json.loads(run([a.gi, "render", pass1, "--mode", "Two-pass", "--width", "32", "--height", "32",
                              "--samples_per_pixel", "1", "--caustic_photons", "20000", "--json", "-q",
                              "--image_path", os.path.join(tmp, "view.png")]))
        log = " ".join(out["log"])
        for want in ["'caustic_cornell_glass_sphere.ply' glass", "'caustic_cornell_mirror.ply' mirror"]:
            if want not in log:
                sys.exit("FAILED: the two-pass view of pass1.ply does not say %r:\n%s" % (want, log))
        single = os.path.join(tmp, "single.ply")
        run([a.gi, "ao", os.path.join(a.meshes, "cornell_box.ply"), "--rays_per_vertex", "8", "-q", "-o", single])
        if "gi_layer" in header(single):
            sys.exit("FAILED: a one-file scene recorded layers")
        check_refined(a, tmp, files)
        check_chain(a, tmp)
    print("cli layers: ok")


if __name__ == "__main__":
    main()
