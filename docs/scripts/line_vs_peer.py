"""A continuous-line ("TSP art") drawing against a carefully made peer.

    python3 -m venv /tmp/linev && /tmp/linev/bin/pip install numpy scipy pillow fast-tsp
    /tmp/linev/bin/python docs/scripts/line_vs_peer.py PHOTO OURS.svg [--pen-mm 1.0]
        [--frame-mm X,Y,W,H] [--json out.json] [--tsp-seconds S] [--peer-gamma 1,2]
        [--peer-scale 0.7,1] [--lloyd-iters 40] [--seed 1]
    /tmp/linev/bin/python docs/scripts/line_vs_peer.py --self-test      # 30 s

About 2 minutes per photo at 10K vertices on 2 cores (5 tours of 4 + n/1000 s each).

SVG read (pixelpie's pen output): the page's width (mm; cm, in, pt, px also read)
over its viewBox gives mm per unit. Every <path> is read (meant to be ONE; more
are read as further subpaths) except under <defs> and the like or in a group
whose inkscape:label starts with "%" (the paper); <rect>s are ignored. Ancestor
transforms (translate, scale, matrix) are applied. `d` takes M/m/L/l/H/h/V/v/
C/c/Z/z in SVG number syntax ("10 2-5 10", ".5.5", exponents); cubics are
flattened to chords of at most 0.05 mm. Subpaths = number of M/m. The pen is the
nearest stroke-width (path or ancestor; attribute or style), in the path's own
units as SVG inherits it, times sqrt|det| of the path's transform; --pen-mm
overrides. Frame: the photo fills the box X,Y,W,H in mm from the viewBox's
top-left corner (default: the whole viewBox). Vertices: the path's nodes (its
M/L/H/V/C end points; a Z adds none).

Method.
- Grey: photo -> display grey in [0,1] = sRGB-encode(Rec.709 Y of linearised
  sRGB); a grey photo is value/255 (EXIF orientation applied).
- Render: the frame is mapped onto the photo's pixels; subpixel centres (S x S
  per pixel, S >= 4, ~12 across the pen) are inked within pen/2 of a segment
  (a union of round-capped thick segments), box-averaged to coverage c; display
  grey = 1 - c.
- Tone: both greys blurred by a Gaussian of sigma = sqrt(photo pixels / our
  vertices) photo pixels (edges reflected); PSNR = 10 log10(1 / MSE). Means of
  the unblurred greys and their |difference| are reported too.
- Crossings: pairs of segments of the drawn (flattened) polyline that cross
  properly (strict orientation signs: touching or collinear overlap does not
  count); segments sharing a vertex skipped; candidate pairs from a grid.
- Tour: our node polyline's length (pen-up jumps between subpaths included)
  against fast_tsp's open path through the same nodes: a dummy city at distance
  0 from all closes it, so both ends are free; distances scaled so that the
  bounding box's diagonal is 65000 (fast_tsp's uint16 range). Skipped above
  12000 nodes. ours_len_mm is the drawn length (curves, no jumps).
- Peer (StippleGen-style TSP art, made well): weighted Lloyd (LBG-like)
  stippling with weight (1 - grey)^gamma: N points seeded by weight, then
  --lloyd-iters steps on a grid of ~30 pixels per point (cKDTree assignment,
  weighted centroids, empty cells reseeded); fast_tsp's open path; drawn with
  our pen in our frame and measured with our sigma. N = round(0.7 x ours) and
  N = ours (--peer-scale), each with gamma 1 (StippleGen) and 2 (the point
  density follows the weight, a line's coverage goes as density^(1/2), so
  gamma 2 makes coverage follow darkness); the best PSNR is the peer's.
"""
import argparse
import json
import math
import os
import re
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import fast_tsp
import numpy as np
from PIL import Image, ImageOps
from scipy.ndimage import gaussian_filter
from scipy.spatial import cKDTree

NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
UNIT_MM = {"mm": 1.0, "cm": 10.0, "in": 25.4, "pt": 25.4 / 72, "px": 25.4 / 96, "": 25.4 / 96}
SKIP = {"defs", "rect", "clipPath", "mask", "symbol", "metadata", "pattern", "marker"}


def transform_of(text):
    """The 3x3 affine matrix of a transform attribute."""
    m = np.eye(3)
    for name, args in re.findall(r"(\w+)\s*\(([^)]*)\)", text or ""):
        v = [float(x) for x in NUM.findall(args)]
        if name == "translate":
            t = np.array([[1, 0, v[0]], [0, 1, v[1] if len(v) > 1 else 0], [0, 0, 1]])
        elif name == "scale":
            t = np.diag([v[0], v[1] if len(v) > 1 else v[0], 1.0])
        elif name == "matrix":
            t = np.array([[v[0], v[2], v[4]], [v[1], v[3], v[5]], [0, 0, 1]])
        else:
            raise ValueError(f"unsupported transform {name}")
        m = m @ t
    return m


def parse_d(d):
    """Subpaths of `d`, absolute: lists of ('M', p), ('L', p), ('C', c1, c2, p), ('Z',)."""
    toks = re.findall(r"[MmLlHhVvCcZz]|" + NUM.pattern, d)
    subs, i, cmd, cur, start = [], 0, None, np.zeros(2), np.zeros(2)

    def take(k):
        nonlocal i
        if i + k > len(toks) or any(t.isalpha() for t in toks[i:i + k]):
            raise ValueError(f"bad path data at token {i}")
        i += k
        return np.array([float(t) for t in toks[i - k:i]])
    while i < len(toks):
        if toks[i].isalpha():
            cmd, i = toks[i], i + 1
            if cmd in "Zz":
                subs[-1].append(("Z",))
                cur = start.copy()
                continue
        elif cmd is None or cmd in "Zz":
            raise ValueError("path data must start with M")
        rel = cmd.islower() and (cmd != "m" or bool(subs))   # a first m is absolute
        base, c = (cur if rel else np.zeros(2)), cmd.upper()
        if c == "M":
            cur = start = base + take(2)
            subs.append([("M", cur)])
            cmd = "l" if cmd == "m" else "L"                 # further pairs are line-tos
        elif c == "L":
            cur = base + take(2)
            subs[-1].append(("L", cur))
        elif c in "HV":
            k, cur = "HV".index(c), cur.copy()
            cur[k] = (cur[k] if rel else 0) + take(1)[0]
            subs[-1].append(("L", cur))
        elif c == "C":
            v = take(6)
            cur = base + v[4:]
            subs[-1].append(("C", base + v[:2], base + v[2:4], cur))
        else:
            raise ValueError(f"unsupported path command {cmd}")
    return subs


