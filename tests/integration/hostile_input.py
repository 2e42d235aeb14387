#!/usr/bin/env python3
"""Damaged and hostile input against the command-line tool's contract: exit
status 1 and ONE line on stderr saying what is wrong; never a crash, a hang,
a partly loaded mesh or an output file. Each row of CASES: what is damaged,
the files (written here), the arguments, a fragment the line must hold.
Then the outputs (hostile_outputs.py): one that would overwrite an input,
cannot be written or fails half-way, names that are not UTF-8, numbers
beyond single precision, empty batches.

usage: hostile_input.py --gi BUILD/tools/gi [--report] [--mlx-run BUILD/mlx-run]
  --report   print a table of what happens instead of failing on the first miss
  --mlx-run  also give every damaged mesh file to meshlabserver (MeshLab's own
             readers, then our AO filter) and print what happens: a record, not
             a test, since our plugins cannot fix MeshLab's readers
"""
import argparse
import math
import os
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hostile_outputs  # noqa: E402
from plyread import read_ply  # noqa: E402

TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
# A closed unit cube, outward faces (12 triangles).
CUBE_V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_F = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4),
          (2, 6, 7), (2, 7, 3), (0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5)]


def ply_header(fmt, nv, nf, vprops=("float x", "float y", "float z"), index="list uchar int vertex_indices",
               face_colour=False, extra=""):
    h = "ply\nformat %s 1.0\n%selement vertex %d\n" % (fmt, extra, nv)
    h += "".join("property %s\n" % p for p in vprops)
    h += "element face %d\nproperty %s\n" % (nf, index)
    if face_colour:
        h += "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    return h + "end_header\n"


def ascii_ply(verts, faces, face_colour=True, nv=None, nf=None, tokens=None):
    """tokens: vertex coordinate texts replacing the numbers (damaged values)."""
    body = ""
    for i, v in enumerate(verts):
        body += " ".join(tokens[i] if tokens and i < len(tokens) else ["%g" % c for c in v]) + "\n"
    for f in faces:
        body += " ".join(str(x) for x in [len(f)] + list(f)) + (" 200 100 50" if face_colour else "") + "\n"
    return (ply_header("ascii", len(verts) if nv is None else nv, len(faces) if nf is None else nf,
                       face_colour=face_colour) + body).encode()


def binary_ply(verts, faces, face_colour=True, endian="<", count="B", nv=None, nf=None,
               index="list uchar int vertex_indices", counts=None):
    """counts: per-face list counts written instead of len(face) (lying lists)."""
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    body = b"".join(struct.pack(endian + "3f", *v) for v in verts)
    for i, f in enumerate(faces):
        n = counts[i] if counts else len(f)
        body += struct.pack(endian + count, n) + struct.pack(endian + "%di" % len(f), *f)
        if face_colour:
            body += bytes([200, 100, 50])
    return ply_header(fmt, len(verts) if nv is None else nv, len(faces) if nf is None else nf,
                      index=index, face_colour=face_colour).encode() + body


def stl_binary(tris, count=None):
    b = b"STLB hostile-input test".ljust(80, b" ") + struct.pack("<I", len(tris) if count is None else count)
    for t in tris:
        b += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *p) for p in t) + b"\0\0"
    return b


def off(nv, nf, verts, faces):
    return ("OFF\n%d %d 0\n" % (nv, nf) + "".join("%s %s %s\n" % tuple(v) for v in verts) +
            "".join(" ".join(str(x) for x in [len(f)] + list(f)) + "\n" for f in faces)).encode()


CUBE_ASCII = ascii_ply(CUBE_V, CUBE_F, face_colour=True)
CUBE_HEADER_LEN = CUBE_ASCII.index(b"end_header\n") + len(b"end_header\n")
OBJ_TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

