"""Pixel checks on the modeler's screenshots (Pillow).

  check_image.py centred SHOT            the clay object sits in the middle of the frame
  check_image.py changed BEFORE AFTER    the two differ, in the middle, over a small area
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
else:
    sys.exit("unknown mode " + mode)