def read_svg(path):
    """Flattened subpaths (mm), nodes (mm), subpath count, pen (mm or None), viewBox frame (mm)."""
    root = ET.parse(path).getroot()
    vb = [float(v) for v in NUM.findall(root.get("viewBox", ""))] or [0, 0, 1, 1]
    mm = 1.0
    if root.get("viewBox") and root.get("width"):
        w = re.fullmatch(r"\s*(" + NUM.pattern + r")\s*([a-z]*)\s*", root.get("width"))
        mm = float(w.group(1)) * UNIT_MM[w.group(2)] / vb[2]
    found = []

    def walk(e, m, width):
        t = e.tag.rsplit("}", 1)[-1]
        label = next((v for k, v in e.attrib.items() if k.endswith("label")), "")
        if t in SKIP or (t == "g" and label.startswith("%")):
            return
        m = m @ transform_of(e.get("transform"))
        style = dict(kv.split(":", 1) for kv in (e.get("style") or "").split(";") if ":" in kv)
        sw = style.get("stroke-width", e.get("stroke-width"))
        width = float(NUM.match(sw.strip()).group()) if sw else width
        if t == "path" and e.get("d"):
            found.append((parse_d(e.get("d")), m, width))
        for c in e:
            walk(c, m, width)
    walk(root, np.diag([mm, mm, 1.0]) @ np.array([[1, 0, -vb[0]], [0, 1, -vb[1]], [0, 0, 1]]), None)
    if not found:
        raise ValueError("no <path> found")
    if len(found) > 1:
        print(f"note: {len(found)} paths, read as subpaths of one line", file=sys.stderr)
    subs, nodes, pen = [], [], None
    for sp, m, width in found:
        if width is not None and pen is None:
            pen = width * math.sqrt(abs(np.linalg.det(m[:2, :2])))
        tf = lambda p: m[:2, :2] @ p + m[:2, 2]
        for items in sp:
            pts = [tf(items[0][1])]
            nodes.append(pts[0])
            for it in items[1:]:
                if it[0] == "Z":
                    pts.append(pts[0])
                    continue
                if it[0] == "L":
                    pts.append(tf(it[1]))
                else:
                    q = np.array([pts[-1], tf(it[1]), tf(it[2]), tf(it[3])])
                    n = max(2, math.ceil(np.hypot(*np.diff(q, axis=0).T).sum() / 0.05))
                    s = np.linspace(0, 1, n + 1)[1:, None]
                    pts.extend((1 - s) ** 3 * q[0] + 3 * (1 - s) ** 2 * s * q[1]
                               + 3 * (1 - s) * s * s * q[2] + s ** 3 * q[3])
                nodes.append(pts[-1])
            subs.append(np.array(pts))
    return subs, np.array(nodes), len(subs), pen, (0.0, 0.0, vb[2] * mm, vb[3] * mm)


def display_grey(path):
    im = ImageOps.exif_transpose(Image.open(path))
    if im.mode in ("1", "L", "LA"):
        return np.asarray(im.convert("L"), np.float64) / 255.0
    if im.mode.startswith("I"):
        a = np.asarray(im, np.float64)
        return a / (65535.0 if a.max() > 255 else 255.0)
    a = np.asarray(im.convert("RGB"), np.float64) / 255.0
    y = np.clip(np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4) @ [0.2126, 0.7152, 0.0722], 0, 1)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * y ** (1 / 2.4) - 0.055)


def render(subs, pen, frame, shape):
    """Display grey (1 - ink coverage) of the line on the photo's pixel grid."""
    (X, Y, W, H), (ph, pw) = frame, shape
    ss = int(min(16, math.sqrt(64e6 / (pw * ph)), max(4, math.ceil(12 * W / (pen * pw)))))
    g = np.array([W / (pw * ss), H / (ph * ss)])      # subpixel size, mm
    ink, r = np.zeros((ph * ss, pw * ss), bool), pen / 2
    for p in subs:
        p = (p - [X, Y]) / g - 0.5                    # subpixel index space (centres at integers)
        p = np.vstack([p, p]) if len(p) == 1 else p
        for a, b in zip(p[:-1], p[1:]):
            lo = np.maximum(np.floor(np.minimum(a, b) - r / g), 0).astype(int)
            hi = np.minimum(np.ceil(np.maximum(a, b) + r / g) + 1, ink.shape[::-1]).astype(int)
            if np.any(lo >= hi):
                continue
            xs, ys = (np.arange(lo[0], hi[0]) - a[0]) * g[0], (np.arange(lo[1], hi[1]) - a[1]) * g[1]
            dx, dy = (b - a) * g
            ll = dx * dx + dy * dy
            t = np.clip((xs[None, :] * dx + ys[:, None] * dy) / ll, 0, 1) if ll > 0 else 0.0
            ink[lo[1]:hi[1], lo[0]:hi[0]] |= (xs[None, :] - t * dx) ** 2 + (ys[:, None] - t * dy) ** 2 <= r * r
    return 1.0 - ink.reshape(ph, ss, pw, ss).mean(axis=(1, 3))


