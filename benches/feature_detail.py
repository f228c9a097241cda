#!/usr/bin/env python3
"""Detail inside a constrained ridge's and valley's core (issue 40 item 4:
features keep their detail, >= 80 % of the exemplar's for their type).

    python3 benches/feature_detail.py BINARY [SIZE] [SEEDS]

For each seed (default 11,12,13), BINARY synthesizes a SIZE² map (default
384) on the embedded database, then the same map with one straight curve
across it (row SIZE/2, from 10 % to 90 % of the side, smoothing 0): its
crest 300 m above (ridge) or below (valley) the unconstrained map's mean
along the line, 10° sides, 24-px reach. Gentle sides on purpose: a steep
profile's crest is itself a kink, and a kink reads as 5×5 detail.

Core: the pixels within 3 px of the line (8 px in from its ends). Detail:
the std of h minus its 5×5 mean over the core. It is printed against
three references:
- `types`: the exemplars' own detail for the types the core's pixels were
  drawn from (`--coords`; the RMS over the core of each (exemplar, type)'s
  detail over the whole exemplar) — the issue's reference;
- `copied`: the detail of the very texels the core copies;
- `unconstrained`: the core's place in the map without the curve.
and the mean |crest − target| along the line (the profile's accuracy).
Medians over the seeds close the table. Needs numpy; reads the exemplars
from data/exemplars/ (the embedded database, in its alphabetical order).
"""
import json, os, statistics, struct, subprocess, sys, tempfile, zlib

import numpy as np

binary = sys.argv[1]
size = int(sys.argv[2]) if len(sys.argv) > 2 else 384
seeds = [int(s) for s in (sys.argv[3] if len(sys.argv) > 3 else "11,12,13").split(",")]
data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "exemplars")


def read_png(path):
    """Greyscale or RGB, 8 or 16 bits, not interlaced: what the CLI and
    data/ write (numpy alone, no imaging library)."""
    b = open(path, "rb").read()
    p, idat = 8, b""
    while p < len(b):
        n, t = struct.unpack(">I4s", b[p:p + 8])
        d = b[p + 8:p + 8 + n]
        p += 12 + n
        if t == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", d[:10])
        elif t == b"IDAT":
            idat += d
    channels = {0: 1, 2: 3}[colour]
    bpp = channels * depth // 8
    stride = w * bpp
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, stride + 1).astype(np.int32)
    out = np.zeros((h, stride), np.int32)
    prev = np.zeros(stride, np.int32)
    for y in range(h):
        f, line = raw[y, 0], raw[y, 1:]
        if f == 0:
            cur = line.copy()
        elif f == 2:
            cur = (line + prev) & 255
        else:
            cur = np.zeros(stride, np.int32)
            for i in range(stride):
                a = cur[i - bpp] if i >= bpp else 0
                c = prev[i - bpp] if i >= bpp else 0
                u = prev[i]
                if f == 1:
                    pred = a
                elif f == 3:
                    pred = (a + u) // 2
                else:
                    pa, pb, pc = abs(u - c), abs(a - c), abs(a + u - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (u if pb <= pc else c)
                cur[i] = (line[i] + pred) & 255
        out[y] = cur
        prev = cur
    if depth == 16:
        out = (out[:, 0::2] << 8) | out[:, 1::2]
    return out.reshape(h, w, channels) if channels > 1 else out.reshape(h, w)


def detail(h):
    """h minus its 5×5 mean (mirrored at the edges)."""
    p = np.pad(h, 2, mode="symmetric")
    c = np.cumsum(np.cumsum(np.pad(p, ((1, 0), (1, 0))), 0), 1)
    box = c[5:, 5:] - c[:-5, 5:] - c[5:, :-5] + c[:-5, :-5]
    return h - box / 25.0


type_maps, details, type_detail = [], [], {}
for e, name in enumerate(sorted(os.listdir(data))):
    mapping = json.load(open(os.path.join(data, name, name + ".json")))["height_mapping"]
    h = mapping["offset_m"] + mapping["scale_m"] * read_png(os.path.join(data, name, name + ".png"))
    types = read_png(os.path.join(data, name, name + "_types.png"))
    details.append(detail(h))
    type_maps.append(types)
    for t in np.unique(types):
        type_detail[(e, int(t))] = details[-1][types == t].std()

tmp = tempfile.mkdtemp()
run = lambda *a: subprocess.run([binary, *a], check=True, capture_output=True)
read_r32 = lambda p: np.fromfile(p, "<f4").reshape(size, size).astype(np.float64)
y, x0, x1 = size // 2, size // 10, size - size // 10
core = np.zeros((size, size), bool)
core[y - 3:y + 4, x0 + 8:x1 - 8] = True
rows = {"ridge": [], "valley": []}
print(f"{size}², core {core.sum()} px | detail m | / types | / copied | / unconstrained | crest error m")
for seed in seeds:
    base = os.path.join(tmp, "base.r32")
    run("synth", "--size", f"{size}x{size}", "--seed", str(seed), "-o", base)
    b = read_r32(base)
    for kind, dh, slope in (("ridge", 300.0, -10), ("valley", -300.0, 10)):
        target = b[core].mean() + dh
        widget = lambda at: {"at": at, "height_m": target, "slope_deg": [slope, slope], "reach_px": [24, 24]}
        scene = {"size": [size, size], "seed": seed,
                 "curves": [{"id": kind, "points": [[x0, y], [x1, y]], "smoothing": 0, "widgets": [widget(0.0), widget(1.0)]}]}
        path = os.path.join(tmp, "scene.json")
        json.dump(scene, open(path, "w"))
        out, coords = os.path.join(tmp, "out.r32"), os.path.join(tmp, "coords.png")
        run("synth", "--scene", path, "-o", out, "--coords", coords)
        h, c = read_r32(out), read_png(coords)
        cx, cy, ce = c[..., 0][core], c[..., 1][core], c[..., 2][core]
        d = detail(h)[core].std()
        types = np.sqrt(np.mean([type_detail[(e, int(type_maps[e][v, u]))] ** 2 for u, v, e in zip(cx, cy, ce)]))
        copied = np.array([details[e][v, u] for u, v, e in zip(cx, cy, ce)]).std()
        free = detail(b)[core].std()
        err = np.abs(h[y, x0 + 8:x1 - 8] - target).mean()
        rows[kind].append((d / types, d / copied, d / free, err))
        print(f"seed {seed} {kind:6} | {d:5.1f} | {100 * d / types:4.0f} % | {100 * d / copied:4.0f} % | {100 * d / free:4.0f} % | {err:5.1f}")
for kind, r in rows.items():
    med = [statistics.median(col) for col in zip(*r)]
    print(f"median {kind:6} |       | {100 * med[0]:4.0f} % | {100 * med[1]:4.0f} % | {100 * med[2]:4.0f} % | {med[3]:5.1f}")
