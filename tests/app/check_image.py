# SPDX-License-Identifier: Apache-2.0
"""Pixel checks on the modeler's screenshots (Pillow).

  check_image.py centred SHOT            the clay object sits in the middle of the frame
  check_image.py changed BEFORE AFTER    the two differ, in the middle, over a small area
  check_image.py looks CLAY GLOSSY WAX NORMALS
                                         the same sphere in each look: each as its matcap
                                         says (wax red, normals as colours, a glossy
                                         highlight), and no two alike
"""
import sys
from PIL import Image

def clay(p):
    r, g, b = p
    return r > 90 and r > g + 12 and g > b  # warm, bright: clay, not grid or background

def load(path):
    im = Image.open(path).convert("RGB")
    return im, im.load()

def centroid(points):
    n = len(points)
    return (sum(x for x, _ in points) / n, sum(y for _, y in points) / n)

mode = sys.argv[1]
if mode == "centred":
    im, px = load(sys.argv[2])
    w, h = im.size
    bg = px[0, 0]
    assert max(abs(a - b) for a, b in zip(bg, (41, 43, 48))) <= 2, f"background {bg}"
    pts = [(x, y) for y in range(h) for x in range(w) if clay(px[x, y])]
    frac = len(pts) / (w * h)
    cx, cy = centroid(pts)
    print(f"clay covers {100 * frac:.1f}% of the frame, centred at ({cx:.0f}, {cy:.0f}) of {w}x{h}")
    assert 0.05 < frac < 0.6, frac
    assert abs(cx - w / 2) < 0.06 * w and abs(cy - h / 2) < 0.06 * h, (cx, cy)
elif mode == "changed":
    a, pa = load(sys.argv[2])
    b, pb = load(sys.argv[3])
    assert a.size == b.size
    w, h = a.size
    diff = [(x, y) for y in range(h) for x in range(w)
            if max(abs(u - v) for u, v in zip(pa[x, y], pb[x, y])) > 24]
    area = sum(1 for y in range(h) for x in range(w) if clay(pa[x, y]))
    assert diff, "the screenshots are the same"
    cx, cy = centroid(diff)
    print(f"{len(diff)} pixels changed ({100 * len(diff) / area:.1f}% of the object), "
          f"centred at ({cx:.0f}, {cy:.0f})")
    assert len(diff) > 0.01 * area and len(diff) < 0.5 * area, (len(diff), area)
    assert abs(cx - w / 2) < 0.15 * w and abs(cy - h / 2) < 0.15 * h, (cx, cy)
elif mode == "looks":
    shots = [load(p)[1] for p in sys.argv[2:6]]
    w, h = load(sys.argv[2])[0].size
    body = [(x, y) for y in range(h) for x in range(w) if clay(shots[0][x, y])]
    assert len(body) > 0.05 * w * h, "no clay in the clay shot"
    cx, cy = centroid(body)
    def mean(px, pts, c):
        return sum(px[x, y][c] for x, y in pts) / len(pts)
    def luma(p):
        return 0.3 * p[0] + 0.59 * p[1] + 0.11 * p[2]
    for i in range(4):
        for j in range(i + 1, 4):
            d = sum(max(abs(a - b) for a, b in zip(shots[i][x, y], shots[j][x, y]))
                    for x, y in body) / len(body)
            assert d > 20, (sys.argv[2 + i], sys.argv[2 + j], d)
    glossy, wax, normals = shots[1], shots[2], shots[3]
    # Wax: red.
    r, g, b = (mean(wax, body, c) for c in range(3))
    print(f"red wax: mean colour {r:.0f} {g:.0f} {b:.0f}")
    assert r > 2 * g and r > 2 * b, (r, g, b)
    # Normals: red grows to the right (x), green to the top (y; rows grow downward).
    left = [p for p in body if p[0] < cx - 0.2 * w / 8]
    right = [p for p in body if p[0] > cx + 0.2 * w / 8]
    top = [p for p in body if p[1] < cy - 0.2 * h / 8]
    bottom = [p for p in body if p[1] > cy + 0.2 * h / 8]
    dr = mean(normals, right, 0) - mean(normals, left, 0)
    dg = mean(normals, top, 1) - mean(normals, bottom, 1)
    print(f"normals: red right minus left {dr:.0f}, green top minus bottom {dg:.0f}")
    assert dr > 60 and dg > 60, (dr, dg)
    # Glossy: a small, near-white highlight on a cool body.
    bright = sum(1 for x, y in body if luma(glossy[x, y]) >= 240) / len(body)
    print(f"glossy: {100 * bright:.2f}% of the body in the highlight, "
          f"blue {mean(glossy, body, 2):.0f} over red {mean(glossy, body, 0):.0f}")
    assert 0.0005 < bright < 0.05, bright
    assert mean(glossy, body, 2) > mean(glossy, body, 0), "not a cool glaze"
else:
    sys.exit("unknown mode " + mode)
