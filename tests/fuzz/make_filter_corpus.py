#!/usr/bin/env python3
"""Writes the seed corpus of the filters' fuzz target (tests/fuzz/filter_corpus):
for every filter, two small scenes that hold together in the byte layout
fuzz_filters.cpp reads (filter, two option bytes, vertex and face counts,
coordinates, corners, extras): a closed box with a coloured, emitting lid
(second layer), and a floor under a tilted quad; for the error map, its four
attributes follow. Run it again after changing that layout."""
import os

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "filter_corpus")
os.makedirs(out, exist_ok=True)
FILTERS = ["ao", "obscurance", "sky", "thickness", "radiosity", "photonmap", "reference", "formfactors", "render",
           "hemicube", "errormap"]  # the order of kKinds in fuzz_filters.cpp


def coord(x):
    """The byte whose grid value (byte % 9 - 4) / 4 is x (x in -1, -0.75, ..., 1)."""
    return int(round(x * 4)) + 4


def scene(points, faces, extras, face_bytes=b""):
    b = bytes([len(points) - 3, len(faces) - 1])
    b += bytes(coord(c) for p in points for c in p)
    b += bytes(i for f in faces for i in f)
    return b + bytes([extras]) + face_bytes


# A closed box, faces inward; its last two triangles (the lid) in a second
# layer, with face colours and a face quality of 1 on the lid.
box_v = [(x, y, z) for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)]
box_f = [(0, 3, 2), (0, 1, 3), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7),
         (1, 7, 3), (4, 6, 7), (4, 7, 5)]
colours = b"".join(bytes([200, 180, 160]) for _ in box_f)
quality = bytes([coord(0)] * 10 + [coord(1)] * 2)
box = scene(box_v, box_f, 1 | 4 | 32, colours + quality)
# A floor (two triangles) under a tilted quad facing it.
two_v = [(-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1), (-0.5, 0.5, -0.5), (0.5, 0.5, -0.5), (0.5, 0.75, 0.5),
         (-0.5, 0.75, 0.5)]
two_f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7)]
two = scene(two_v, two_f, 0)
for k, name in enumerate(FILTERS):
    for label, body, nv, options in (("box", box, len(box_v), bytes([1, 2])), ("two", two, len(two_v), bytes([3, 1]))):
        if name == "errormap":  # value, its standard error, the reference and its standard error
            body += bytes([coord(0.5)] * nv + [coord(0.25)] * nv + [coord(0.75)] * nv + [coord(0.25)] * nv)
        with open(os.path.join(out, "%s_%s" % (name, label)), "wb") as f:
            f.write(bytes([k]) + options + body)