# (id, what is damaged, {file: bytes} or None, arguments (FILE = first file, OUT = an output path, DIR = a folder),
#  fragment of the one error line)
CASES = [
    # Faces OpenMesh rejected, in files with face colours: it then wrote the face's colour before the array.
    ("ply_index_out_of_range", "ASCII PLY, face colours, a face index beyond the 3 vertices",
     {"a.ply": ascii_ply(TRI, [(0, 1, 7)])}, None, "face 0 uses vertex index 7"),
    ("ply_index_negative", "ASCII PLY, face colours, a negative face index",
     {"a.ply": ascii_ply(TRI, [(0, -1, 2)])}, None, "face 0 uses vertex index -1"),
    ("ply_index_repeated", "ASCII PLY, face colours, its one face listing a vertex twice (read, left out)",
     {"a.ply": ascii_ply(TRI, [(0, 1, 1)])}, None, "no usable triangles"),
    ("ply_two_indices", "ASCII PLY, face colours, a face of 2 indices",
     {"a.ply": ascii_ply(TRI, [(0, 1)])}, None, "face 0 has 2 vertex indices"),
    ("ply_binary_index_out_of_range", "binary PLY, face colours, a face index beyond the vertices",
     {"a.ply": binary_ply(TRI, [(0, 1, 7)])}, None, "face 0 uses vertex index 7"),
    ("ply_many_bad_faces", "ASCII PLY, face colours, 60 faces with out-of-range indices (OpenMesh printed 49 lines)",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)] + [(0, 1, 9)] * 60)}, None, "face 1 uses vertex index 9"),
    ("ply_vertex_count_high", "ASCII PLY, face colours, the header claims 4 vertices for 3",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], nv=4)}, None, "face 0"),
    ("ply_vertex_count_low", "ASCII PLY, face colours, the header claims 2 vertices for 3",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], nv=2)}, None, "face 0"),
    ("ply_binary_vertex_count_high", "binary PLY, the header claims 1000 vertices for 3",
     {"a.ply": binary_ply(TRI, [(0, 1, 2)], nv=1000)}, None, "more data than the file holds"),
    ("ply_binary_truncated", "binary PLY, face colours, the last 2 bytes missing",
     {"a.ply": binary_ply(TRI, [(0, 1, 2)])[:-2]}, None, "the file ends inside face 0"),
    ("ply_ascii_nan", "ASCII PLY, a coordinate 'nan'",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], tokens=[["nan", "0", "0"]])}, None, "vertex 0: property 'x'"),
    ("ply_ascii_1e39", "ASCII PLY, a float coordinate '1e39' (beyond float)",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], tokens=[["0", "1e39", "0"]])}, None, "vertex 0: property 'y'"),
    ("ply_ascii_word", "ASCII PLY, a coordinate 'zero'",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], tokens=[["0", "0", "zero"]])}, None, "vertex 0: property 'z'"),
    ("ply_binary_nan", "binary PLY, a NaN coordinate",
     {"a.ply": binary_ply([(float("nan"), 0, 0)] + TRI[1:], [(0, 1, 2)])}, None, "vertex 0: property 'x'"),
    ("ply_binary_inf", "binary big-endian PLY, an infinite coordinate",
     {"a.ply": binary_ply([(0, 0, 0), (1, float("inf"), 0), (0, 1, 0)], [(0, 1, 2)], endian=">")}, None,
     "vertex 1: property 'y'"),
    ("ply_property_before_element", "PLY header with a property line before any element",
     {"a.ply": b"ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n0\n"}, None,
     "a property before any element"),
    ("ply_format_control_char", "PLY format line holding a control character",
     {"a.ply": b"ply\nformat ascii\x01 1.0\nelement vertex 0\nend_header\n"}, None, "control character"),
    ("ply_list_count_2_30", "binary PLY under 1 KB, a face list count of 2^30",
     {"a.ply": binary_ply(TRI, [(0, 1, 2)], count="i", index="list int int vertex_indices", counts=[1 << 30])},
     None, "claims 1073741824 items"),
    ("ply_list_count_negative", "binary PLY, a face list count of -5",
     {"a.ply": binary_ply(TRI, [(0, 1, 2)], count="i", index="list int int vertex_indices", counts=[-5])},
     None, "negative count"),
    ("ply_ascii_truncated_half", "ASCII PLY of a closed box, face colours, cut at half its data",
     {"a.ply": CUBE_ASCII[:CUBE_HEADER_LEN + (len(CUBE_ASCII) - CUBE_HEADER_LEN) // 2]}, None, "truncated"),
    ("ply_ascii_truncated_one_face", "ASCII PLY of a closed box, face colours, the last face line missing",
     {"a.ply": CUBE_ASCII[:CUBE_ASCII.rstrip(b"\n").rindex(b"\n") + 1]}, None, "the file ends inside face 11"),
    ("ply_huge_count", "PLY header claiming 10^12 vertices",
     {"a.ply": ply_header("binary_little_endian", 10 ** 12, 0).encode() + b"\0" * 64}, None,
     "more data than the file holds"),
    ("ply_no_end_header", "PLY header without end_header",
     {"a.ply": b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"}, None, "no end_header"),
    ("ply_unknown_type", "PLY property of an unknown type",
     {"a.ply": b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n"}, None,
     "unknown type 'float128'"),
    ("ply_float_indices", "PLY face list of float indices",
     {"a.ply": ascii_ply(TRI, [(0, 1, 2)], face_colour=False).replace(b"uchar int", b"uchar float")}, None,
     "must be a list of integers"),
    ("ply_trailing_data", "binary PLY with bytes after the last face",
     {"a.ply": binary_ply(TRI, [(0, 1, 2)]) + b"\0" * 7}, None, "data follows the last element"),
    ("ply_not_ply", "a .ply file that is not PLY", {"a.ply": b"\x00\xff garbage" + b"\x7f" * 300}, None,
     "not a PLY file"),
    ("ply_point_cloud", "PLY with vertices and no faces",
     {"a.ply": ascii_ply(TRI, [], face_colour=False)}, None, "has no faces"),
    ("empty_file", "a file of 0 bytes", {"a.ply": b""}, None, "empty"),
    ("directory", "a directory as the input", None, ["ao", "DIR"], "is a directory"),
    ("missing_file", "a file that does not exist", None, ["ao", "DIR/none.ply"], "no such file"),
    ("unsupported_extension", "a .txt file", {"a.txt": OBJ_TRI.encode()}, None, "unsupported format"),
    ("obj_word_coordinate", "OBJ with one unparseable coordinate (OpenMesh dropped the vertex)",
     {"a.obj": b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n"}, None, "line 2"),
    ("obj_nan", "OBJ with a NaN coordinate", {"a.obj": b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"}, None, "line 1"),
    ("obj_1e39", "OBJ with a coordinate beyond float", {"a.obj": (OBJ_TRI + "v 1e39 0 0\nf 1 2 3\n").encode()}, None,
     "line 4"),
    ("obj_index_zero", "OBJ face with index 0", {"a.obj": (OBJ_TRI + "f 0 1 2\n").encode()}, None,
     "line 4: vertex index '0'"),
    ("obj_index_beyond", "OBJ face with an index beyond the vertex count", {"a.obj": (OBJ_TRI + "f 1 2 9\n").encode()},
     None, "line 4: vertex index '9'"),
    ("obj_two_refs", "OBJ face of 2 vertices", {"a.obj": (OBJ_TRI + "f 1 2\n").encode()}, None, "line 4"),
    ("obj_repeated", "OBJ, its one face listing a vertex twice (read, left out)", {"a.obj": (OBJ_TRI + "f 1 2 2\n").encode()}, None,
     "1 invalid"),
    ("obj_formfeed_line", "OBJ vertex line starting with a form feed, faces with normals (OpenMesh skipped the vertex, "
     "then wrote its normal past the array: found by fuzzing)",
     {"a.obj": b"v 0 0 0\nv 1 0 0\n\x0cv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n"}, None, "line 3 holds a control character"),
    ("obj_unknown_statement", "OBJ with a statement we do not read", {"a.obj": (OBJ_TRI + "curv 0 1 1 2\nf 1 2 3\n").encode()},
     None, "line 4: unsupported OBJ statement"),
    ("off_counts_high", "OFF whose header claims 5 vertices for 3",
     {"a.off": off(5, 1, TRI, [(0, 1, 2)])}, None, "a count that lies"),
    ("off_counts_low", "OFF whose header claims 2 vertices for 3",
     {"a.off": off(2, 1, TRI, [(0, 1, 2)])}, None, "line 5"),
    ("off_nan", "OFF with a NaN coordinate", {"a.off": off(3, 1, [("nan", 0, 0)] + TRI[1:], [(0, 1, 2)])}, None,
     "line 3"),
    ("off_repeated", "OFF, its one face listing a vertex twice (read, left out)", {"a.off": off(3, 1, TRI, [(0, 2, 2)])}, None,
     "no usable triangles"),
    ("stl_count_lies", "binary STL claiming 5 triangles, holding 2",
     {"a.stl": stl_binary([TRI, [(1, 0, 0), (1, 1, 0), (0, 1, 0)]], count=5)}, None, "triangle count (5"),
    ("stl_nan", "binary STL with a NaN corner",
     {"a.stl": stl_binary([[(float("nan"), 0, 0)] + TRI[1:]])}, None, "triangle 0"),
    ("stl_ascii_truncated", "ASCII STL cut inside a facet",
     {"a.stl": b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"}, None, "endsolid"),
    # The command line itself.
    ("cli_output_empty", "-o ''", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])}, ["ao", "FILE", "-o", ""], "--output is empty"),
    ("cli_output_no_folder", "-o into a folder that does not exist", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "-o", "DIR/no/such/folder/out.ply"], "does not exist"),
    ("cli_output_is_directory", "-o naming a directory", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "-o", "DIR"], "is a directory"),
    ("cli_output_under_file", "-o under a regular file", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "-o", "FILE/out.ply"], "is not a folder"),
    ("cli_save_result_no_folder", "--save-result into a missing folder", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["reference", "FILE", "--save-result", "DIR/no/ref.json"], "does not exist"),
    ("cli_script_output_empty", "script -o ''", None, ["script", "ao", "-o", ""], "--output is empty"),
    ("cli_script_share_without_mesh", "script --max_distance 10% without --mesh", None,
     ["script", "ao", "--max_distance", "10%"], "needs --mesh"),
    ("cli_unknown_subcommand", "a first word that is no subcommand", None, ["nosuch"], "unknown subcommand 'nosuch'"),
    ("cli_ff_table_extreme_ratio", "formfactors-table of a strip 1e-20 wide", None,
     ["formfactors-table", "--perpendicular", "1e-20,1,1"], "more than 1e4 apart"),
    ("cli_ff_table_huge_length", "formfactors-table of 1e30", None,
     ["formfactors-table", "--parallel", "1e30,1,1"], "below 1e12"),
    ("cli_threads_negative", "--threads -1", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])}, ["ao", "FILE", "--threads", "-1"],
     "--threads"),
    ("cli_threads_zero", "--threads 0", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])}, ["ao", "FILE", "--threads", "0"],
     "--threads"),
    ("cli_unknown_option", "an unknown option", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])}, ["ao", "FILE", "--bogus", "1"],
     "--bogus"),
    ("cli_missing_value", "an option without its value", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "--rays_per_vertex"], "rays_per_vertex"),
    ("cli_bad_number", "a parameter that is no number", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "--rays_per_vertex", "abc"], "rays_per_vertex"),
    ("cli_strata_max_rays", "adaptive strata to a target with max_rays below its first round", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["ao", "FILE", "--estimator", "Adaptive strata", "--target_error", "0.01", "--max_rays", "100"], "above max_rays 100"),
    ("cli_strata_obscurance", "obscurance by adaptive strata", {"a.ply": ascii_ply(TRI, [(0, 1, 2)])},
     ["obscurance", "FILE", "--estimator", "Adaptive strata"], "expected one of: Per vertex, Shared with neighbours"),
    ("cli_point_light_beyond_floats", "photon mapping from a point light 1e30 away (photons cannot start there)",
     {"a.ply": CUBE_ASCII}, ["photonmap", "FILE", "--point_position", "1e30,1e30,0", "--point_intensity", "1",
                             "--photons", "1000"], "point_position lies too far"),
    ("cli_no_input", "no input file", None, ["ao"], "input"),
    ("cli_no_subcommand", "no subcommand", None, [], "subcommand"),
    ("cli_bad_layer", "a damaged --layer file", {"a.ply": ascii_ply(TRI, [(0, 1, 2)]), "b.ply": ascii_ply(TRI, [(0, 1, 7)])},
     ["ao", "FILE", "--layer", "DIR/b.ply"], "b.ply: face 0 uses vertex index 7"),
]

