#!/usr/bin/env python3
"""meshlabserver integration tests: each filter runs from a complete .mlx
script (written by `gi script`) in the real, staged meshlabserver under
xvfb-run, and the saved PLY must carry per-vertex quality and colour with the
values expected for the scene. Bad inputs must fail with a non-zero exit and
a clear reason in the log. The harness is mlx_common.py; the cases of
radiosity and the eye pass are in mlx_radiosity_cases.py, those of mesh
states only MeshLab makes in mlx_mesh_state_cases.py.

usage: mlx_test.py CASE --build BUILD_DIR --meshes TEST_MESHES_DIR
"""
import argparse
import math
import re
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mlx_common import Ctx, check, fail, nearest, run_gi, scaled_box, vertices  # noqa: E402
from mlx_radiosity_cases import case_formfactors, case_radiosity, case_raytrace, case_refine  # noqa: E402
from mlx_mesh_state_cases import case_mesh_states  # noqa: E402
from plyread import read_ply  # noqa: E402


def case_ao(c):
    out = os.path.join(c.tmp, "ao.ply")
    log = c.server(os.path.join(c.meshes, "floor_wall.ply"), c.script("ao", "ao", "--rays_per_vertex", "2048"), out)
    check("GI: Ambient Occlusion: vertices=" in log, "log line with what was computed")
    v = vertices(out)
    check(all(0.0 <= r["quality"] <= 1.0 for r in v), "AO quality in [0, 1]")
    check(all(r["red"] == r["green"] == r["blue"] for r in v), "AO colour is grey")
    # Floor vertex at distance d = 1 from a wall of height 1: 1/2 + d / (2 sqrt(d^2 + 1)) = 0.8536.
    r = nearest(v, (1.0, 0.0, 0.0), lambda r: r["z"] == 0.0 and r["x"] > 0.5)
    d = r["x"]
    expect = 0.5 + d / (2 * math.sqrt(d * d + 1))
    check(abs(r["quality"] - expect) < 0.03, "floor AO %.4f vs analytic %.4f (2048 rays, tol 0.03)" % (r["quality"], expect))
    far = nearest(v, (4.0, 0.0, 0.0), lambda r: r["z"] == 0.0)
    check(far["quality"] > r["quality"], "AO grows away from the wall")
    # The file as MeshLab writes it with more attributes (normals, flags, face
    # colour and quality): the command-line tool's strict reader must load it.
    full = os.path.join(c.tmp, "ao_full.ply")
    c.server(os.path.join(c.meshes, "floor_wall.ply"), c.script("ao_few", "ao", "--rays_per_vertex", "16"), full,
             mask=("vc", "vq", "vn", "vf", "fc", "ff", "fq"))
    p = subprocess.run([c.gi, "ao", full, "-q", "--rays_per_vertex", "16", "-o", os.path.join(c.tmp, "ao_again.ply")],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "gi reads the PLY meshlabserver wrote with flags and face attributes (%s)" % p.stderr.strip())
    # The same floor and wall 1e7 from the origin, as MeshLab holds them (floats): the geometry is already
    # rounded (a float step of 1 there), which the log now says.
    ply = read_ply(os.path.join(c.meshes, "floor_wall.ply"))
    far = os.path.join(c.tmp, "far.ply")
    with open(far, "w") as fh:
        fh.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(ply["vertex"]), len(ply["face"])))
        for r in ply["vertex"]:
            fh.write("%r %r %r\n" % (r["x"] + 1e7, r["y"], r["z"]))
        for t in ply["face"]:
            fh.write("3 %s\n" % " ".join(str(i) for i in t["vertex_indices"]))
    log = c.server(far, c.script("ao_far", "ao", "--rays_per_vertex", "8"), os.path.join(c.tmp, "far_out.ply"))
    check("coordinates are floats as far as 1e+07" in log, "MeshLab's float coordinates far from the origin are warned of")
    check("even from a file with double coordinates" in log and "gi command-line tool" in log,
          "the warning says MeshLab rounded them and names the cures")
    # A colour channel beyond 255 in a hand-edited script: Qt's colour is then
    # invalid and read as black (a reflectance of 0, without a word); refused.
    script = c.script("rho_300", "radiosity")
    with open(script) as fh:
        text = fh.read()
    text, n = re.subn(r'(<Param type="RichColor" r=")\d+("[^>]*name="reflectance")', r"\g<1>300\2", text)
    check(n == 1, "the script holds the reflectance's red channel")
    with open(script, "w") as fh:
        fh.write(text)
    log = c.server(os.path.join(c.meshes, "cornell_box.ply"), script, os.path.join(c.tmp, "rho_300.ply"), expect_ok=False)
    check("'reflectance' is not a colour" in log, "a colour channel of 300 is refused with its name")