def crossings(subs):
    """Properly crossing pairs of segments that share no vertex."""
    segs, ends, base = [], [], 0
    for p in subs:
        keep = np.r_[True, np.any(np.diff(p, axis=0) != 0, axis=1)]
        p, ids = p[keep], np.arange(base, base + keep.sum())
        if len(p) > 2 and np.all(p[-1] == p[0]):
            ids[-1] = ids[0]                          # closed: the last segment meets the first
        segs.append(np.hstack([p[:-1], p[1:]]))
        ends.append(np.c_[ids[:-1], ids[1:]])
        base += len(p)
    s, e = np.vstack(segs), np.vstack(ends)
    if len(s) < 2:
        return 0
    lo, hi = np.minimum(s[:, :2], s[:, 2:]), np.maximum(s[:, :2], s[:, 2:])
    cell = max(2 * np.median(np.hypot(*(s[:, 2:] - s[:, :2]).T)), np.ptp(s) / 4000, 1e-9)
    c0, c1 = (((v - lo.min(0)) // cell).astype(np.int64) for v in (lo, hi))
    nx, ny = c1[:, 0] - c0[:, 0] + 1, c1[:, 1] - c0[:, 1] + 1
    cnt = nx * ny                                     # cells each segment's box covers
    seg = np.repeat(np.arange(len(s)), cnt)
    k = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    key = (c0[seg, 1] + k // nx[seg]) * (c1[:, 0].max() + 2) + c0[seg, 0] + k % nx[seg]
    o = np.argsort(key, kind="stable")
    key, seg, pairs = key[o], seg[o], [np.zeros((0, 2), np.int64)]
    for d in range(1, len(key)):                      # all pairs within a cell
        m = key[:-d] == key[d:]
        if not m.any():
            break
        pairs.append(np.c_[seg[:-d][m], seg[d:][m]])
    a, b = np.unique(np.sort(np.vstack(pairs), axis=1), axis=0).T
    keep = ~(e[a, :, None] == e[b, None, :]).any(axis=(1, 2))
    P, Q, R, S = s[a[keep], :2], s[a[keep], 2:], s[b[keep], :2], s[b[keep], 2:]
    eps = 1e-12 * (np.ptp(s) + 1) ** 2                # below it: collinear
    cross = lambda u, v: u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    o = [np.where(np.abs(x) > eps, np.sign(x), 0) for x in (
        cross(Q - P, R - P), cross(Q - P, S - P), cross(S - R, P - R), cross(S - R, Q - R))]
    return int(np.sum((o[0] * o[1] < 0) & (o[2] * o[3] < 0)))


def open_tsp(xy, seconds):
    """fast_tsp's open path through xy (an order), a dummy city at 0 from all closing it."""
    m = len(xy)
    if m < 3:
        return np.arange(m)
    k = 65000.0 / max(np.hypot(*np.ptp(xy, axis=0)), 1e-12)
    dist = np.zeros((m + 1, m + 1), np.int32)
    for i in range(0, m, 1024):
        d = np.hypot(*(xy[i:i + 1024, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        dist[i:i + len(d), :m] = np.minimum(np.rint(d * k), 65000)
    tour = fast_tsp.find_tour(dist, duration_seconds=seconds, max_threads=None)
    j = tour.index(m)
    return np.array(tour[j + 1:] + tour[:j])


def length(p):
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0


def lloyd(grey, n, frame, iters, gamma, rng):
    """n points (mm) of weighted Lloyd stippling, weight (1 - grey)^gamma."""
    ph, pw = grey.shape
    f = math.sqrt(min(max(30 * n, 200_000), 1_000_000) / (ph * pw))
    gw, gh = max(1, round(pw * f)), max(1, round(ph * f))
    g = np.asarray(Image.fromarray(grey.astype(np.float32), "F").resize((gw, gh), Image.BILINEAR), float)
    w = np.clip(1 - g, 0, 1) ** gamma
    ys, xs = np.nonzero(w > 1e-6)
    pix, w = np.c_[xs + 0.5, ys + 0.5], w[ys, xs]
    prob = w / w.sum()
    pts = pix[rng.choice(len(pix), n, replace=n > len(pix), p=prob)] + rng.uniform(-.5, .5, (n, 2))
    for _ in range(iters):
        idx = cKDTree(pts).query(pix, workers=-1)[1]
        mass = np.bincount(idx, w, n)
        ok = mass > 0
        pts[ok] = np.c_[np.bincount(idx, w * pix[:, 0], n), np.bincount(idx, w * pix[:, 1], n)][ok] / mass[ok, None]
        pts[~ok] = pix[rng.choice(len(pix), (~ok).sum(), p=prob)]
    return pts / [gw, gh] * frame[2:] + frame[:2]


def psnr(a, b):
    return 10 * math.log10(1 / max(np.mean((a - b) ** 2), 1e-12))


def measure(photo, svg, pen_mm=None, frame=None, tsp_seconds=None, gammas=(1, 2), scales=(0.7, 1),
            iters=40, seed=1):
    t0 = time.time()
    subs, nodes, nsub, pen, view = read_svg(svg)
    pen, frame = pen_mm or pen, frame or view
    if pen is None:
        raise ValueError("no stroke-width in the SVG: give --pen-mm")
    grey = display_grey(photo)
    (ph, pw), v = grey.shape, len(nodes)
    if abs(frame[2] / frame[3] - pw / ph) > 0.01 * pw / ph:
        print(f"warning: frame {frame[2]}x{frame[3]} mm, photo {pw}x{ph} px: aspects differ", file=sys.stderr)
    sigma = math.sqrt(pw * ph / v)
    blur = lambda g: gaussian_filter(g, sigma, mode="reflect")
    gref, ours = blur(grey), render(subs, pen, frame, grey.shape)
    secs = tsp_seconds if tsp_seconds is not None else min(60.0, 4 + v / 1000)
    r = dict(photo=os.path.basename(photo), svg=os.path.basename(svg), vertices=v, subpaths=nsub,
             crossings=crossings(subs), pen_mm=pen, frame_mm=list(frame), sigma_px=sigma,
             ours_psnr=psnr(blur(ours), gref), photo_mean=float(grey.mean()), ours_mean=float(ours.mean()),
             ours_len_mm=sum(length(p) for p in subs), ours_chord_mm=length(nodes), tsp_seconds=secs)
    r["mean_diff"] = abs(r["photo_mean"] - r["ours_mean"])
    r["fasttsp_len_mm"] = length(nodes[open_tsp(nodes, secs)]) if v <= 12000 else None
    r["ratio"] = r["ours_chord_mm"] / r["fasttsp_len_mm"] if r["fasttsp_len_mm"] else None
    if v > 12000:
        r["note"] = "tour check skipped above 12000 vertices"
    rng, runs = np.random.default_rng(seed), []
    for gamma in gammas:
        for n in sorted({max(3, round(f * v)) for f in scales}):
            pts = lloyd(grey, n, np.array(frame), iters, gamma, rng)
            line = pts[open_tsp(pts, secs)]
            peer = render([line], pen, frame, grey.shape)
            runs.append(dict(n=n, gamma=gamma, psnr=psnr(blur(peer), gref), mean=float(peer.mean()),
                             len_mm=length(line), crossings=crossings([line])))
    best = max(runs, key=lambda x: x["psnr"])
    r.update(peer_psnr=best["psnr"], peer_n=best["n"], peer_gamma=best["gamma"], peer_runs=runs,
             delta_db=r["ours_psnr"] - best["psnr"], seconds=time.time() - t0)
    return r


HEAD = (f"{'photo':<16}{'verts':>7}{'subp':>5}{'cross':>6}{'pen':>6}{'ours dB':>8}{'peer dB':>8}{'(N,g)':>11}"
        f"{'delta':>7}{'photo':>7}{'ours':>7}{'|dm|':>7}{'len mm':>9}{'tsp mm':>9}{'ratio':>7}")


def row(r):
    tsp = f"{r['fasttsp_len_mm']:9.0f}{r['ratio']:7.4f}" if r["ratio"] else f"{'-':>9}{'-':>7}"
    return (f"{r['photo'][:15]:<16}{r['vertices']:7d}{r['subpaths']:5d}{r['crossings']:6d}{r['pen_mm']:6.2f}"
            f"{r['ours_psnr']:8.2f}{r['peer_psnr']:8.2f}{'(%d,%g)' % (r['peer_n'], r['peer_gamma']):>11}"
            f"{r['delta_db']:+7.2f}{r['photo_mean']:7.3f}{r['ours_mean']:7.3f}{r['mean_diff']:7.3f}"
            f"{r['ours_len_mm']:9.0f}{tsp}\n" + "".join(
                f"  peer N={p['n']} gamma={p['gamma']:g}: {p['psnr']:.2f} dB, mean grey {p['mean']:.3f}, "
                f"{p['len_mm']:.0f} mm, {p['crossings']} crossings\n" for p in r["peer_runs"])
            + f"  sigma {r['sigma_px']:.3f} px, {r['seconds']:.0f} s" + (f"; {r['note']}" if "note" in r else ""))


def test_svg(path, w_mm, h_mm, pen, pts=None, d=None):
    """A file in pixelpie's pen format (paper layer, ink layer, a scale(0.01) group)
    with one path: `d`, else M then l through pts (hundredths of a mm, whole)."""
    if d is None:
        d = f"M{pts[0][0]} {pts[0][1]}l"
        for v in np.diff(np.asarray(pts), axis=0).ravel():
            d += (" " if v >= 0 and d[-1] != "l" else "") + str(int(v))
    with open(path, "w") as f:
        f.write(f'<?xml version="1.0" encoding="UTF-8"?>\n<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape='
                f'"http://www.inkscape.org/namespaces/inkscape" version="1.1" width="{w_mm}mm" height="{h_mm}mm" '
                f'viewBox="0 0 {w_mm} {h_mm}">\n<g inkscape:groupmode="layer" id="paper" inkscape:label="% paper">'
                f'<rect x="0" y="0" width="{w_mm}" height="{h_mm}" fill="#fff"/><path d="M0 0L{w_mm} {h_mm}"/></g>\n'
                f'<g inkscape:groupmode="layer" id="layer1" inkscape:label="1 line" fill="none" stroke="black" '
                f'stroke-width="{pen}" stroke-linecap="round" stroke-linejoin="round">\n<g transform="scale(0.01)" '
                f'stroke-width="{round(pen * 100)}">\n<path d="{d}"/>\n</g>\n</g>\n</svg>\n')
    return d


def self_test():
    ok = True

    def check(name, got, lo, hi):
        nonlocal ok
        ok &= lo <= got <= hi
        print(f"  {'ok ' if lo <= got <= hi else 'BAD'} {name}: {got:.4f} (want {lo:g}..{hi:g})")
    s = parse_d("M1205 8793l10 2-5 10 .5.5M1 1h3v-2H0V0c1 0 1 1 1 1C2 2 3 3 4 4zm1 1 2 2")
    assert [len(x) for x in s] == [4, 8, 2] and np.allclose(s[0][3][1], [1210.5, 8805.5]), s
    assert np.allclose(s[1][-2][3], [4, 4]) and np.allclose([s[2][0][1], s[2][1][1]], [[2, 2], [4, 4]])
    assert np.allclose(transform_of("translate(5,2) scale(0.01)") @ [100, 200, 1], [6, 4, 1])
    assert crossings([np.array([[0, 0], [10, 10], [10, 0], [0, 10.]])]) == 1
    assert crossings([np.array([[0, 0], [10, 0], [10, 10], [0, 10], [0, 0.]])]) == 0
    grid = [np.array([[i, -1], [i, 11.]]) for i in range(10)] + [np.array([[-1, j], [11, j + .3]]) for j in range(7)]
    assert crossings(grid) == 70 and crossings([np.array([[1., 1]])]) == 0
    print("parser, transforms, crossings: ok")
    with tempfile.TemporaryDirectory() as tmp:
        W, H, pw, ph = 100, 60, 200, 120               # mm; photo px
        Image.fromarray(np.tile(np.linspace(255, 40, pw), (ph, 1)).astype(np.uint8), "L").save(f"{tmp}/grad.png")
        pts = []                                       # 30 passes 2 mm apart, a node every 1 mm (hundredths)
        for k in range(30):
            pts += [(x, 100 + 200 * k) for x in (range(100, 9901, 100) if k % 2 == 0 else range(9900, 99, -100))]
        d = test_svg(f"{tmp}/ours.svg", W, H, 1.0, pts)
        assert d.startswith("M100 100l100 0 100 0") and "0 200-100 0" in d
        subs, nodes, nsub, pen, view = read_svg(f"{tmp}/ours.svg")
        print(f"serpentine: {len(nodes)} vertices, {nsub} subpath, pen {pen:g} mm, frame {view}")
        check("drawn length mm (30 x 98 + 29 x 2 = 2998)", sum(length(p) for p in subs), 2997.9, 2998.1)
        check("coverage, 1 mm pen, passes 2 mm apart (exact 2999/6000 = 0.49983)",
              1 - render(subs, pen, view, (ph, pw)).mean(), 0.495, 0.505)
        seg = np.array([[20.123, 20.456], [61.37, 39.81]])  # generic: a rational slope aliases
        one = 1 - render([seg], 1.0, view, (ph, pw)).mean()
        check("one segment's ink / exact (2rL + pi r^2)", one / ((length(seg) + math.pi / 4) / (W * H)), 0.995, 1.005)
        r = measure(f"{tmp}/grad.png", f"{tmp}/ours.svg", tsp_seconds=3, iters=30)
        print(HEAD + "\n" + row(r))
        want = math.sqrt(pw * ph / len(nodes))
        check(f"sigma px (sqrt(24000/{len(nodes)}))", r["sigma_px"], want - 1e-9, want + 1e-9)
        check("crossings", r["crossings"], 0, 0)
        check("ours mean grey", r["ours_mean"], 0.495, 0.505)
        check("tour ratio (a serpentine is near optimal)", r["ratio"], 0.97, 1.02)
        check("delta dB (a Lloyd peer beats a flat serpentine on a gradient)", r["delta_db"], -99, 0)
        test_svg(f"{tmp}/curve.svg", W, H, 1.0, d="M100 100C100 1000 9900 1000 9900 100c0 500-9800 500-9800 1000")
        subs, nodes, nsub, pen, _ = read_svg(f"{tmp}/curve.svg")
        check("curve nodes", len(nodes), 3, 3)
        check("curve: flattened length / chords", sum(length(p) for p in subs) / length(nodes), 1.0001, 3)
    print("self-test", "passed" if ok else "FAILED")
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("photo", nargs="?")
    ap.add_argument("svg", nargs="?")
    ap.add_argument("--pen-mm", type=float, help="pen width (default: the SVG's stroke-width)")
    ap.add_argument("--frame-mm", help="X,Y,W,H of the photo's box in mm (default: the viewBox)")
    ap.add_argument("--json")
    ap.add_argument("--tsp-seconds", type=float, help="fast_tsp budget per tour (default 4 + n/1000, <= 60)")
    ap.add_argument("--peer-gamma", default="1,2", help="peer weight exponents to try")
    ap.add_argument("--peer-scale", default="0.7,1", help="peer point counts to try, as fractions of ours")
    ap.add_argument("--lloyd-iters", type=int, default=40)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        sys.exit(0 if self_test() else 1)
    if not (a.photo and a.svg):
        ap.error("PHOTO and OURS.svg are required")
    floats = lambda t: tuple(float(v) for v in t.split(","))
    r = measure(a.photo, a.svg, a.pen_mm, floats(a.frame_mm) if a.frame_mm else None, a.tsp_seconds,
                floats(a.peer_gamma), floats(a.peer_scale), a.lloyd_iters, a.seed)
    print(HEAD + "\n" + row(r))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(r, f, indent=1)


if __name__ == "__main__":
    main()