# Files that must load (exit 0): the readers' strictness must not reject what MeshLab writes.
GOOD = [  # (id, what, bytes, faces the output must hold: nothing dropped)
    ("meshlab_extras", "binary PLY as MeshLab writes it: vertex quality, flags, float colour with alpha, face texcoord list",
     b"ply\nformat binary_little_endian 1.0\ncomment VCGLIB generated\nelement vertex 3\nproperty float x\n"
     b"property float y\nproperty float z\nproperty float quality\nproperty int flags\nproperty float red\n"
     b"property float green\nproperty float blue\nproperty float alpha\nelement face 1\n"
     b"property list uchar int vertex_indices\nproperty list uchar float texcoord\nproperty int flags\n"
     b"property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\nproperty double quality\n"
     b"end_header\n" +
     b"".join(struct.pack("<3ffi4f", *v, float("nan"), 0, 1, 0.5, 0, 1) for v in TRI) +
     struct.pack("<B3iB6fi4Bd", 3, 0, 1, 2, 6, 0, 0, 1, 0, 0, 1, 0, 10, 20, 30, 255, 1.5), 1),
    ("cube_ascii", "the closed box, complete", CUBE_ASCII, 12),
    ("tri_big_endian", "binary big-endian PLY", binary_ply(TRI, [(0, 1, 2)], endian=">"), 1),
]


