"""field_NAME.png: one dataset of the run's last field file.

Any dataset the run registered can be drawn (velocity, pressure, tracer,
particle_velocity, the face components u, v, w, ...): vectors as their
magnitude, face components averaged to the cells.  The plane is the box's
two directions with the most cells (the middle cell layer of the third); a
box thinner than three cells across one of them (the profile scenes) gives a
line, the value against the long direction.  Maps have equal axes, a figure
of the box's aspect, the body's outline (obstacle.*) with its cells greyed,
and the grains' surface T = 1/2 when the run has a tracer."""
import textwrap

import matplotlib
import numpy as np

from . import figure
from .units import FIELD_KIND

NAMES = "xyz"
FACE_AXIS = {"u": 2, "v": 1, "w": 0, "up": 2, "vp": 1, "wp": 0}  # array axis (z, y, x)
SYMBOL = {"velocity": "|u|", "particle_velocity": "|u$_p$|", "tracer": "T",
          "pressure": "p", "pressure_regularised": "p$_{reg}$", "viscosity": r"$\eta$",
          "shear_rate": "|D|", "inertial_number": "I"}
LOG_FIELDS = ("viscosity", "shear_rate", "inertial_number")
# the symbols a user may type for a dataset of another name
ALIASES = {"T": "tracer", "eta": "viscosity", "p": "pressure", "I": "inertial_number"}


class FieldMissing(Exception):
    def __init__(self, name, path, available):
        super().__init__("no field '%s' in %s; it has: %s" % (name, path, ", ".join(available)))


def available(f):
    """The datasets of an open field file that are fields of the grid."""
    n = [int(v) for v in f.attrs["n"]]
    cells = (n[2], n[1], n[0])
    out = []
    for name, d in f.items():
        shape = tuple(d.shape)
        if len(shape) == 4 and shape[:3] == cells or len(shape) == 3 and \
                sum(a - b for a, b in zip(shape, cells)) in (0, 1) and \
                all(a - b in (0, 1) for a, b in zip(shape, cells)):
            out.append(name)
    return sorted(out)


def cell_values(f, name):
    """The dataset as a cell array (nz, ny, nx)."""
    a = np.asarray(f[name][...], dtype=float)
    n = [int(v) for v in f.attrs["n"]]
    cells = (n[2], n[1], n[0])
    if a.ndim == 4:
        return np.sqrt((a ** 2).sum(axis=-1))
    for ax in range(3):
        if a.shape[ax] == cells[ax] + 1:  # faces of a bounded direction
            lo = np.take(a, range(cells[ax]), axis=ax)
            hi = np.take(a, range(1, cells[ax] + 1), axis=ax)
            return 0.5 * (lo + hi)
    if name in FACE_AXIS:  # faces of a periodic direction: the last cell's high face is face 0
        return 0.5 * (a + np.roll(a, -1, axis=FACE_AXIS[name]))
    return a


def edges(f, d):
    """The face coordinates along direction d (stretched grids store them)."""
    key = NAMES[d] + "_faces"
    if key in f:
        return np.asarray(f[key][...], dtype=float)
    n, length = int(f.attrs["n"][d]), float(f.attrs["len"][d])
    return np.linspace(0.0, length, n + 1)


def resolve(name, names):
    """The dataset of names that name stands for (itself, or the dataset its
    alias names); raises FieldMissing when there is none."""
    if name in names:
        return name
    if ALIASES.get(name) in names:
        return ALIASES[name]
    raise FieldMissing(name, "the field files", names)


def check(run, name):
    """Raises FieldMissing when the run's last field file lacks name."""
    import h5py
    if not run.fields:
        return
    path = run.fields[-1][1]
    with h5py.File(path, "r") as f:
        names = available(f)
    try:
        resolve(name, names)
    except FieldMissing:
        raise FieldMissing(name, path, names) from None


