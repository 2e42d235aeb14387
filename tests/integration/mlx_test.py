#!/usr/bin/env python3
"""meshlabserver integration tests: each filter runs from a complete .mlx
script (written by `gi script`) in the real, staged meshlabserver under
xvfb-run, and the saved PLY must carry per-vertex quality and colour with the
values expected for the scene. Bad inputs must fail with a non-zero exit and
a clear reason in the log.

usage: mlx_test.py CASE --build BUILD_DIR --meshes TEST_MESHES_DIR
"""
import argparse
import math
import re
import os
import subprocess
import sys
import tempfile

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
    files = os.listdir(cache)
    with open(os.path.join(cache, files[0])) as f:
        ref = json.load(f)
    at = ref["attributes"]
    check(ref["format"] == "gi-result" and len(at["StdError"]["values"]) == len(v) and min(at["Paths"]["values"]) >= 64
          and len(at["Radiosity"]["values"]) == 3 * len(v) and len(at["Irradiance"]["values"]) == 3 * len(v),
          "result file holds B, H, standard errors and path counts")


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


def case_examples(c):
    # Every shipped example script runs in meshlabserver on the mesh it names.
    root = os.path.dirname(c.meshes)
    ex = os.path.join(root, "examples")
    meshes = {"ambient_occlusion": "bunny", "ambient_occlusion_adaptive": "bunny", "ambient_occlusion_shared": "bunny", "thickness": "bunny", "obscurance_bunny": "bunny",
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


def run_gi(c, args):
    p = subprocess.run([c.gi] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return p


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
    # Non-convergence is a warning in the JSON: rho 0.999 stopped by the bounds set here.
    white = lit + ["--reflectance", "255,255,255"]
    p = run_gi(c, ["radiosity", box, "-q", "--json", "--max_iterations", "50"] + white)
    w = json.loads(p.stdout)["warnings"]
    check(p.returncode == 0 and len(w) == 1 and "not converged" in w[0], "radiosity stopped early warns: %s" % w[:1])
    p = run_gi(c, ["reference", box, "-q", "--json", "--max_depth", "20", "--samples_per_vertex", "4"] + white)
    w = json.loads(p.stdout)["warnings"]
    check(p.returncode == 0 and len(w) == 1 and "max_depth = 20" in w[0], "reference cut by max_depth warns: %s" % w[:1])


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


CASES = {"raytrace": case_raytrace, "cli": case_cli, "examples": case_examples, "layers": case_layers, "reference": case_reference, "formfactors": case_formfactors, "ao": case_ao, "obscurance_sky": case_obscurance_sky, "radiosity": case_radiosity, "refine": case_refine,
         "photonmap": case_photonmap, "caustic": case_caustic, "bad_input": case_bad_input, "dump": case_dump,
         "robust": case_robust}

if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=sorted(CASES))
    ap.add_argument("--build", required=True)
    ap.add_argument("--meshes", required=True)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        CASES[a.case](Ctx(a.build, a.meshes, tmp))
    print("PASS")
