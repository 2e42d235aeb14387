#!/usr/bin/env python3
"""The two front ends share behaviour, not just names: every filter of the
catalogue (`gi filters --json`) runs on the same scene with the same parameters
through the real meshlabserver (a complete .mlx written by `gi script`) and
through the command-line tool. Both call gi::runFilter with the same seed, so
what each writes must be bit-identical:

- vertex quality and vertex colour;
- the vertex normals, where the filter replaces them;
- face quality and face colour, where the filter writes them;
- the per-vertex attributes. meshlabserver cannot save MeshLab's custom
  attributes, so they are read back by copying one into vertex quality with
  MeshLab's own "Per Vertex Quality Function" in a second run (its muparser
  sees scalar attributes as NAME and vector ones as NAME_x, NAME_y, NAME_z).
  MeshLab 2020.09 binds those variables to elements of a growing std::vector,
  one vector for scalars and one for vector components, each in name order,
  so a variable pushed before the vector's last reallocation reads freed
  memory (0 here): with n variables only those from index 2^floor(log2(n-1))
  on are readable (n = 3: the last; n = 6: the last two; vector components
  ordered by attribute name, then component: Radiosity_z before
  RadiosityDirect_x, though "D" sorts before "_"). Seen: BentNormal_x
  and _y read 0 and _z the true value; with Irradiance and Radiosity only
  Radiosity_y and _z are right. The test reads exactly the readable ones and
  requires at least one per filter that writes attributes; the others are
  compared through quality and colour (computed from the same arrays) and,
  for bent normals, through the vertex normals.

- a new layer a filter adds (photon mapping's photons): MeshLab's layer 1
  against the PLY the CLI writes beside its output.

A filter the table below does not name runs with its defaults, so a new
filter is covered the day it enters the catalogue.

usage: parity_test.py --build BUILD_DIR --meshes TEST_MESHES_DIR [--only CLI_NAME]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plyread import read_ply  # noqa: E402

# Per filter: variants of parameters (small sample counts: the test is about
# equality, not accuracy). The second AO variant exercises what the front ends
# once did differently: the colour mapping and the bent normals.
VARIANTS = {
    "ao": [["--rays_per_vertex", "16"],
           ["--rays_per_vertex", "16", "--color_mapping", "1", "--bent_normals_to_vertex_normals", "true"]],
    "obscurance": [["--rays_per_vertex", "16"]],
    "sky": [["--rays_per_vertex", "16", "--sun_rays", "4"]],
    "radiosity": [["--rays_per_patch", "64", "--light_samples", "16", "--gather_rays", "16", "--face_output", "true"],
                  ["--rays_per_patch", "64", "--light_samples", "16", "--gather_rays", "16", "--refine", "true",
                   "--refine_max_depth", "1"],
                  ["--solver", "Hierarchical", "--hierarchy_epsilon", "0.001", "--link_rays", "2", "--light_samples",
                   "16", "--gather_rays", "16", "--face_output", "true"]],
    "photonmap": [["--photons", "20000", "--light_samples", "16"],
                  # The photons as a new layer: MeshLab adds it beside the mesh, the CLI writes cli.Photons.ply.
                  ["--photons", "20000", "--light_samples", "16", "--photon_layer", "true", "--photon_layer_max", "5000"]],
    # On the input errormap_input makes: its quality against another seed's reference file, as z-scores.
    "errormap": [["--reference_source", "PLY file", "--reference_attribute", "quality", "--reference_error", "StdError",
                  "--error_measure", "2"],
                 ["--reference_source", "PLY file", "--reference_attribute", "quality", "--error_measure", "1"]],
    "reference": [["--samples_per_vertex", "8", "--max_depth", "8"]],
    "formfactors": [["--face_index", "5", "--rays_per_patch", "4096"]],
    "hemicube": [["--face_index", "49", "--hemicube_resolution", "32", "--nusselt_resolution", "64"]],
    "render": [["--width", "48", "--height", "32", "--samples_per_pixel", "2", "--vertex_radiance", "true"],
               ["--width", "40", "--height", "40", "--samples_per_pixel", "4", "--mode", "Path traced",
                "--max_depth", "4", "--vertex_radiance", "true"]],
}
STANDARD = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha", "quality", "radius", "flags"}


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
    out = p.stdout.decode("utf-8", "replace")
    if p.returncode != 0:
        fail("%s exited %d:\n%s" % (os.path.basename(cmd[0]), p.returncode, out[-3000:]))
    return out


def quality_function(script, attribute, path):
    """The script with MeshLab's Per Vertex Quality Function copying `attribute` into quality."""
    with open(script) as f:
        text = f.read()
    step = (' <filter name="Per Vertex Quality Function">\n'
            '  <Param type="RichString" value="%s" name="q"/>\n'
            '  <Param type="RichBool" value="false" name="normalize"/>\n'
            '  <Param type="RichBool" value="false" name="map"/>\n'
            '  <Param type="RichBool" value="false" name="onselected"/>\n'
            ' </filter>\n' % attribute)
    with open(path, "w") as f:
        f.write(text.replace("</FilterScript>", step + "</FilterScript>"))
    return path