def plot(run, out, name, units):
    import h5py
    if not run.fields:
        print("no fields_*.h5 (output.fields = off?): no field map")
        return None
    path = run.fields[-1][1]
    with h5py.File(path, "r") as f:
        names = available(f)
        try:
            name = resolve(name, names)
        except FieldMissing:
            raise FieldMissing(name, path, names) from None
        a = cell_values(f, name)
        tracer = cell_values(f, "tracer") if "tracer" in names and name != "tracer" else None
        n = [int(v) for v in f.attrs["n"]]
        e = [edges(f, d) for d in range(3)]
        step, time = int(f.attrs["step"]), float(f.attrs["time"])
    kind = FIELD_KIND.get(name, "none")
    symbol = SYMBOL.get(name, name)
    when = "t = %.4g, step %d" % (time, step) if run.transient else "step %d" % step
    # the two directions with the most cells (x, z, y on ties), the middle layer of the third
    d1, d2 = sorted(sorted(range(3), key=lambda d: (-n[d], (0, 2, 1).index(d)))[:2])
    third = 3 - d1 - d2
    axis_of = (2, 1, 0)  # direction -> array axis
    if min(n[d1], n[d2]) < 3:
        long_d = d1 if n[d1] >= n[d2] else d2
        others = tuple(axis_of[d] for d in range(3) if d != long_d)
        line = a.mean(axis=others)
        return _line(run, out, name, units, line, e[long_d], long_d, symbol, kind, when)
    s = np.take(a, n[third] // 2, axis=axis_of[third])  # axes (d2, d1)
    t = None if tracer is None else np.take(tracer, n[third] // 2, axis=axis_of[third])
    layer = "" if n[third] == 1 else ", cell layer %d of %d along %s" % (
        n[third] // 2 + 1, n[third], NAMES[third])
    return _map(run, out, name, units, s, t, e[d1], e[d2], d1, d2, symbol, kind,
                "%s: %s, %s%s" % (run.name, units.label(symbol, kind), when, layer))


def _line(run, out, name, units, line, e, d, symbol, kind, when):
    c = 0.5 * (e[:-1] + e[1:])
    fig = figure.new(5.0, 5.0)
    ax = fig.add_subplot()
    ax.plot(line, c, "o-", ms=3)
    ax.set_xlabel(units.label(symbol, kind))
    ax.set_ylabel(units.label(NAMES[d], "length"))
    ax.set_ylim(e[0], e[-1])
    ax.set_title("%s: %s along %s, %s" % (run.name, symbol, NAMES[d], when), fontsize=10)
    ax.grid(alpha=0.3)
    return figure.save(fig, out, "field_%s.png" % name)


def _map(run, out, name, units, s, t, e1, e2, d1, d2, symbol, kind, title):
    c1, c2 = 0.5 * (e1[:-1] + e1[1:]), 0.5 * (e2[:-1] + e2[1:])
    solid = figure.solid_mask(run, d1, d2, c1, c2)
    hidden = ~np.isfinite(s) if solid is None else ~np.isfinite(s) | solid
    s = np.ma.masked_array(s, mask=hidden)
    fig, ax, cax, orientation = figure.map_axes(e1[-1] - e1[0], e2[-1] - e2[0])
    ax.set_facecolor("0.8")  # the body's cells
    norm, cmap = None, "viridis"
    finite = s.compressed()
    finite = finite[np.isfinite(finite)]
    if name in LOG_FIELDS and finite.size and finite.min() > 0 and \
            finite.max() > 100 * finite.min():
        norm = matplotlib.colors.LogNorm()  # decades apart: rigid zones beside flowing ones
    if name == "tracer":
        norm, cmap = matplotlib.colors.Normalize(0.0, 1.0), "YlOrBr"
    mesh = ax.pcolormesh(e1, e2, s, shading="flat", cmap=cmap, norm=norm)
    fig.colorbar(mesh, cax=cax, label=units.label(symbol, kind), orientation=orientation)
    notes = []
    if figure.draw_body(ax, run, d1, d2):
        notes.append("black: the body")
    surface = t if t is not None else (s if name == "tracer" else None)
    if surface is not None and np.nanmin(surface) < 0.5 < np.nanmax(surface):
        # the cells' values held out to the box's edges: the line reaches the walls
        ax.contour(np.r_[e1[0], c1, e1[-1]], np.r_[e2[0], c2, e2[-1]],
                   np.pad(np.asarray(surface, dtype=float), 1, mode="edge"), levels=[0.5],
                   colors="w" if name != "tracer" else "k", linewidths=1.0)
        notes.append("%s line: T = 1/2" % ("white" if name != "tracer" else "black"))
    ax.set_aspect("equal")
    ax.set_xlim(e1[0], e1[-1])
    ax.set_ylim(e2[0], e2[-1])
    ax.set_xlabel(units.label(NAMES[d1], "length"))
    ax.set_ylabel(units.label(NAMES[d2], "length"))
    title = textwrap.fill(title, int(fig.get_figwidth() * 11))
    ax.set_title(title + ("\n(" + "; ".join(notes) + ")" if notes else ""), fontsize=10)
    return figure.save(fig, out, "field_%s.png" % name, crop=True)
