"""meshlabserver integration tests of radiosity and what is built on it: the
solution on the Cornell box, form factors, mesh refinement and the two-pass
ray-traced view (cases of mlx_test.py)."""
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mlx_common import check, fail, nearest, read_pfm, run_gi, vertices  # noqa: E402
from plyread import read_ply  # noqa: E402


def case_radiosity(c):
    mesh = os.path.join(c.meshes, "cornell_box.ply")
    # Bounces 0: direct light only, the ceiling stays dark.
    out0 = os.path.join(c.tmp, "rad0.ply")
    log = c.server(mesh, c.script("rad0", "radiosity", "--mesh", mesh, "--emitter_source", "Face quality above threshold",
                                  "--bounces", "0", "--rays_per_patch", "256"), out0)
    check("GI: Radiosity:" in log and "12 emitter faces" in log, "radiosity log names the emitters")
    v0 = vertices(out0)
    floor0 = nearest(v0, (400, 0, 150))
    ceil0 = nearest(v0, (100, 548.8, 100))
    check(floor0["quality"] > 0.2, "floor under the light is lit (B = %.3f W/m^2)" % floor0["quality"])
    check(ceil0["quality"] < 0.01 * floor0["quality"], "0 bounces: the ceiling gets no light (B = %.4f)" % ceil0["quality"])
    # All bounces (default): the ceiling is lit by inter-reflection; the log accounts for the energy.
    out = os.path.join(c.tmp, "rad.ply")
    log = c.server(mesh, c.script("rad", "radiosity", "--mesh", mesh, "--emitter_source", "1", "--rays_per_patch", "256",
                                  "--face_output", "true"), out, mask=("vc", "vq", "fc", "fq"))
    m = re.search(r"energy_balance_error=([0-9.e+-]+)", log)
    check(m is not None and float(m.group(1)) < 0.02, "energy balance in the log (error %s)" % (m.group(1) if m else "?"))
    v = vertices(out)
    ceil = nearest(v, (100, 548.8, 100))
    check(ceil["quality"] > 0.05 * nearest(v, (400, 0, 150))["quality"], "all bounces: the ceiling is lit (B = %.4f)" % ceil["quality"])
    faces = read_ply(out)["face"]
    check(all("quality" in f and "red" in f for f in faces[:1]) and max(f["quality"] for f in faces) > 1.0,
          "per-face quality and colour written with face_output")
    red = nearest(v, (552, 270, 280))
    green = nearest(v, (0, 270, 280))
    check(red["red"] > 2 * red["green"], "the +x wall is red")
    check(green["green"] > 1.2 * green["red"] and green["green"] > 2 * green["blue"], "the x = 0 wall is green")
    # Same engine, same input and seed through the CLI: the same numbers.
    cli = os.path.join(c.tmp, "rad_cli.ply")
    subprocess.run([c.gi, "radiosity", mesh, "-o", cli, "-q", "--emitter_source", "1", "--rays_per_patch", "256"], check=True)
    w = vertices(cli)
    diff = max(abs(a["quality"] - b["quality"]) / max(1e-6, abs(b["quality"])) for a, b in zip(v, w) if b["quality"] > 1e-3)
    check(diff < 1e-3, "meshlabserver and CLI agree (max relative difference %.2g)" % diff)


def case_formfactors(c):
    box = os.path.join(c.meshes, "closed_box.ply")
    out = os.path.join(c.tmp, "ff.ply")
    log = c.server(box, c.script("ff", "formfactors", "--face_index", "5", "--form_factor_method", "Hemicube"), out,
                   mask=("vq", "fq", "fc"))
    m = re.search(r"row sum ([0-9.]+)", log)
    check(m is not None and abs(float(m.group(1)) - 1.0) < 2e-3, "closed box: the row sums to 1 (%s)" % (m.group(1) if m else "?"))
    check("reciprocity error" in log, "reciprocity error logged")
    faces = read_ply(out)["face"]
    check(faces[5]["red"] == 255 and faces[5]["green"] == 0, "the chosen face is marked red")
    check(abs(sum(f["quality"] for f in faces) - 0) > 0 and max(f["quality"] for f in faces) < 1, "F_ij in face quality")
    log = c.server(box, c.script("ff_sel", "formfactors"), expect_ok=False)
    check("select exactly one face" in log, "no selection: clear reason")