def errormap_input(gi, mesh, tmp):
    """The error map compares what a mesh carries with a reference: the input is
    a short path-traced reference run's PLY (its quality), the reference file
    another seed's; returns the input and the parameter naming the file."""
    files = []
    for seed in ("1", "2"):
        files.append(os.path.join(tmp, "errormap_ref%s.ply" % seed))
        run([gi, "reference", mesh, "-o", files[-1], "-q", "--samples_per_vertex", "8", "--max_depth", "4",
             "--seed", seed])
    return files[0], ["--reference_file", files[1]]


INPUTS = {"errormap": errormap_input}


def same(label, a, b, what):
    if len(a) != len(b):
        fail("%s: %s: %d values from meshlabserver, %d from the CLI" % (label, what, len(a), len(b)))
    diff = [i for i, (x, y) in enumerate(zip(a, b)) if x != y]
    if diff:
        i = diff[0]
        fail("%s: %s differs at %d of %d elements (first: %d, meshlabserver %r, CLI %r)"
             % (label, what, len(diff), len(a), i, a[i], b[i]))
    print("ok: %s: %s identical (%d values)" % (label, what, len(a)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--meshes", required=True)
    ap.add_argument("--only")
    a = ap.parse_args()
    gi = os.path.join(a.build, "tools", "gi")
    mlx_run = os.path.join(a.build, "mlx-run")
    mesh = os.path.join(a.meshes, "cornell_box.ply")
    filters = json.loads(run([gi, "filters", "--json"]))
    tmp = tempfile.mkdtemp(prefix="gi-parity-")
    for filt in filters:
        name = filt["cli"]
        if a.only and name != a.only:
            continue
        for k, params in enumerate(VARIANTS.get(name, [[]])):
            label = "%s #%d" % (name, k + 1)
            mesh = os.path.join(a.meshes, "cornell_box.ply")
            if name in INPUTS:
                mesh, more = INPUTS[name](gi, mesh, tmp)
                params = params + more
            script = os.path.join(tmp, "%s%d.mlx" % (name, k))
            images = "image" in filt["writes"]
            ml_img, cli_img = os.path.join(tmp, "ml.png"), os.path.join(tmp, "cli.png")
            run([gi, "script", name, "--mesh", mesh, "-o", script] + params + (["--image_path", ml_img] if images else []))
            ml_out, cli_out = os.path.join(tmp, "ml.ply"), os.path.join(tmp, "cli.ply")
            mask = ["vc", "vq", "vn", "fc", "fq"]
            # A new layer (the photons): layer 1 in MeshLab, OUT.Photons.ply beside the CLI's output.
            new_layer = "--photon_layer" in params
            ml_layer = os.path.join(tmp, "ml_layer.ply")
            # "-l N" right after its "-o" picks the layer; after "-m" meshlabserver reads it as a log file.
            first = ["-o", ml_out] + (["-l", "0"] if new_layer else []) + ["-m"] + mask
            more = ["-o", ml_layer, "-l", "1", "-m", "vc", "vq", "vn"] if new_layer else []
            run([mlx_run, "-i", mesh] + first + more + ["-s", script])
            run([gi, name, mesh, "-o", cli_out, "-q"] + params + (["--image_path", cli_img] if images else []))
            if new_layer:
                lm, lc = read_ply(ml_layer)["vertex"], read_ply(cli_out[:-4] + ".Photons.ply")["vertex"]
                for props, what in ((("x", "y", "z"), "layer positions"), (("red", "green", "blue"), "layer colours"),
                                    (("quality",), "layer quality"), (("nx", "ny", "nz"), "layer normals")):
                    same(label, [tuple(r[p] for p in props) for r in lm], [tuple(r[p] for p in props) for r in lc], what)
            if images:
                for ext in (".png", ".pfm"):
                    with open(ml_img[:-4] + ext, "rb") as f1, open(cli_img[:-4] + ext, "rb") as f2:
                        a1, a2 = f1.read(), f2.read()
                    if a1 != a2:
                        fail("%s: the %s images differ (%d and %d bytes)" % (label, ext, len(a1), len(a2)))
                    print("ok: %s: %s image identical (%d bytes)" % (label, ext, len(a1)))
            ml, cli = read_ply(ml_out), read_ply(cli_out)
            writes = set(filt["writes"])
            mv, cv = ml["vertex"], cli["vertex"]
            same(label, [r["quality"] for r in mv], [r["quality"] for r in cv], "vertex quality")
            if "vertex_color" in writes:
                same(label, [(r["red"], r["green"], r["blue"]) for r in mv],
                     [(r["red"], r["green"], r["blue"]) for r in cv], "vertex colour")
            if "--bent_normals_to_vertex_normals" in params and "nx" not in cv[0]:
                fail("%s: the CLI did not write the bent normals into the vertex normals" % label)
            if "nx" in cv[0]:  # the CLI writes normals only where the filter replaced them
                same(label, [(r["nx"], r["ny"], r["nz"]) for r in mv], [(r["nx"], r["ny"], r["nz"]) for r in cv],
                     "vertex normals")
            mf, cf = ml["face"], cli["face"]
            if "quality" in cf[0] and ("face_quality" in writes):
                same(label, [r["quality"] for r in mf], [r["quality"] for r in cf], "face quality")
            if "red" in cf[0] and ("face_color" in writes):
                same(label, [(r["red"], r["green"], r["blue"]) for r in mf],
                     [(r["red"], r["green"], r["blue"]) for r in cf], "face colour")
            # The filter's own attributes: not those the CLI carries over from its input file (MeshLab
            # 2020.09 reads no custom attributes from a PLY, so its mesh has none of them).
            carried = set(read_ply(mesh)["vertex"][0].keys())
            extra = [p for p in cv[0] if p not in STANDARD and p not in carried]
            if not extra and name in ("ao", "reference", "radiosity", "photonmap", "sky", "render"):
                fail("%s: the CLI wrote no per-vertex attribute" % label)
            readable = []
            for group in (sorted(p for p in extra if not p.endswith(("_x", "_y", "_z"))),
                          sorted((p for p in extra if p.endswith(("_x", "_y", "_z"))), key=lambda p: (p[:-2], p[-2:]))):
                first = 1 << ((len(group) - 1).bit_length() - 1) if len(group) > 1 else 0
                readable += group[first:]
            for attr in readable:
                out = os.path.join(tmp, "attr.ply")
                run([mlx_run, "-i", mesh, "-o", out, "-m", "vq", "-s",
                     quality_function(script, attr, os.path.join(tmp, "attr.mlx"))])
                same(label, [r["quality"] for r in read_ply(out)["vertex"]], [r[attr] for r in cv],
                     "attribute " + attr)
    if not a.only or a.only == "photonmap":
        layered(gi, mlx_run, a.meshes, tmp)
    print("parity: every filter writes the same through meshlabserver and the CLI")


def layered(gi, mlx_run, meshes, tmp):
    """Several layers: meshlabserver's 'All visible layers' against the CLI's --layer files. The glossy
    block reaches below the room's lowest vertex, so the union's box is not the first file's: the CLI
    once kept the first file's centre and rounded the other files' coordinates to float a second
    time (one float step), which flipped photon paths through the glass (up to 87% on dark vertices;
    an outside audit)."""
    names = ["caustic_cornell_box.ply", "caustic_cornell_glass_sphere.ply", "caustic_cornell_glossy_block.ply",
             "caustic_cornell_mirror.ply"]
    files = [os.path.join(meshes, n) for n in names]
    # Distances absolute: a script's defaults come from one mesh's box, the CLI's from the union's.
    params = ["--photons", "20000", "--light_samples", "16", "--max_radius", "48"]
    script = os.path.join(tmp, "layered.mlx")
    run([gi, "script", "photonmap", "--mesh", files[0], "-o", script, "--scene_extent", "All visible layers"] + params)
    cli_out = os.path.join(tmp, "layered_cli.ply")
    run([gi, "photonmap", files[0], "-o", cli_out, "-q"] + [x for f in files[1:] for x in ("--layer", f)] + params)
    cv = read_ply(cli_out)["vertex"]
    inputs = [x for f in files for x in ("-i", f)]
    off = 0
    for k, n in enumerate(names):
        out = os.path.join(tmp, "layered_ml%d.ply" % k)
        run([mlx_run] + inputs + ["-o", out, "-l", str(k), "-m", "vc", "vq", "-s", script])
        mv = read_ply(out)["vertex"]
        part = cv[off:off + len(mv)]
        off += len(mv)
        same("photonmap, layers", [r["quality"] for r in mv], [r["quality"] for r in part], "vertex quality of " + n)
    if off != len(cv):
        fail("photonmap, layers: %d vertices in the CLI's output, %d in meshlabserver's layers" % (len(cv), off))


if __name__ == "__main__":
    main()