def split_floor_wall(c):
    """floor_wall.ply as two layers: the floor (z = 0) and the wall."""
    ply = read_ply(os.path.join(c.meshes, "floor_wall.ply"))
    v, f = ply["vertex"], ply["face"]
    out = []
    for name, keep in (("floor", True), ("wall", False)):
        faces = [t for t in f if all(v[i]["z"] == 0 for i in t["vertex_indices"]) == keep]
        used = sorted({i for t in faces for i in t["vertex_indices"]})
        remap = {o: n for n, o in enumerate(used)}
        path = os.path.join(c.tmp, name + ".ply")
        with open(path, "w") as fh:
            fh.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(used), len(faces)))
            for i in used:
                fh.write("%r %r %r\n" % (v[i]["x"], v[i]["y"], v[i]["z"]))
            for t in faces:
                fh.write("3 %s\n" % " ".join(str(remap[i]) for i in t["vertex_indices"]))
        out.append(path)
    return out


def case_layers(c):
    # Two layers, "All visible layers": the wall (layer 1) occludes the floor (layer 0) and both receive.
    floor, wall = split_floor_wall(c)
    script = c.script("ao_all", "ao", "--scene_extent", "All visible layers", "--rays_per_vertex", "2048")
    results = []
    for layer in ("0", "1"):
        out = os.path.join(c.tmp, "layer%s.ply" % layer)
        p = subprocess.run([c.mlx_run, "-i", floor, "-i", wall, "-o", out, "-l", layer, "-m", "vc", "vq", "-s", script],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
        if p.returncode != 0:
            fail("meshlabserver failed:\n" + p.stdout.decode("utf-8", "replace")[-2000:])
        results.append(vertices(out))
    r = nearest(results[0], (1.0, 0.0, 0.0))
    expect = 0.5 + r["x"] / (2 * math.sqrt(r["x"] ** 2 + 1))
    check(abs(r["quality"] - expect) < 0.03, "the wall layer occludes the floor layer: AO %.4f vs %.4f" % (r["quality"], expect))
    w = nearest(results[1], (0.0, 0.0, 0.5))
    check(0.0 < w["quality"] < 1.0 and w["red"] == w["green"], "the wall layer received its AO too (%.4f)" % w["quality"])
    # A visible point cloud beside them (photon mapping's photon layer is one) takes no part and keeps its
    # colours and quality: "All visible layers" wrote 0s and black over it (an outside audit).
    cloud = os.path.join(c.tmp, "cloud.ply")
    with open(cloud, "w") as fh:
        fh.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                 "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float quality\nend_header\n")
        for x in (0.2, 0.4, 0.6):
            fh.write("%r 0.3 0.2 200 10 30 0.7\n" % x)
    out = os.path.join(c.tmp, "cloud_out.ply")
    p = subprocess.run([c.mlx_run, "-i", floor, "-i", wall, "-i", cloud, "-o", out, "-l", "2", "-m", "vc", "vq",
                        "-s", script], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    log = p.stdout.decode("utf-8", "replace")
    if p.returncode != 0:
        fail("meshlabserver failed with a point cloud layer:\n" + log[-2000:])
    kept = vertices(out)
    check(len(kept) == 3 and all((r["red"], r["green"], r["blue"]) == (200, 10, 30) and abs(r["quality"] - 0.7) < 1e-6
                                 for r in kept), "the point cloud layer kept its colours and quality: %r" % kept[:1])
    check("1 visible layer without faces (point clouds) left out and unchanged" in log, "the log says so")
    # Current layer only (the wall, loaded last): nothing occludes the wall's front but the floor, which is absent.
    script1 = c.script("ao_cur", "ao", "--rays_per_vertex", "256")
    out = os.path.join(c.tmp, "cur.ply")
    p = subprocess.run([c.mlx_run, "-i", floor, "-i", wall, "-o", out, "-l", "1", "-m", "vc", "vq", "-s", script1],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    check(p.returncode == 0 and all(x["quality"] == 1.0 for x in vertices(out)),
          "current layer only: the wall alone is fully open")


def case_obscurance_sky(c):
    out = os.path.join(c.tmp, "ob.ply")
    bowl = os.path.join(c.meshes, "bowl.ply")
    c.server(bowl, c.script("ob", "obscurance", "--mesh", bowl, "--max_distance", "25%"), out)
    v = vertices(out)
    check(all(0.0 <= r["quality"] <= 1.0 for r in v), "obscurance quality in [0, 1]")
    out = os.path.join(c.tmp, "sky.ply")
    log = c.server(os.path.join(c.meshes, "open_plane.ply"),
                   c.script("sky", "sky", "--sky_irradiance", "1", "--sun_irradiance", "2", "--sun_direction", "0,0,1"), out)
    v = vertices(out)
    # Open plane facing +z: E = E_sky + E_sun cos(0) = 3 (luminance, white sky; sun colour is warm, Y < 1).
    check(all(2.5 < r["quality"] <= 3.0 + 1e-3 for r in v), "sky irradiance on an open plane in (2.5, 3]")


def case_photonmap(c):
    mesh = os.path.join(c.meshes, "cornell_box.ply")
    out = os.path.join(c.tmp, "pm.ply")
    log = c.server(mesh, c.script("pm", "photonmap", "--mesh", mesh, "--emitter_source", "1", "--photons", "100000"), out)
    check("GI: Photon Mapping:" in log and "photons_stored=" in log, "photon map log line")
    v = vertices(out)
    ceil = nearest(v, (100, 548.8, 100))
    floor = nearest(v, (400, 0, 150))
    check(floor["quality"] > 0.2, "floor lit by photons (B = %.3f)" % floor["quality"])
    check(ceil["quality"] > 0.0, "indirect light reaches the ceiling (B = %.4f)" % ceil["quality"])


def caustic_layers(c):
    return [os.path.join(c.meshes, "caustic_cornell_%s.ply" % n) for n in ("box", "glass_sphere", "mirror")]


# Light centre (278, 548.7, 279.5) through the glass sphere's centre (185, 180, 200), continued to the floor.
CAUSTIC_FOCUS = (278 + (185 - 278) * 548.7 / 368.7, 0.0, 279.5 + (200 - 279.5) * 548.7 / 368.7)


def case_caustic(c):
    # Three layers (box, glass sphere, mirror) as one scene; the glass and the mirror are found by their
    # layer names. The glass sphere focuses the light onto the floor where geometry says it must.
    layers = caustic_layers(c)
    out = os.path.join(c.tmp, "caustic.ply")
    args = ["--mesh", layers[0], "--scene_extent", "All visible layers", "--emitter_source", "1", "--photons", "300000"]
    log = c.server(layers, c.script("caustic", "photonmap", *args), out, layer=0)
    check("'caustic_cornell_glass_sphere.ply' glass (20480 faces)" in log and "'caustic_cornell_mirror.ply' mirror" in log,
          "the log names the glass and mirror layers")
    m = re.search(r"photons_caustic_map=([0-9.e+]+)", log)
    check(m is not None and float(m.group(1)) > 1000, "caustic map built (%s photons)" % (m.group(1) if m else "?"))
    v = vertices(out)
    focus, under_light = nearest(v, CAUSTIC_FOCUS)["quality"], nearest(v, (278, 0, 279.5))["quality"]
    check(focus > 2 * under_light, "caustic at the predicted focus: B %.3f vs %.3f under the light" % (focus, under_light))
    # Without glass (no layer matches): the sphere is a grey diffuse ball and its shadow is dark.
    out2 = os.path.join(c.tmp, "no_glass.ply")
    c.server(layers, c.script("noglass", "photonmap", *(args + ["--glass_layers", "none"])), out2, layer=0)
    dark = nearest(vertices(out2), CAUSTIC_FOCUS)["quality"]
    check(dark < 0.5 * under_light, "no glass, no caustic: B %.3f in the sphere's shadow" % dark)
    # The CLI: --layer adds files as layers, named by file name.
    import json
    cli = os.path.join(c.tmp, "caustic_cli.ply")
    p = subprocess.run([c.gi, "photonmap", layers[0], "--layer", layers[1], "--layer", layers[2], "--emitter_source", "1",
                        "--photons", "300000", "-o", cli, "-q", "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "gi photonmap with --layer runs")
    j = json.loads(p.stdout)
    check("glass (20480 faces)" in j["setup"] and j["stats"]["photons_caustic_map"] > 1000, "CLI: glass layer and caustic map")
    vc = vertices(cli)
    check(nearest(vc, CAUSTIC_FOCUS)["quality"] > 2 * under_light, "CLI: the same caustic")
    # Progressive photon mapping from meshlabserver.
    out3 = os.path.join(c.tmp, "ppm.ply")
    log = c.server(layers, c.script("ppm", "photonmap", *(args[:-1] + ["100000", "--progressive", "true", "--passes", "4"])),
                   out3, layer=0)
    check("ppm_passes=4" in log and nearest(vertices(out3), CAUSTIC_FOCUS)["quality"] > 2 * under_light,
          "progressive photon mapping: the caustic too")


def case_reference(c):
    import json
    mesh = os.path.join(c.meshes, "cornell_box.ply")
    out = os.path.join(c.tmp, "ref.ply")
    log = c.server(mesh, c.script("ref", "reference", "--mesh", mesh, "--emitter_source", "1", "--samples_per_vertex", "64"), out)
    m = re.search(r"GI: Path Traced Reference: .*?rays_per_second=([0-9.e+]+)", log)
    check(m is not None, "reference log line with rays per second (%s)" % (m.group(1) if m else "?"))
    v = vertices(out)
    check(nearest(v, (400, 0, 150))["quality"] > 0.2 and nearest(v, (100, 548.8, 100))["quality"] > 0.01,
          "floor lit directly, ceiling lit by inter-reflection")
    # CLI: the same numbers, a cached reference file reused the second time.
    cache = os.path.join(c.tmp, "refs")
    os.makedirs(cache)
    cli = os.path.join(c.tmp, "ref_cli.ply")
    args = [c.gi, "reference", mesh, "-o", cli, "--json", "--emitter_source", "1", "--samples_per_vertex", "64", "--cache", cache]
    j1 = json.loads(subprocess.run(args, stdout=subprocess.PIPE, check=True).stdout)
    w = vertices(cli)
    diff = max(abs(a["quality"] - b["quality"]) / max(1e-6, b["quality"]) for a, b in zip(v, w) if b["quality"] > 1e-3)
    check(diff < 1e-3, "meshlabserver and CLI agree (max relative difference %.2g)" % diff)
    j2 = json.loads(subprocess.run(args, stdout=subprocess.PIPE, check=True).stdout)
    check(any("reused the cached result" in n for n in j2["notes"]) and j2["stats"]["rays"] == j1["stats"]["rays"],
          "second run reuses the cached reference")
    # Another build (here the same program with one byte more) does not reuse
    # it: its results may differ (a cache of an older build was reused; a review).
    other = os.path.join(c.tmp, "gi_other_build")
    shutil.copy(c.gi, other)
    with open(other, "ab") as fh:
        fh.write(b"\0")
    os.chmod(other, 0o755)
    j3 = json.loads(subprocess.run([other] + args[1:], stdout=subprocess.PIPE, check=True).stdout)
    check(not any("reused the cached result" in n for n in j3["notes"]), "another build computes anew")
    files = sorted(os.listdir(cache))
    with open(os.path.join(cache, files[0])) as f:
        ref = json.load(f)
    at = ref["attributes"]
    check(ref["format"] == "gi-result" and len(at["StdError"]["values"]) == len(v) and min(at["Paths"]["values"]) >= 64
          and len(at["Radiosity"]["values"]) == 3 * len(v) and len(at["Irradiance"]["values"]) == 3 * len(v),
          "result file holds B, H, standard errors and path counts")


def case_examples(c):
    # Every shipped example script runs in meshlabserver on the mesh it names.
    root = os.path.dirname(c.meshes)
    ex = os.path.join(root, "examples")
    meshes = {"ambient_occlusion": "bunny", "ambient_occlusion_adaptive": "bunny", "ambient_occlusion_shared": "bunny",
              "ambient_occlusion_strata": "bunny", "ambient_occlusion_strata_adaptive": "bunny", "thickness": "bunny", "obscurance_bunny": "bunny",
              "sky_lighting": "floor_wall", "radiosity_cornell": "cornell_box", "radiosity_cornell_one_bounce": "cornell_box",
              "photonmap_cornell": "cornell_box", "reference_cornell": "cornell_box", "form_factors_face0": "closed_box"}
    scripts = sorted(f[:-4] for f in os.listdir(ex) if f.endswith(".mlx"))
    for name in scripts:
        # The artefact pack's scripts are named after their scene (shadow_leak_refined.mlx: shadow_leak.ply).
        pack = [s for s in ("shadow_leak", "staircase") if name.startswith(s + "_")]
        mesh = os.path.join(c.meshes, (pack[0] if pack else meshes.get(name, "cornell_box")) + ".ply")
        if "caustic" in name:  # three layers
            mesh = caustic_layers(c)
        out = os.path.join(c.tmp, name + ".ply")
        if name == "radiosity_selected_faces":  # needs a selection: without one it must say so
            log = c.server(mesh, os.path.join(ex, name + ".mlx"), out, expect_ok=False)
            check("no emitters" in log, "%s without a selection explains itself" % name)
            continue
        c.server(mesh, os.path.join(ex, name + ".mlx"), out)
        check(len(vertices(out)) > 0, "example %s runs" % name)


def case_bad_input(c):
    # A point cloud, an empty mesh, an invalid parameter, a scene without emitters.
    pc = os.path.join(c.tmp, "points.ply")
    with open(pc, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
    log = c.server(pc, c.script("ao_pc", "ao"), expect_ok=False)
    check("no faces" in log, "point cloud: clear reason in the log")
    empty = os.path.join(c.tmp, "empty.ply")
    with open(empty, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 0\nproperty list uchar int vertex_indices\nend_header\n")
    log = c.server(empty, c.script("ao_empty", "ao"), expect_ok=False)
    check("empty" in log or "no faces" in log, "empty mesh: clear reason in the log")
    bad = c.script("ao_bad", "ao")
    with open(bad) as f:
        text = f.read()
    with open(bad, "w") as f:
        f.write(text.replace('value="256" name="rays_per_vertex"', 'value="0" name="rays_per_vertex"'))
    log = c.server(os.path.join(c.meshes, "open_plane.ply"), bad, expect_ok=False)
    check("rays_per_vertex" in log and "outside" in log, "invalid parameter: named in the log")
    log = c.server(os.path.join(c.meshes, "open_plane.ply"), c.script("rad_none", "radiosity"), expect_ok=False)
    check("no emitters" in log, "no emitter: clear reason in the log")


def case_dump(c):
    dump = os.path.join(c.tmp, "filters.txt")
    p = subprocess.run([c.mlx_run, "-d", dump], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=120)
    with open(dump, encoding="utf-8", errors="replace") as f:
        text = f.read()
    for name in ("GI: Ambient Occlusion", "GI: Ambient Obscurance", "GI: Sky Lighting", "GI: Radiosity", "GI: Photon Mapping",
                 "GI: Path Traced Reference", "GI: Form Factors of Selected Face"):
        check(name in text, "meshlabserver -d lists '%s'" % name)
    for param in ("rays_per_vertex", "emitter_source", "photons", "sun_direction"):
        check(".mlx name: " + param in text, "meshlabserver -d lists parameter %s" % param)


def case_cli(c):
    import json
    p = subprocess.run([c.gi, "--help"], stdout=subprocess.PIPE, text=True)
    check(p.returncode == 0 and "radiosity" in p.stdout and "photonmap" in p.stdout, "gi --help lists the subcommands")
    p = subprocess.run([c.gi, "ao", "--help"], stdout=subprocess.PIPE, text=True)
    check("--rays_per_vertex" in p.stdout and "default: 256" in p.stdout, "gi ao --help shows parameters and defaults")
    mesh = os.path.join(c.meshes, "floor_wall.ply")
    out = os.path.join(c.tmp, "cli.ply")
    p = subprocess.run([c.gi, "ao", mesh, "-o", out, "--json", "--rays_per_vertex", "64", "--max_distance", "10%"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "gi ao runs")
    j = json.loads(p.stdout)
    check(j["filter"] == "GI: Ambient Occlusion" and j["stats"]["rays"] > 0, "--json summary with rays")
    check(abs(j["parameters"]["max_distance"] - 0.1 * j["scene"]["diagonal"]) < 1e-6, "10% means 10% of the diagonal")
    check("%" in p.stderr, "progress on stderr")
    vertices(out)
    for args, words in ((["ao", mesh, "--rays_per_vertex", "0"], "rays_per_vertex"),
                        (["ao", mesh, "--max_distance", "-1"], "max_distance"),
                        (["radiosity", os.path.join(c.meshes, "open_plane.ply")], "no emitters"),
                        (["ao", os.path.join(c.tmp, "missing.ply")], "missing.ply")):
        p = subprocess.run([c.gi] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        lines = [l for l in p.stderr.splitlines() if l.strip()]
        check(p.returncode != 0 and len(lines) == 1 and words in lines[0],
              "bad input %s: exit %d, one line: %s" % (args[-1], p.returncode, lines[-1] if lines else ""))
    # The course's form-factor table: closed form beside the three methods, JSON, every method within its tolerance.
    p = subprocess.run([c.gi, "formfactors-table", "--rays", "16384", "--segments", "16", "--rings", "1",
                        "--parallel", "1,2,0.5", "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "gi formfactors-table runs: %s" % p.stderr[-300:])
    table = json.loads(p.stdout)
    check(len(table) == 3 and all(len(r["methods"]) == 3 and all(m["within"] for m in r["methods"]) for r in table),
          "formfactors-table: three configurations, three methods each, all within tolerance")
    p = subprocess.run([c.gi, "formfactors-table", "--disks", "1,0,1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    check(p.returncode == 1 and len(lines) == 1 and "positive" in lines[0], "formfactors-table bad dimension: one line")
    # Radiosity's course outputs from the CLI: snapshots as PLY properties, the residual CSV, the exported system.
    csv, prefix = os.path.join(c.tmp, "residual.csv"), os.path.join(c.tmp, "system")
    out = os.path.join(c.tmp, "course.ply")
    p = subprocess.run([c.gi, "radiosity", os.path.join(c.meshes, "cornell_box.ply"), "-o", out, "-q", "--emitter_source", "1",
                        "--rays_per_patch", "64", "--vertex_output", "Patch average", "--solver", "Progressive refinement",
                        "--ambient_term", "true", "--snapshot_steps", "0,5", "--residual_csv", csv,
                        "--export_system", prefix], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "radiosity with the course outputs runs: %s" % p.stderr[-300:])
    header = open(out, "rb").read(4000).decode("latin-1")
    check("Radiosity_step_0_x" in header and "Radiosity_step_5_z" in header, "snapshots as PLY vertex properties")
    check(open(csv).readline().strip() == "step,residual", "residual CSV written")
    check(all(os.path.exists(prefix + s) for s in ("_F.mtx", "_E.mtx", "_rho.mtx", "_Esys.mtx", "_B.mtx", "_area.mtx")),
          "linear system exported as Matrix Market files")
    # The light-path split of the reference: four RGB attributes in the PLY.
    out = os.path.join(c.tmp, "paths.ply")
    p = subprocess.run([c.gi, "reference", os.path.join(c.meshes, "cornell_box.ply"), "-o", out, "-q", "--emitter_source", "1",
                        "--samples_per_vertex", "8", "--light_path_split", "true"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    check(p.returncode == 0, "reference with the light-path split runs: %s" % p.stderr[-300:])
    header = open(out, "rb").read(4000).decode("latin-1")
    check(all("Radiosity_%s_z" % k in header for k in ("emitted", "direct", "caustic", "indirect")),
          "light-path split as PLY vertex properties")


def case_robust(c):
    import json
    # Scales: closed boxes 1e-20 and 1e38 across compute like the unit box (they aborted in Embree, wrote NaN
    # or saw an open sky): AO 0 inside, the radiosity furnace B = E / (1 - rho) at every vertex.
    lit = ["--emitter_source", "1", "--emitter_quality_threshold", "-1", "--emitter_intensity", "1",
           "--emitter_color", "255,255,255"]
    rho = ((188 / 255 + 0.055) / 1.055) ** 2.4  # the default constant reflectance, sRGB 188
    for k in ("1e-20", "1e38"):
        box = os.path.join(c.tmp, "box_%s.ply" % k)
        scaled_box(box, float(k))
        out = os.path.join(c.tmp, "ao_%s.ply" % k)
        p = run_gi(c, ["ao", box, "-o", out, "-q", "--rays_per_vertex", "64"])
        check(p.returncode == 0 and all(r["quality"] == 0.0 for r in vertices(out)), "AO 0 inside a box %s across" % k)
        out = os.path.join(c.tmp, "rad_%s.ply" % k)
        p = run_gi(c, ["radiosity", box, "-o", out, "-q", "--json"] + lit)
        exact = 1 / (1 - rho)
        worst = max(abs(r["quality"] / exact - 1) for r in vertices(out))
        check(p.returncode == 0 and worst < 0.02, "radiosity furnace in a box %s across: worst %.4f (tol 0.02)" % (k, worst))
        check(json.loads(p.stdout)["warnings"] == [], "no warning for a converged furnace %s across" % k)
    # A direction of magnitude 1e20 is the direction, not a zero vector (a sun below every horizon).
    mesh = os.path.join(c.meshes, "floor_wall.ply")
    q = []
    for d in ("1e20,1e20,0", "1,1,0"):
        out = os.path.join(c.tmp, "sun.ply")
        p = run_gi(c, ["sky", mesh, "-o", out, "-q", "--sun_direction", d, "--sky_irradiance", "0", "--sun_angular_radius", "0"])
        q.append([r["quality"] for r in vertices(out)])
    check(q[0] == q[1] and max(q[0]) > 0, "--sun_direction 1e20,1e20,0 lights like 1,1,0")
    # Runaway work is refused before it starts: one line, non-zero exit.
    box = os.path.join(c.tmp, "box48.ply")
    scaled_box(box, 1.0, 2)
    for args, words in ((["--refine", "true", "--refine_max_depth", "12", "--refine_max_patches", "100000000"],
                         "may reach 100000000 patches"),
                        (["--form_factor_method", "Hemicube", "--hemicube_resolution", "4096", "--memory_budget_mb", "100"],
                         "memory_budget_mb = 100 is too small")):
        p = run_gi(c, ["radiosity", box, "-q"] + lit + args)
        lines = [l for l in p.stderr.splitlines() if l.strip()]
        check(p.returncode != 0 and len(lines) == 1 and words in lines[0],
              "refused at once: exit %d, one line: %s" % (p.returncode, lines[-1][:120] if lines else ""))
    # Non-convergence is a warning in the JSON: rho 0.999 stopped by the bounds set here (after
    # the warning that white, rho 1, was limited to 0.999).
    white = lit + ["--reflectance", "255,255,255"]
    p = run_gi(c, ["radiosity", box, "-q", "--json", "--max_iterations", "50"] + white)
    w = json.loads(p.stdout)["warnings"]
    check(p.returncode == 0 and len(w) == 2 and "limited to 0.999" in w[0] and "not converged" in w[1],
          "radiosity stopped early warns: %s" % w[1:2])
    p = run_gi(c, ["reference", box, "-q", "--json", "--max_depth", "20", "--samples_per_vertex", "4"] + white)
    w = json.loads(p.stdout)["warnings"]
    check(p.returncode == 0 and len(w) == 2 and "limited to 0.999" in w[0] and "max_depth = 20" in w[1],
          "reference cut by max_depth warns: %s" % w[1:2])


CASES = {"raytrace": case_raytrace, "cli": case_cli, "examples": case_examples, "layers": case_layers, "reference": case_reference, "formfactors": case_formfactors, "ao": case_ao, "obscurance_sky": case_obscurance_sky, "radiosity": case_radiosity, "refine": case_refine,
         "photonmap": case_photonmap, "caustic": case_caustic, "bad_input": case_bad_input, "dump": case_dump,
         "robust": case_robust, "mesh_states": case_mesh_states}

if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--build", required=True)
    ap.add_argument("--meshes", required=True)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        CASES[a.case](Ctx(a.build, a.meshes, tmp))
    print("PASS")
