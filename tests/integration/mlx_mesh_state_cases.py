"""meshlabserver integration tests of mesh states only MeshLab makes: an
attribute of another type under a result's name, texture coordinates and
the layer's own attributes through refinement, a layer's unfrozen
transformation matrix, face numbers after faces were deleted, and a re-run
of a filter that adds a layer (cases of mlx_test.py). MeshLab's own filters make each state before ours run."""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mlx_common import check, vertices  # noqa: E402
from plyread import read_ply  # noqa: E402


def filters_of(path):
    """The <filter> elements of a script gi wrote."""
    t = open(path).read()
    return t[t.index("<filter"):t.rindex("</filter>") + len("</filter>")]


def script(c, name, *parts):
    path = os.path.join(c.tmp, name + ".mlx")
    with open(path, "w") as f:
        f.write("<!DOCTYPE FilterScript>\n<FilterScript>\n" + "\n".join(parts) + "\n</FilterScript>\n")
    return path


def define_attribute(name, expr):
    """MeshLab's 'Define New Per Vertex Attribute': a float attribute."""
    return (' <filter name="Define New Per Vertex Attribute">\n'
            '  <Param type="RichString" value="%s" name="name"/>\n'
            '  <Param type="RichString" value="%s" name="expr"/>\n </filter>' % (name, expr))


def quality_function(expr):
    return (' <filter name="Per Vertex Quality Function">\n'
            '  <Param type="RichString" value="%s" name="q"/>\n'
            '  <Param type="RichBool" value="false" name="normalize"/>\n'
            '  <Param type="RichBool" value="false" name="map"/>\n'
            '  <Param type="RichBool" value="false" name="onselected"/>\n </filter>' % expr)


def set_matrix(tz, freeze, scale_x=1):
    """MeshLab's 'Matrix: Set from translation/rotation/scale' on the current layer."""
    p = "".join('  <Param type="RichFloat" value="%s" name="%s"/>\n' % (v, n) for n, v in
                (("translationX", 0), ("translationY", 0), ("translationZ", tz), ("rotationX", 0), ("rotationY", 0),
                 ("rotationZ", 0), ("scaleX", scale_x), ("scaleY", 1), ("scaleZ", 1)))
    return (' <filter name="Matrix: Set from translation/rotation/scale">\n' + p +
            '  <Param type="RichBool" value="false" name="compose"/>\n'
            '  <Param type="RichBool" value="%s" name="Freeze"/>\n'
            '  <Param type="RichBool" value="false" name="allLayers"/>\n </filter>' % ("true" if freeze else "false"))


def uv(x, y, z):
    """Texture coordinates linear in the position: exact under interpolation."""
    return (x + z) / 1200.0 + 0.01, (y + z) / 1200.0 + 0.01


def textured_box(c, path, per_wedge):
    ply = read_ply(os.path.join(c.meshes, "cornell_box.ply"))
    v, f = ply["vertex"], ply["face"]
    head = ["ply", "format ascii 1.0", "comment TextureFile tex.png", "element vertex %d" % len(v),
            "property float x", "property float y", "property float z", "property float quality"]
    if not per_wedge:
        head += ["property float texture_u", "property float texture_v"]
    head += ["element face %d" % len(f), "property list uchar int vertex_indices"]
    if per_wedge:
        head += ["property list uchar float texcoord"]
    head += ["property float quality", "end_header"]
    lines = head[:]
    for r in v:
        s = "%r %r %r %r" % (r["x"], r["y"], r["z"], r.get("quality", 0.0))
        if not per_wedge:
            s += " %.7f %.7f" % uv(r["x"], r["y"], r["z"])
        lines.append(s)
    for t in f:
        ix = t["vertex_indices"]
        s = "3 %d %d %d" % tuple(ix)
        if per_wedge:
            s += " 6 " + " ".join("%.7f %.7f" % uv(v[i]["x"], v[i]["y"], v[i]["z"]) for i in ix)
        s += " %r" % t.get("quality", 0.0)
        lines.append(s)
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def plate(path, z, up):
    """A 1 x 1 square of 8 x 8 cells at height z, facing up or down."""
    n = 8
    pts = [(i / n, j / n, z) for j in range(n + 1) for i in range(n + 1)]
    tris = []
    for j in range(n):
        for i in range(n):
            a, b, d, e = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i, (j + 1) * (n + 1) + i + 1
            tris += [(a, b, e), (a, e, d)] if up else [(a, e, b), (a, d, e)]
    with open(path, "w") as fh:
        fh.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                 "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(pts), len(tris)))
        fh.writelines("%r %r %r\n" % p for p in pts)
        fh.writelines("3 %d %d %d\n" % t for t in tris)


