#!/usr/bin/env python3
"""The CLI's two passes over a scene of several layers: `gi photonmap` on the
caustic Cornell box (room, glass sphere and mirror as three files) writes
one PLY that records its layers, and `gi render --mode Two-pass` on that
file finds the glass and the mirror by their layer names again (before, the
one file was one layer and the view lost both). A one-file scene records
nothing.

usage: cli_layers_test.py --gi GI --meshes TEST_MESHES_DIR
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("FAILED: %s\n%s" % (" ".join(cmd), p.stderr))
    return p.stdout


def header(path):
    with open(path, "rb") as f:
        data = f.read(1 << 16)
    return data[:data.index(b"end_header\n")].decode()


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
    print("cli layers: ok")


if __name__ == "__main__":
    main()
