#!/usr/bin/env python3
"""Where a mode's error against the long path-traced reference lies
(bench/render_bench.py's scene, camera and reference, which must exist:
run render_bench.py first).

One setting of a mode is rendered with several seeds; their mean image
keeps the mode's bias and divides its noise by the number of seeds. Per
pixel: the mean minus the reference (luminance), over the pixels
render_bench measures. Reported by the surface each pixel's centre ray sees
(render_bench's RENDER_BENCH_CLASSES map) and, for the room's walls, by the
distance to the nearest edge of the room in patches (the scene's 50 mm
mesh): for each group its share of the image's squared error (bias^2: the
seeds' mean against the reference, with the reference's variance and the
mean's own variance taken out), its mean signed difference, and its pixels.
Writes OUT.png: the signed difference per pixel relative to the reference's
mean (red brighter than the reference, blue darker; full colour at
+-SCALE), beside the reference and the mean image, 4x enlarged.

usage: /usr/bin/python3 bench/render_error_map.py MODE A B [--seeds N] [--scale S] [--out OUT]
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
CLASSES = ["floor", "ceiling", "left wall", "right wall", "back wall", "other diffuse", "emitter", "glossy block",
           "mirror", "glass", "nothing"]
PATCH = 50.0  # the bench scene's patch size (mm): scenes::causticCornellGlossy(50, ...)


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = f.read()
    ch = 3 if kind == b"PF" else 1
    fmt = ("<" if scale < 0 else ">") + "%df" % (w * h * ch)
    v = struct.unpack(fmt, data[: 4 * w * h * ch])
    rows = [[tuple(v[(y * w + x) * ch:(y * w + x) * ch + ch]) for x in range(w)] for y in range(h)]
    return w, h, rows[::-1]  # PFM stores the bottom row first


def lum(c):
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]


def write_png(path, w, h, rgb):
    raw = b"".join(b"\x00" + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def srgb(v):
    v = max(0.0, min(1.0, v))
    return int(round(255 * (12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode")
    ap.add_argument("a", type=int)
    ap.add_argument("b", type=int)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--scale", type=float, default=0.1)
    ap.add_argument("--build", default=os.path.join(os.path.dirname(HERE), "build"))
    ap.add_argument("--results", default=os.path.join(HERE, "results"))
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    refs = os.path.join(a.results, "refs")
    stems = sorted(f[:-4] for f in os.listdir(refs) if f.endswith(".pfm") and not f.endswith("_se.pfm"))
    stems = [s for s in stems if s.startswith("render_ref_64x64")] or stems
    if not stems:
        sys.exit("no reference in %s: run bench/render_bench.py first" % refs)
    stem = os.path.join(refs, stems[-1])
    w, h, ref = read_pfm(stem + ".pfm")
    _, _, se = read_pfm(stem + "_se.pfm")
    exe = os.path.join(a.build, "bench", "render_bench")
    tmp = tempfile.mkdtemp(prefix="render_error_map")
    imgs, runs = [], []
    env = dict(os.environ)
    for seed in range(1, a.seeds + 1):
        env["RENDER_BENCH_IMAGE"] = os.path.join(tmp, "img%d.pfm" % seed)
        env["RENDER_BENCH_MASK"] = os.path.join(tmp, "mask.pfm")
        env["RENDER_BENCH_CLASSES"] = os.path.join(tmp, "classes.pfm")
        p = subprocess.run([exe, "run", str(w), str(h), stem, a.mode, str(a.a), str(a.b), str(seed)], env=env,
                           stdout=subprocess.PIPE, text=True, check=True)
        runs.append(json.loads(p.stdout))
        imgs.append(read_pfm(env["RENDER_BENCH_IMAGE"])[2])
        print("seed %d: %.2f s, error %.4f (corrected %.4f)" % (seed, runs[-1]["seconds"], runs[-1]["relative_rms_error"],
                                                              runs[-1]["relative_rms_error_corrected"]), flush=True)
    _, _, mask = read_pfm(env["RENDER_BENCH_MASK"])
    _, _, cls = read_pfm(env["RENDER_BENCH_CLASSES"])
    n = len(imgs)
    L = [[[lum(im[y][x]) for x in range(w)] for y in range(h)] for im in imgs]
    mean = [[sum(l[y][x] for l in L) / n for x in range(w)] for y in range(h)]
    # The mean's own variance per pixel from the seeds' spread (an unbiased estimate of var / n).
    var_mean = [[sum((l[y][x] - mean[y][x]) ** 2 for l in L) / (n - 1) / n if n > 1 else 0.0 for x in range(w)]
                for y in range(h)]
    keep = [(x, y) for y in range(h) for x in range(w) if mask[y][x][0] > 0.5]
    ref_mean = sum(lum(ref[y][x]) for x, y in keep) / len(keep)
    groups = {}

    def group(x, y):
        c = int(round(cls[y][x][0]))
        name = CLASSES[c] if 0 <= c < len(CLASSES) else "?"
        if c <= 5:
            d = cls[y][x][1] / PATCH
            name += " (edge < 1 patch)" if d < 1 else " (1-2 patches)" if d < 2 else " (> 2 patches)"
        return name
    tot_b2 = 0.0
    for x, y in keep:
        d = mean[y][x] - lum(ref[y][x])
        b2 = d * d - se[y][x][0] ** 2 - var_mean[y][x]
        g = groups.setdefault(group(x, y), [0, 0.0, 0.0, 0.0])
        g[0] += 1
        g[1] += b2
        g[2] += d
        g[3] += lum(ref[y][x])
        tot_b2 += b2
    N = len(keep)
    print("\n%s %d %d, %d seeds: relative RMS bias over %d pixels %.2f%% (the seeds' mean against the reference, "
          "both variances taken out)" % (a.mode, a.a, a.b, n, N, 100 * math.sqrt(max(tot_b2, 0) / N) / ref_mean))
    print("%-34s %6s %12s %14s %16s" % ("surface", "pixels", "share of bias^2", "mean diff", "mean diff / own"))
    for name, (cnt, b2, d, r) in sorted(groups.items(), key=lambda kv: -kv[1][1]):
        print("%-34s %6d %11.1f%% %+13.2f%% %+15.2f%%" % (name, cnt, 100 * b2 / tot_b2 if tot_b2 > 0 else 0,
                                                          100 * d / cnt / ref_mean, 100 * d / max(r, 1e-30)))
    # Image: reference | mean | signed difference, 4x.
    exposure = 1.0 / sorted(lum(ref[y][x]) for x, y in keep)[int(0.99 * (N - 1))]
    Z = 4
    W3 = 3 * w * Z
    rgb = bytearray(W3 * h * Z * 3)
    for y in range(h):
        for x in range(w):
            cols = [tuple(srgb(exposure * v) for v in ref[y][x]), tuple(srgb(exposure * sum(im[y][x][k] for im in imgs) / n)
                                                                       for k in range(3))]
            if mask[y][x][0] > 0.5:
                t = max(-1.0, min(1.0, (mean[y][x] - lum(ref[y][x])) / ref_mean / a.scale))
                cols.append((255, int(255 * (1 - t)), int(255 * (1 - t))) if t >= 0 else
                            (int(255 * (1 + t)), int(255 * (1 + t)), 255))
            else:
                cols.append((40, 40, 40))
            for k, c in enumerate(cols):
                for yy in range(y * Z, y * Z + Z):
                    for xx in range((k * w + x) * Z, (k * w + x) * Z + Z):
                        o = (yy * W3 + xx) * 3
                        rgb[o:o + 3] = bytes(c)
    out = a.out or os.path.join(a.results, "error_map_%s_%d_%d.png" % (a.mode, a.a, a.b))
    write_png(out, W3, h * Z, rgb)
    print("wrote %s (reference | mean of %d seeds | difference, full colour at +-%g%% of the mean)" % (out, n, 100 * a.scale))


if __name__ == "__main__":
    main()
