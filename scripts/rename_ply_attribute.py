#!/usr/bin/env python3
"""rename_ply_attribute.py IN OUT FROM TO: copies a PLY, renaming the per-vertex
attribute FROM (the properties FROM, or FROM_x FROM_y FROM_z) to TO; an
attribute already called TO is renamed TO_old. Only the header changes, so
binary files stay valid. (make_figures.sh shows a radiosity snapshot
through the two-pass view, which reads the attribute Radiosity.)"""
import re
import sys


def main():
    src, dst, old, new = sys.argv[1:5]
    with open(src, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").split("\n")
    out, found = [], False
    for line in lines:
        m = re.match(r"^(property \S+ )(\S+)$", line)
        if m:
            name = m.group(2)
            for a, b in ((new, new + "_old"), (old, new)):
                if name == a or re.match(re.escape(a) + r"_[xyz]$", name):
                    name = b + name[len(a):]
                    found |= a == old
                    break
            line = m.group(1) + name
        out.append(line)
    if not found:
        sys.exit("rename_ply_attribute: %s has no attribute %s" % (src, old))
    with open(dst, "wb") as f:
        f.write("\n".join(out).encode("ascii") + data[end:])


if __name__ == "__main__":
    main()
