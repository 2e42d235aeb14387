"""Minimal PLY reader (ASCII and binary little-endian) for the integration
tests: vertex and face elements with scalar properties, face index lists."""
import struct

_FMT = {"char": "b", "uchar": "B", "int8": "b", "uint8": "B", "short": "h", "ushort": "H", "int16": "h",
        "uint16": "H", "int": "i", "uint": "I", "int32": "i", "uint32": "I", "float": "f", "float32": "f",
        "double": "d", "float64": "d"}


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header") + len(b"end_header")
    while data[end:end + 1] in (b"\r", b"\n"):
        end += 1
    header = data[:end].decode("ascii", "replace").splitlines()
    fmt = header[1].split()[1]
    elements = []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "element":
            elements.append({"name": w[1], "count": int(w[2]), "props": []})
        elif w[0] == "property":
            if w[1] == "list":
                elements[-1]["props"].append((w[4], "list", w[2], w[3]))
            else:
                elements[-1]["props"].append((w[2], w[1], None, None))
    out = {}
    pos = end
    if fmt == "ascii":
        tokens = data[end:].split()
        ti = 0
        for el in elements:
            rows = []
            for _ in range(el["count"]):
                row = {}
                for name, kind, ct, it in el["props"]:
                    if kind == "list":
                        n = int(tokens[ti]); ti += 1
                        row[name] = [int(t) for t in tokens[ti:ti + n]]; ti += n
                    else:
                        row[name] = float(tokens[ti]); ti += 1
                rows.append(row)
            out[el["name"]] = rows
        return out
    assert fmt == "binary_little_endian", fmt
    for el in elements:
        rows = []
        simple = all(k != "list" for _, k, _, _ in el["props"])
        if simple:
            st = struct.Struct("<" + "".join(_FMT[k] for _, k, _, _ in el["props"]))
            names = [n for n, _, _, _ in el["props"]]
            for _ in range(el["count"]):
                rows.append(dict(zip(names, st.unpack_from(data, pos))))
                pos += st.size
        else:
            for _ in range(el["count"]):
                row = {}
                for name, kind, ct, it in el["props"]:
                    if kind == "list":
                        (n,) = struct.unpack_from("<" + _FMT[ct], data, pos); pos += struct.calcsize(_FMT[ct])
                        row[name] = list(struct.unpack_from("<%d%s" % (n, _FMT[it]), data, pos))
                        pos += n * struct.calcsize(_FMT[it])
                    else:
                        (row[name],) = struct.unpack_from("<" + _FMT[kind], data, pos); pos += struct.calcsize(_FMT[kind])
                rows.append(row)
        out[el["name"]] = rows
    return out
