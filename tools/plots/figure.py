"""Figures: sizes from a box's aspect, saving, and the body's outline."""
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import patches  # noqa: E402
import numpy as np  # noqa: E402

DPI = 110
AREA = 36.0  # square inches of a map's drawing area


def map_size(width, height, area=AREA, max_w=10.0, max_h=8.0):
    """(w, h) inches of a drawing area of the box's aspect, about `area`
    square inches, neither side beyond its maximum."""
    r = height / width
    w = math.sqrt(area / r)
    w = min(w, max_w, max_h / r)
    return w, w * r


def new(w, h):
    return plt.figure(figsize=(w, h), layout="constrained")


def map_axes(width, height):
    """(figure, axes, colour bar axes, its orientation) for a map of a
    width x height box: the axes have the box's aspect and the figure fits
    around them (margins in inches), the colour bar at the right of a tall
    or square box, below a wide one."""
    w, h = map_size(width, height)
    wide = h < 0.6 * w
    left, top = 0.9, 0.95
    right, bottom = (0.35, 1.35) if wide else (1.35, 0.6)
    spare = max(0.0, 5.0 - (left + w + right))  # room for the title of a narrow box
    left, right = left + spare / 2, right + spare / 2
    fw, fh = left + w + right, bottom + h + top
    fig = plt.figure(figsize=(fw, fh))
    ax = fig.add_axes([left / fw, bottom / fh, w / fw, h / fh])
    if wide:
        cax = fig.add_axes([left / fw, 0.5 / fh, w / fw, 0.18 / fh])
    else:
        cax = fig.add_axes([(left + w + 0.15) / fw, bottom / fh, 0.2 / fw, h / fh])
    return fig, ax, cax, "horizontal" if wide else "vertical"


def save(fig, out, name, note=None, crop=False):
    """Writes out/name (crop: to what is drawn, a map's margins being
    generous); says what it shows when note is given."""
    path = os.path.join(out, name)
    fig.savefig(path, dpi=DPI, **({"bbox_inches": "tight", "pad_inches": 0.1} if crop else {}))
    plt.close(fig)
    print("wrote %s%s" % (path, " (%s)" % note if note else ""))
    return path


def headline_text(run, keys, width=100):
    """'key = value (exact v)' for the [result] keys that exist, joined in
    lines of about width characters."""
    parts = []
    for k in keys:
        if k not in run.result:
            continue
        text = "%s = %s" % (k, _short(run.result[k]))
        p = run.partner(k)
        parts.append(text + (" (%s %s)" % (p[0], _short(p[1])) if p else ""))
    lines = [""]
    for p in parts:  # wrapped between the values, not inside one
        if lines[-1] and len(lines[-1]) + len(p) > width:
            lines.append("")
        lines[-1] += (", " if lines[-1] else "") + p
    return "\n".join(lines)


def _short(text):
    try:
        return "%.5g" % float(text)
    except ValueError:
        return text


# ---- the body: obstacle.* keys ----

PLANES = {"xz": (0, 2), "xy": (0, 1), "yz": (1, 2)}


def shapes(run):
    """[(kind, values)] of obstacle.shapes and the plane's two directions;
    ([], None) without a body."""
    text = run.key("obstacle.shapes", "") or ""
    plane = PLANES.get(run.key("obstacle.plane", "xz"))
    out = []
    for part in text.split(";"):
        words = part.split()
        if not words:
            continue
        try:
            vals = [float(w) for w in words[1:]]
        except ValueError:
            continue
        if words[0] == "circle" and len(vals) == 3 or words[0] == "rectangle" and len(vals) == 4:
            out.append((words[0], vals))
    return out, plane


def solid_mask(run, d1, d2, c1, c2):
    """Boolean array (len(c2), len(c1)): cell centres c1 x c2 (directions d1,
    d2) inside the solid; None without a body in this plane."""
    body, plane = shapes(run)
    if not body or plane is None or set(plane) != {d1, d2}:
        return None
    x1, x2 = np.meshgrid(c1, c2)
    a, b = (x1, x2) if plane == (d1, d2) else (x2, x1)
    inside = np.zeros(x1.shape, dtype=bool)
    for kind, v in body:
        if kind == "circle":
            inside |= (a - v[0]) ** 2 + (b - v[1]) ** 2 < v[2] ** 2
        else:
            inside |= (a > v[0]) & (a < v[2]) & (b > v[1]) & (b < v[3])
    if run.key("obstacle.invert") == "on":
        inside = ~inside
    return inside


def draw_body(ax, run, d1, d2):
    """The outline of every shape of the plane (d1 horizontal, d2 vertical)."""
    body, plane = shapes(run)
    if not body or plane is None or set(plane) != {d1, d2}:
        return False
    swap = plane != (d1, d2)
    for kind, v in body:
        if kind == "circle":
            c = (v[1], v[0]) if swap else (v[0], v[1])
            p = patches.Circle(c, v[2], fill=False, ec="k", lw=1.2)
        else:
            a0, b0, a1, b1 = (v[1], v[0], v[3], v[2]) if swap else v
            p = patches.Rectangle((a0, b0), a1 - a0, b1 - b0, fill=False, ec="k", lw=1.2)
        ax.add_patch(p)
    return True