def run(cmd, timeout=60):
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
        return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return None, "", "timeout after %d s" % timeout


def lines(text):
    return [l for l in text.splitlines() if l.strip()]


def describe(rc, err):
    if rc is None:
        return "hang (%s)" % err
    if rc < 0:
        return "killed by signal %d" % -rc
    ls = lines(err)
    return "exit %d, %d line%s%s" % (rc, len(ls), "" if len(ls) == 1 else "s", (": " + ls[0][:110]) if ls else "")


def materialize(tmp, cid, files, args):
    d = os.path.join(tmp, cid)
    os.makedirs(d)
    paths = []
    for name, data in (files or {}).items():
        paths.append(os.path.join(d, name))
        with open(paths[-1], "wb") as f:
            f.write(data)
    out = os.path.join(d, "out.ply")
    if args is None:
        args = ["ao", "FILE", "-o", out]
    sub = {"FILE": paths[0] if paths else "", "DIR": d, "OUT": out}
    args = [a.replace("FILE", sub["FILE"]).replace("DIR", sub["DIR"]) if a not in sub else sub[a] for a in args]
    return d, paths, out, args


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gi", required=True)
    ap.add_argument("--report", action="store_true")
    ap.add_argument("--mlx-run")
    o = ap.parse_args()
    failures = []
    with tempfile.TemporaryDirectory(prefix="gi_hostile_") as tmp:
        for cid, what, files, args, fragment in CASES:
            d, paths, out, argv = materialize(tmp, cid, files, args)
            argv += ["--rays_per_vertex", "8", "-q"] if argv[:1] == ["ao"] and "--rays_per_vertex" not in argv else []
            rc, stdout, err = run([o.gi] + argv)
            ls = lines(err)
            ok = (rc == 1 and len(ls) == 1 and fragment in ls[0] and ls[0].startswith("gi: error: ")
                  and not stdout.strip() and not os.path.exists(out))
            if o.report:
                print("| %s | %s | %s |" % (cid, what, describe(rc, err)))
            else:
                print("%s: %s -> %s" % ("ok" if ok else "FAIL", cid, describe(rc, err)))
            if not ok:
                failures.append("%s (%s): expected exit 1 and one line holding %r" % (cid, what, fragment))
        for cid, what, data, faces in GOOD:
            d, paths, out, argv = materialize(tmp, cid, {"a.ply": data}, None)
            rc, stdout, err = run([o.gi] + argv + ["--rays_per_vertex", "8", "-q"])
            ok = rc == 0 and os.path.exists(out) and len(read_ply(out)["face"]) == faces
            print("%s: %s (must load) -> %s" % ("ok" if ok else "FAIL", cid, describe(rc, err)))
            if not ok:
                failures.append("%s (%s): should load" % (cid, what))
        # Outputs: overwriting an input, failed and unwritable writes, names and numbers (hostile_outputs.py).
        failures += hostile_outputs.check_all(os.path.abspath(o.gi), os.path.join(tmp, "outputs"))
        if o.mlx_run:
            meshlabserver_record(o, tmp)
    if failures and not o.report:
        print("FAIL:\n  " + "\n  ".join(failures))
        sys.exit(1)


def meshlabserver_record(o, tmp):
    script = os.path.join(tmp, "ao.mlx")
    subprocess.run([o.gi, "script", "ao", "--rays_per_vertex", "8", "-o", script], check=True)
    print("\n| case | meshlabserver |")
    print("|---|---|")
    for cid, what, files, args, fragment in CASES:
        if not files or args is not None:
            continue
        d = os.path.join(tmp, cid)
        path = os.path.join(d, sorted(files)[0])
        rc, stdout, err = run([o.mlx_run, "-i", path, "-o", os.path.join(d, "mlx_out.ply"), "-m", "vc", "vq",
                               "-s", script], timeout=30)
        log = stdout + err
        gist = [l for l in lines(log) if any(k in l.lower() for k in ("error", "fail", "unable", "cannot", "gi:", "crash",
                                                                       "abort", "segment", "invalid"))]
        print("| %s | %s%s |" % (cid, "hang (killed after 30 s)" if rc is None else
                                 ("signal %d" % -rc if rc < 0 else "exit %d" % rc),
                                 ("; " + " / ".join(g.strip()[:80] for g in gist[:2])) if gist else ""))


if __name__ == "__main__":
    main()