def case_refine(c):
    """GI: Radiosity with adaptive mesh refinement: the saved layer is the
    refined mesh; the light, chosen by selection, stays selected, so a second
    run in the same script finds it again."""
    mesh = os.path.join(c.meshes, "cornell_box.ply")
    n_in = len(read_ply(mesh)["face"])
    fast = ["--mesh", mesh, "--emitter_source", "Selected faces", "--rays_per_patch", "256", "--light_samples", "64",
            "--gather_rays", "32"]
    first = open(c.script("ref1", "radiosity", *(fast + ["--refine", "true", "--refine_max_depth", "2"]))).read()
    again = open(c.script("ref2", "radiosity", *fast)).read()
    body = lambda t: t[t.index("<filter"):t.rindex("</filter>") + len("</filter>")]
    select = (' <filter name="Select by Face Quality">\n'
              '  <Param type="RichDynamicFloat" value="0.5" min="0" max="1" name="minQ"/>\n'
              '  <Param type="RichDynamicFloat" value="1.5" min="0" max="2" name="maxQ"/>\n'
              '  <Param type="RichBool" value="true" name="Inclusive"/>\n </filter>\n')
    path = os.path.join(c.tmp, "refine.mlx")
    with open(path, "w") as f:
        f.write("<!DOCTYPE FilterScript>\n<FilterScript>\n" + select + " " + body(first) + "\n " + body(again) +
                "\n</FilterScript>\n")
    out = os.path.join(c.tmp, "refined.ply")
    log = c.server(mesh, path, out, mask=("vc", "vq", "fc", "fq"))
    runs = re.findall(r"(\d+) emitter faces", log)
    check(len(runs) >= 2 and int(runs[0]) == 12, "first run: the 12 selected light faces emit (%s)" % runs)
    check(int(runs[-1]) > 12, "second run on the refined mesh: the light's refined faces are still selected (%s)" % runs[-1])
    check("refinement stopped" in log and "faces refined" in log, "the log reports the refinement levels")
    ply = read_ply(out)
    v, faces = ply["vertex"], ply["face"]
    check(len(faces) > n_in, "the saved layer is refined: %d faces from %d" % (len(faces), n_in))
    check(all(math.isfinite(r["quality"]) for r in v), "finite vertex quality everywhere")
    light = [r for r in v if r["y"] > 548 and 213 < r["x"] < 343 and 227 < r["z"] < 332]
    floor = nearest(v, (400, 0, 150))
    check(light and min(r["quality"] for r in light) > 10 * floor["quality"],
          "the light still emits (B >= %.1f on %d light vertices, floor %.2f)" %
          (min(r["quality"] for r in light) if light else 0, len(light), floor["quality"]))
    check(sum(1 for f in faces if f["quality"] > 0.5) > 12, "face quality (the light's mark) carried to its refined faces")
    def border_length(p):
        pv, pf = p["vertex"], p["face"]
        used = {}
        for f in pf:
            t = f["vertex_indices"]
            for k in range(3):
                e = (min(t[k], t[(k + 1) % 3]), max(t[k], t[(k + 1) % 3]))
                used[e] = used.get(e, 0) + 1
        return sum(math.dist([pv[a][x] for x in "xyz"], [pv[b][x] for x in "xyz"]) for (a, b), n in used.items() if n == 1)
    lin, lout = border_length(read_ply(mesh)), border_length(ply)
    check(abs(lout - lin) < 1e-4 * lin, "no T-junctions: the border length stays %.1f (now %.1f)" % (lin, lout))
    colours_in = {(f["red"], f["green"], f["blue"]) for f in read_ply(mesh)["face"]}
    colours_out = {(f["red"], f["green"], f["blue"]) for f in faces}
    check(colours_out <= colours_in and len(colours_out) == len(colours_in),
          "face colours (the reflectance) carried from the source faces (%d colours)" % len(colours_out))
    # Two layers, all visible: the ceiling with the light (layer 0) and the rest (layer 1); each is replaced
    # by its own refined part and receives its result.
    box = read_ply(mesh)
    bv, bf = box["vertex"], box["face"]
    paths = []
    for name, top in (("top", True), ("rest", False)):
        faces = [t for t in bf if all(bv[i]["y"] > 548 for i in t["vertex_indices"]) == top]
        used = sorted({i for t in faces for i in t["vertex_indices"]})
        remap = {o: n for n, o in enumerate(used)}
        path = os.path.join(c.tmp, name + ".ply")
        with open(path, "w") as fh:
            fh.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face %d\nproperty list uchar int vertex_indices\nproperty float quality\nend_header\n"
                     % (len(used), len(faces)))
            for i in used:
                fh.write("%r %r %r\n" % (bv[i]["x"], bv[i]["y"], bv[i]["z"]))
            for t in faces:
                fh.write("3 %s %r\n" % (" ".join(str(remap[i]) for i in t["vertex_indices"]), t["quality"]))
        paths.append((path, len(faces)))
    two = c.script("ref_layers", "radiosity", "--mesh", mesh, "--scene_extent", "All visible layers", "--emitter_source",
                   "1", "--rays_per_patch", "128", "--light_samples", "64", "--gather_rays", "16", "--refine", "true",
                   "--refine_max_depth", "1")
    for layer, (path, n) in enumerate(paths):
        out = os.path.join(c.tmp, "ref_layer%d.ply" % layer)
        p = subprocess.run([c.mlx_run, "-i", paths[0][0], "-i", paths[1][0], "-o", out, "-l", str(layer), "-m", "vq", "fq",
                            "-s", two], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
        if p.returncode != 0:
            fail("meshlabserver failed:\n" + p.stdout.decode("utf-8", "replace")[-2000:])
        ply = read_ply(out)
        q = [r["quality"] for r in ply["vertex"]]
        check(len(ply["face"]) > n and all(math.isfinite(x) for x in q) and max(q) > 0,
              "layer %d refined on its own (%d faces from %d) and lit (max B %.2f)" % (layer, len(ply["face"]), n, max(q)))
    # The CLI writes the refined mesh too, and it can be lit again.
    cli = os.path.join(c.tmp, "refined_cli.ply")
    p = subprocess.run([c.gi, "radiosity", mesh, "-o", cli, "--json", "--emitter_source", "1", "--rays_per_patch", "256",
                        "--refine", "true", "--refine_max_depth", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    check(p.returncode == 0, "gi radiosity --refine true runs")
    import json
    j = json.loads(p.stdout)
    n_cli = len(read_ply(cli)["face"])
    check(n_cli > n_in and n_cli == int(j["stats"]["refined_patches"]),
          "CLI output is the refined mesh (%d faces, stats %d)" % (n_cli, j["stats"]["refined_patches"]))
    p = subprocess.run([c.gi, "radiosity", cli, "-q", "--json", "--emitter_source", "1", "--rays_per_patch", "64"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0 and json.loads(p.stdout)["scene"]["emitter_faces"] > 12,
          "the refined file lights again: its light faces kept their quality")


def case_raytrace(c):
    box = os.path.join(c.meshes, "cornell_box.ply")
    size = ["--width", "64", "--height", "48"]
    # Without a first pass, two-pass rendering says which filter to run first and changes nothing.
    log = c.server(box, c.script("tp0", "render", "--mesh", box, "--mode", "Two-pass", *size), expect_ok=False)
    check("GI: Radiosity" in log and "first pass" in log, "two-pass without a first pass: a clear reason")
    # Radiosity, then the two-pass view in the same script: the Radiosity attribute carries the first pass.
    first = c.script("rad", "radiosity", "--mesh", box, "--rays_per_patch", "256")
    png = os.path.join(c.tmp, "two_pass.png")
    view = c.script("tp", "render", "--mesh", box, "--mode", "Two-pass", "--samples_per_pixel", "16",
                    "--image_path", png, *size)
    both = os.path.join(c.tmp, "rad_tp.mlx")
    with open(first) as f1, open(view) as f2, open(both, "w") as out:
        out.write(f1.read().replace("</FilterScript>\n", "") + "".join(f2.read().splitlines(True)[2:]))
    log = c.server(box, both, os.path.join(c.tmp, "tp.ply"))
    check("GI: Ray Traced View: " in log and "mode Two-pass" in log, "two-pass view logged after the radiosity pass")
    w, h, tp = read_pfm(png[:-4] + ".pfm")
    check((w, h) == (64, 48) and os.path.getsize(png) > 0, "meshlabserver wrote the PNG and the 64 x 48 PFM")
    check(all(math.isfinite(x) and x >= 0 for x in tp), "radiance finite and non-negative")
    # The path-traced view of the same camera: the yardstick. Whole-image means agree within 5%
    # (the two-pass image carries the radiosity solution's own error, about 1-2% on this box).
    ref = os.path.join(c.tmp, "path.png")
    c.server(box, c.script("pt", "render", "--mesh", box, "--mode", "Path traced", "--samples_per_pixel", "256",
                           "--image_path", ref, *size), os.path.join(c.tmp, "pt.ply"))
    _, _, pt = read_pfm(ref[:-4] + ".pfm")
    check(not [f for f in os.listdir(c.tmp) if f.endswith(".tmp")], "images written through temporaries, none left")
    # A file name with the characters XML escapes: `gi script` writes them as entities, MeshLab reads
    # them back, the plugin and the CLI take them (they were refused until 7 December 2026).
    odd = os.path.join(c.tmp, 'R&D <1> "q".png')
    c.server(box, c.script("odd", "render", "--mesh", box, "--samples_per_pixel", "1", "--image_path", odd, *size),
             os.path.join(c.tmp, "odd.ply"))
    check(os.path.getsize(odd) > 0 and os.path.getsize(odd[:-4] + ".pfm") > 0, "meshlabserver wrote " + odd)
    odd_cli = os.path.join(c.tmp, 'cli R&D <1> "q".png')
    p = subprocess.run([c.gi, "render", box, "-q", "-o", os.path.join(c.tmp, "odd_cli.ply"), "--samples_per_pixel",
                        "1", "--image_path", odd_cli] + size, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0 and os.path.getsize(odd_cli) > 0, "the CLI wrote %s (%s)" % (odd_cli, p.stderr.strip()))
    # The plugin checks its output files before any work, as the CLI does (io/output_files.h): a
    # file over the one a loaded layer came from (the residual CSV: an image must be named .png, and
    # one named as the mesh is refused for that), an image in a folder that does not exist.
    copy = os.path.join(c.tmp, "box_copy.ply")
    with open(box, "rb") as f:
        original = f.read()
    with open(copy, "wb") as f:
        f.write(original)
    log = c.server(copy, c.script("over", "radiosity", "--mesh", copy, "--residual_csv", copy), expect_ok=False)
    with open(copy, "rb") as f:
        kept = f.read() == original
    check("would overwrite the input" in log and "layer" in log and kept,
          "a file over the loaded mesh's file is refused, the file kept")
    log = c.server(copy, c.script("overimg", "render", "--mesh", copy, "--image_path", copy, *size), expect_ok=False)
    with open(copy, "rb") as f:
        kept = f.read() == original
    check("written as PNG" in log and "rays" not in log and kept, "an image path not named .png is refused, the file kept")
    log = c.server(box, c.script("nofolder", "render", "--mesh", box, "--image_path",
                                 os.path.join(c.tmp, "none", "i.png"), *size), expect_ok=False)
    check("does not exist" in log and "rays" not in log, "an image in a missing folder is refused before any ray")
    m_tp, m_pt = sum(tp) / len(tp), sum(pt) / len(pt)
    check(abs(m_tp / m_pt - 1) < 0.05, "two-pass and path-traced images agree: mean %.4f vs %.4f" % (m_tp, m_pt))
    # The same two passes through the command-line tool: the first pass read back from its PLY
    # (the attribute Radiosity as the properties Radiosity_x, _y, _z).
    pass1 = os.path.join(c.tmp, "pass1.ply")
    p = run_gi(c, ["radiosity", box, "-o", pass1, "--rays_per_patch", "256", "-q"])
    check(p.returncode == 0, "gi radiosity writes pass1.ply " + p.stderr)
    check(any(k.startswith("Radiosity_") for k in vertices(pass1)[0]), "gi radiosity wrote the Radiosity properties")
    cli_png = os.path.join(c.tmp, "cli_two_pass.png")
    p = run_gi(c, ["render", pass1, "--mode", "Two-pass", "--samples_per_pixel", "16", "--image_path", cli_png, "-q"]
               + size)
    check(p.returncode == 0, "gi render --mode Two-pass reads the first pass from pass1.ply " + p.stderr)
    _, _, cli = read_pfm(cli_png[:-4] + ".pfm")
    m_cli = sum(cli) / len(cli)
    check(abs(m_cli / m_pt - 1) < 0.05, "CLI two-pass (first pass from pass1.ply) and path-traced images agree: "
          "mean %.4f vs %.4f" % (m_cli, m_pt))
    # Same first pass, same camera, same samples: the meshlabserver image, up to the rounding of the
    # positions pass1.ply stores (absolute coordinates in float, re-centred on reading).
    dmax = max(abs(a - b) for a, b in zip(cli, tp))
    check(dmax < 1e-3 * max(tp), "CLI two-pass image matches meshlabserver's (max difference %.3g of %.3g)"
          % (dmax, max(tp)))
    # Without the first pass's properties the CLI says what to run first.
    p = subprocess.run([c.gi, "render", box, "--mode", "Two-pass", "-q"] + size, stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    check(p.returncode == 1 and "first pass" in p.stderr and len(p.stderr.strip().splitlines()) == 1,
          "CLI two-pass on a mesh without a first pass: one line saying what to run first")
