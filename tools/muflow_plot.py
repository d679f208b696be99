#!/usr/bin/python3
"""Reads a muflow run folder and plots it.

    /usr/bin/python3 tools/muflow_plot.py OUTDIR [--out DIR] [--field NAME]

OUTDIR is a run's output.dir (summary.ini, profile.csv, history.csv,
fields_*.h5).  Prints the headline numbers of summary.ini's [result] section
as they stand there (status, steps, the error and the headline value with its
exact value, the heap's tilt and flow rate) and draws, into DIR (default
OUTDIR):

  profile.png   the profile (profile.csv) against the analytic one
  history.png   residual and error against the step (history.csv)
  field.png     a cell field of the last fields_*.h5 over the two widest
                directions (the middle cell layer of the third): the
                velocity magnitude by default, or --field NAME (pressure,
                pressure_regularised, shear_rate, inertial_number, viscosity,
                velocity)

A plot whose input is missing (a scene without a profile, output.fields =
off) is skipped with a note.  Exit status 0, or 1 when OUTDIR holds none of
the files.  Needs numpy, matplotlib and h5py (Debian: python3-matplotlib
python3-h5py, `make deps`).
"""
import argparse
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

FIELD_NAMES = ("velocity", "pressure", "pressure_regularised", "shear_rate",
               "inertial_number", "viscosity")


def read_ini(path):
    """{section: [(key, value text), ...]} in file order; comments skipped."""
    sections, current = {}, None
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            if not s or s[0] in ";#":
                continue
            if s.startswith("[") and s.endswith("]"):
                current = sections.setdefault(s[1:-1], [])
            elif "=" in s and current is not None:
                key, value = s.split("=", 1)
                current.append((key.strip(), value.strip()))
    return sections


def headline(result):
    """The lines to print: (key, value text) from [result], in a fixed order."""
    values = dict(result)
    keys = ["status", "steps"]
    keys += [k for k in ("err_rms", "err_midline") if k in values]
    # the headline value is the key that has a key_exact beside it
    keys += [k for k, _ in result if k + "_exact" in values or k + "_reference" in values]
    keys += [k for k in ("tilt", "flow_rate") if k in values]
    lines = []
    for k in keys:
        if k not in values:
            continue
        text = values[k]
        if k + "_exact" in values:
            text += " (exact %s)" % values[k + "_exact"]
        elif k + "_reference" in values:
            text += " (reference %s)" % values[k + "_reference"]
        lines.append((k, text))
    return lines