def case_mesh_states(c):
    box = os.path.join(c.meshes, "cornell_box.ply")
    lit = ["--mesh", box, "--emitter_source", "Face quality above threshold", "--rays_per_patch", "64",
           "--light_samples", "16", "--gather_rays", "16"]
    rad = filters_of(c.script("rad", "radiosity", *lit))

    # 1. A float attribute named as radiosity's three-number result (MeshLab's
    # 'Define New Per Vertex Attribute' offers 'Radiosity'): MeshLab crashed
    # writing three floats into it. Now refused in one sentence, nothing saved.
    path = script(c, "clash", define_attribute("Radiosity", "x"), rad)
    out = os.path.join(c.tmp, "clash.ply")
    p = subprocess.run([c.mlx_run, "-i", box, "-o", out, "-m", "vc", "vq", "-s", path],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    log = p.stdout.decode("utf-8", "replace")
    check(p.returncode not in (0, 134, 139, -6, -11), "refused, not crashed (exit %d)" % p.returncode)
    check("already has a per-vertex attribute 'Radiosity' of another type" in log and "remove or rename" in log,
          "the refusal names the attribute and the remedy")
    check(not os.path.exists(out), "nothing saved")
    # An attribute of the result's own type is the result's to overwrite.
    ao = filters_of(c.script("ao", "ao", "--rays_per_vertex", "16"))
    out = os.path.join(c.tmp, "same_type.ply")
    c.server(box, script(c, "same_type", define_attribute("AmbientOcclusion", "x"), ao), out)
    check(all(0.0 <= r["quality"] <= 1.0 for r in vertices(out)), "a float AmbientOcclusion is overwritten by AO")

    # 2. Refinement keeps texture coordinates (per wedge and per vertex) and
    # the layer's own attributes on the vertices and faces it adds.
    refine = filters_of(c.script("refine", "radiosity", *(lit + ["--refine", "true", "--refine_max_depth", "2"])))
    for per_wedge in (True, False):
        mesh = os.path.join(c.tmp, "tex_%d.ply" % per_wedge)
        textured_box(c, mesh, per_wedge)
        out = os.path.join(c.tmp, "tex_out_%d.ply" % per_wedge)
        c.server(mesh, script(c, "tex_%d" % per_wedge, refine), out, mask=("vc", "vq", "wt" if per_wedge else "vt"))
        ply = read_ply(out)
        v, f = ply["vertex"], ply["face"]
        check(len(f) > 3 * 1508 // 2, "refined: %d faces" % len(f))
        bad = total = 0
        for t in f:
            for j, i in enumerate(t["vertex_indices"]):
                want = uv(v[i]["x"], v[i]["y"], v[i]["z"])
                got = (t["texcoord"][2 * j], t["texcoord"][2 * j + 1]) if per_wedge else (v[i]["texture_u"], v[i]["texture_v"])
                total += 1
                bad += abs(got[0] - want[0]) > 1e-4 or abs(got[1] - want[1]) > 1e-4
        check(bad == 0, "%s texture coordinates interpolated: %d of %d corners wrong" %
              ("per-wedge" if per_wedge else "per-vertex", bad, total))
    out = os.path.join(c.tmp, "attr_out.ply")
    c.server(box, script(c, "attr", define_attribute("myattr", "x"), refine, quality_function("myattr - x")), out)
    v = vertices(out)
    bad = sum(1 for r in v if abs(r["quality"]) > 1e-3 * max(1.0, abs(r["x"])))
    check(len(v) > 1010 and bad == 0, "the layer's attribute (x) mixed onto the %d new vertices: %d wrong" % (len(v) - 1010, bad))

    # 3. A layer moved by an unfrozen matrix is where MeshLab shows it: plate
    # B, 1 above plate A and facing it, moved 4 further away sees almost all
    # sky, as with the matrix frozen (it was computed where it had been).
    a, b = os.path.join(c.tmp, "plate_a.ply"), os.path.join(c.tmp, "plate_b.ply")
    plate(a, 0.0, True)
    plate(b, 1.0, False)
    ao_all = filters_of(c.script("ao_all", "ao", "--scene_extent", "All visible layers", "--rays_per_vertex", "256"))
    means = {}
    for name, moves in (("none", []), ("frozen", [set_matrix(4, True)]), ("unfrozen", [set_matrix(4, False)])):
        out = os.path.join(c.tmp, "plates_%s.ply" % name)
        c.server([a, b], script(c, "plates_" + name, *(moves + [ao_all])), out)
        q = [r["quality"] for r in vertices(out)]
        means[name] = sum(q) / len(q)
    check(means["none"] < 0.9 and means["frozen"] > 0.97, "the plates shade each other only when close: %s" % means)
    check(abs(means["unfrozen"] - means["frozen"]) < 0.002,
          "unfrozen matrix as frozen: mean AO %.4f against %.4f" % (means["unfrozen"], means["frozen"]))
    # A mirroring matrix turns the side the faces face: refused by name.
    log = c.server([a, b], script(c, "plates_mirror", set_matrix(0, False, -1), ao_all), expect_ok=False)
    check("has a mirroring transformation matrix" in log, "an unfrozen mirroring matrix is refused")

    # 4. Deleted faces keep MeshLab's numbers until compacted: face_index
    # 1300 after deleting faces 0 to 199 is MeshLab's face 1300 (it named
    # MeshLab's 1500), the log says 1300 (it said 1100), and the row is the
    # compacted mesh's face 1100's: the deleted faces take no part.
    select = lambda cond: (' <filter name="Conditional Face Selection">\n'
                           '  <Param type="RichString" value="%s" name="condSelect"/>\n </filter>' % cond)
    delete = ' <filter name="Delete Selected Faces">\n </filter>'
    ff = lambda k: filters_of(c.script("ff_%d" % k, "formfactors", "--face_index", str(k), "--rays_per_patch", "256"))
    comp = os.path.join(c.tmp, "compacted.ply")
    c.server(box, script(c, "compact", select("fi &lt; 200"), delete), comp)
    rows = {}
    for name, mesh, parts in (("index", box, [select("fi &lt; 200"), delete, ff(1300)]),
                              ("selected", box, [select("fi &lt; 200"), delete, select("fi == 1300"), ff(-1)]),
                              ("compacted", comp, [ff(1100)])):
        out = os.path.join(c.tmp, "ff_%s.ply" % name)
        log = c.server(mesh, script(c, "ff_" + name, *parts), out)
        m = re.search(r"GI: Form Factors of Selected Face: face=(\d+)", log)
        rows[name] = (int(m.group(1)) if m else None, [r["quality"] for r in vertices(out)])
    check(rows["index"][0] == 1300 and rows["selected"][0] == 1300 and rows["compacted"][0] == 1100,
          "the log names MeshLab's face: %s" % [rows[k][0] for k in rows])
    check(rows["index"][1] == rows["compacted"][1] and rows["selected"][1] == rows["compacted"][1],
          "the row of MeshLab's face 1300 is the compacted mesh's 1100, bit for bit")
    log = c.server(box, script(c, "ff_deleted", select("fi &lt; 200"), delete, ff(100)), expect_ok=False)
    check("face_index 100 names no face of the layers: that face was deleted" in log, "a deleted face is refused by name")

    # 5. A re-run of photon mapping with its photon layer refills the layer
    # the first run made (it stacked Photons(1), Photons(2)...), and never
    # touches a layer of the user's under the same name (here a point cloud
    # a project file labels "Photons").
    proj = os.path.join(c.tmp, "rerun")
    os.makedirs(proj, exist_ok=True)
    shutil.copy(box, os.path.join(proj, "box.ply"))
    with open(os.path.join(proj, "cloud.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 7\nproperty float x\nproperty float y\nproperty float z\n"
                "end_header\n" + "".join("%d 0 0\n" % i for i in range(7)))
    eye = "   <MLMatrix44>\n1 0 0 0 \n0 1 0 0 \n0 0 1 0 \n0 0 0 1 \n</MLMatrix44>\n"
    with open(os.path.join(proj, "in.mlp"), "w") as f:  # the last layer loaded is the current one: the box
        f.write("<!DOCTYPE MeshLabDocument>\n<MeshLabProject>\n <MeshGroup>\n" +
                "".join('  <MLMesh label="%s" filename="%s" visible="1">\n%s  </MLMesh>\n' % (lab, fn, eye)
                        for lab, fn in (("Photons", "cloud.ply"), ("box", "box.ply"))) +
                " </MeshGroup>\n <RasterGroup/>\n</MeshLabProject>\n")
    pm = ["--photons", "20000", "--light_samples", "4", "--photon_layer", "true", "--photon_layer_max", "500"]
    runs = [filters_of(c.script("pm_%d" % s, "photonmap", *(pm + ["--seed", str(s)]))) for s in (1, 2)]
    once = os.path.join(proj, "once.mlp")
    p = subprocess.run([c.mlx_run, "-p", os.path.join(proj, "in.mlp"), "-w", once, "-s", script(c, "pm_once", runs[0])],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    check(p.returncode == 0, "photon mapping with its layer in a project (exit %d)" % p.returncode)
    first = read_ply(os.path.join(proj, "Photons(1)_out.ply"))["vertex"]
    twice = os.path.join(proj, "twice.mlp")
    p = subprocess.run([c.mlx_run, "-p", os.path.join(proj, "in.mlp"), "-w", twice, "-s", script(c, "pm_twice", *runs)],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    log = p.stdout.decode("utf-8", "replace")
    check(p.returncode == 0, "photon mapping run twice (exit %d)" % p.returncode)
    labels = re.findall(r'<MLMesh [^>]*\blabel="([^"]*)"', open(twice).read())  # Qt orders the attributes at random
    check(labels == ["cloud_out.ply", "box_out.ply", "Photons(1)_out.ply"],
          "the second run refills its own layer, no third: %s" % labels)
    check("layer 'Photons(1)' (an earlier run's Photons) refilled" in log, "the log says which layer was refilled")
    second = read_ply(os.path.join(proj, "Photons(1)_out.ply"))["vertex"]
    pos = lambda v: sorted((r["x"], r["y"], r["z"]) for r in v)
    check(len(second) == len(first) == 500 and pos(second) != pos(first),
          "the layer holds the second run's 500 photons (seed 2), not the first's")
    check(len(read_ply(os.path.join(proj, "cloud_out.ply"))["vertex"]) == 7, "the user's 'Photons' layer untouched")