def read_csv(path):
    """Header and columns (numpy arrays of floats, nan where unreadable)."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    if not rows:
        return [], []
    header, body = rows[0], rows[1:]

    def num(text):
        try:
            return float(text)
        except ValueError:
            return math.nan

    cols = [np.array([num(r[c]) if c < len(r) else math.nan for r in body])
            for c in range(len(header))]
    return header, cols


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print("wrote %s" % path)


def plot_profile(run, out, title):
    path = os.path.join(run, "profile.csv")
    if not os.path.exists(path):
        print("no profile.csv (a scene without a profile): no profile plot")
        return None
    header, cols = read_csv(path)
    if len(header) < 2 or len(cols[0]) == 0:
        print("profile.csv is empty: no profile plot")
        return None
    coord, vel = cols[0], cols[1]
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.plot(vel, coord, "o", ms=4, label="muflow")
    exact = -1
    for suffix in ("_exact", "_reference"):
        if header[1] + suffix in header:
            exact = header.index(header[1] + suffix)
    if exact >= 0 and np.isfinite(cols[exact]).any():
        ok = np.isfinite(cols[exact])
        ax.plot(cols[exact][ok], coord[ok], "-", label="analytic / reference")
    else:
        print("profile.csv has no analytic profile: muflow's alone")
    ax.set_xlabel(header[1])
    ax.set_ylabel(header[0])
    ax.set_title(title + ": profile")
    ax.grid(alpha=0.3)
    ax.legend()
    dest = os.path.join(out, "profile.png")
    save(fig, dest)
    return dest


def plot_history(run, out, title):
    path = os.path.join(run, "history.csv")
    if not os.path.exists(path):
        print("no history.csv: no history plot")
        return None
    header, cols = read_csv(path)
    if "step" not in header or len(cols[0]) == 0:
        print("history.csv is empty: no history plot")
        return None
    col = dict(zip(header, cols))
    step = col["step"]
    fig, ax = plt.subplots(figsize=(6, 4))
    drawn = 0
    for name, style in (("residual", "-"), ("err_rms", "--"), ("err_midline", "--")):
        y = col.get(name)
        if y is None:
            continue
        ok = np.isfinite(y) & (y > 0)
        if ok.any():
            ax.semilogy(step[ok], y[ok], style, label=name)
            drawn += 1
    if not drawn:
        print("history.csv has no positive residual or error: history plot empty")
    ax.set_xlabel("step")
    ax.set_title(title + ": history")
    ax.grid(alpha=0.3, which="both")
    if drawn:
        ax.legend()
    dest = os.path.join(out, "history.png")
    save(fig, dest)
    return dest


def last_fields_file(run):
    best, best_step = None, -1
    for name in os.listdir(run):
        m = re.fullmatch(r"fields_(\d+)\.h5", name)
        if m and int(m.group(1)) > best_step:
            best, best_step = name, int(m.group(1))
    return best


def plot_field(run, out, title, field):
    import h5py

    name = last_fields_file(run)
    if name is None:
        print("no fields_*.h5: no field map")
        return None
    with h5py.File(os.path.join(run, name), "r") as f:
        n = [int(v) for v in f.attrs["n"]]          # nx ny nz
        length = [float(v) for v in f.attrs["len"]]
        step = int(f.attrs["step"])
        a = np.asarray(f[field][...], dtype=float)  # (nz, ny, nx[, 3])
    label = field
    if field == "velocity":
        a = np.sqrt((a ** 2).sum(axis=-1))
        label = "|velocity|"
    # the two widest directions (x, y, z order on ties); the middle layer of the third
    d1, d2 = sorted(sorted(range(3), key=lambda d: -n[d])[:2])
    third = 3 - d1 - d2
    axis_of = {0: 2, 1: 1, 2: 0}  # direction -> array axis (arrays are (z, y, x))
    s = np.take(a, n[third] // 2, axis=axis_of[third])
    # s has the remaining axes in (z, y, x) order: d2 first, then d1
    names = "xyz"
    e1 = np.linspace(0.0, length[d1], n[d1] + 1)
    e2 = np.linspace(0.0, length[d2], n[d2] + 1)
    fig, ax = plt.subplots(figsize=(6, 5))
    norm = None
    finite = s[np.isfinite(s)]
    if field in ("viscosity", "shear_rate", "inertial_number") and finite.size and \
            finite.min() > 0 and finite.max() > 100 * finite.min():
        norm = matplotlib.colors.LogNorm()  # decades apart: rigid zones beside flowing ones
    mesh = ax.pcolormesh(e1, e2, s, shading="flat", cmap="viridis", norm=norm)
    fig.colorbar(mesh, ax=ax, label=label)
    ax.set_xlabel(names[d1])
    ax.set_ylabel(names[d2])
    if max(length[d1], length[d2]) <= 3 * min(length[d1], length[d2]):
        ax.set_aspect("equal")  # else a thin profile grid: stretched to be seen
    where = "" if n[third] == 1 else "\n(cell layer %d of %d along %s)" % (
        n[third] // 2, n[third], names[third])
    ax.set_title("%s: %s, step %d%s" % (title, label, step, where), fontsize=10)
    dest = os.path.join(out, "field.png")
    save(fig, dest)
    return dest


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run", help="a run's output folder")
    p.add_argument("--out", help="folder for the PNGs (default: the run folder)")
    p.add_argument("--field", default="velocity", choices=FIELD_NAMES,
                   help="cell field of the map (velocity: its magnitude)")
    args = p.parse_args(argv)
    run = args.run
    if not os.path.isdir(run):
        print("muflow_plot: %s is not a folder" % run, file=sys.stderr)
        return 1
    known = ("summary.ini", "profile.csv", "history.csv")
    if not any(os.path.exists(os.path.join(run, k)) for k in known) and not last_fields_file(run):
        print("muflow_plot: %s holds no muflow output" % run, file=sys.stderr)
        return 1
    out = args.out or run
    os.makedirs(out, exist_ok=True)

    title = os.path.basename(os.path.normpath(run))
    summary = os.path.join(run, "summary.ini")
    if os.path.exists(summary):
        ini = read_ini(summary)
        for key, text in headline(ini.get("result", [])):
            print("%s = %s" % (key, text))
    else:
        print("no summary.ini (the run did not finish)")
    plot_profile(run, out, title)
    plot_history(run, out, title)
    plot_field(run, out, title, args.field)
    return 0


if __name__ == "__main__":
    sys.exit(main())
