#!/usr/bin/python3
"""Plots muflow runs: each scene against its reference, the history, fields.

    /usr/bin/python3 tools/muflow_plot.py OUTDIR [OUTDIR ...] [--out DIR]
                                          [--field NAME ...]

OUTDIR is a run's output.dir.  For each run, prints the headline of
summary.ini's [result] (status, steps, the errors, each value beside its
exact or reference one, the scene's own numbers; each key once) and draws
into DIR (default OUTDIR; with several runs DIR/<run folder name>):

  compare.png       the scene against its reference: the profile scenes'
                    velocity against the exact profile (bagnold, bagnold2,
                    chute, couette, bingham_channel, bedload), the cavity's
                    mid-line and psi_max against Vola et al. (2003), the
                    heap's surface velocity and flowing layer, the ducts'
                    mid-plane against the plane channel, the collapse's
                    x_f(t), h(0, t) and surface against Lagree et al.
                    (2011), the cylinder's drag, a body in a channel against
                    Schaefer & Turek (1996); a scene this tool does not
                    name, its profile.csv's first value column against the
                    file's exact column (muflow alone without one)
  history.png       a steady run's residual and error against the step; a
                    transient run's time step and kinetic energy against t
  field_NAME.png    a dataset of the last fields_*.h5 over the box's two
                    widest directions (equal axes, the body's outline):
                    velocity (its magnitude) by default, or each --field
                    NAME given (pressure, viscosity, tracer, shear_rate, ...:
                    any dataset of the file; an unknown name lists them)

Axes are in the case's units: SI where the case is (a gravity of 9.81), else
the scene's scales (none for a scene this tool does not name).  A plot whose
input is missing is skipped with a note.  Exit status 0; 1 when an OUTDIR
holds no muflow output; 2 for a --field the field files do not have.  Needs
Debian's /usr/bin/python3 with numpy, matplotlib and h5py (`make deps`).
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from plots import fields, figure, history, scenes  # noqa: E402
from plots.run import Run  # noqa: E402
from plots.units import Units  # noqa: E402

KNOWN = ("summary.ini", "profile.csv", "history.csv")


def is_run(path):
    return os.path.isdir(path) and (
        any(os.path.exists(os.path.join(path, k)) for k in KNOWN) or
        any(n.startswith("fields_") and n.endswith(".h5") for n in os.listdir(path)))


def plot_run(run, out, names):
    units = Units(run)
    if run.has_summary:
        for key, text in scenes.headline(run):
            print("%s = %s" % (key, text))
        for note in run.notes:
            print("summary.ini: %s" % note)
    else:
        print("no summary.ini (the run did not finish)")
    print("axes in %s" % ("SI units" if units.si else "the case's dimensionless units"))
    compare = scenes.comparison(run)
    if compare is not None:
        compare(run, out, units)
    else:
        print("scene '%s' has no comparison to draw" % (run.scene or "?"))
    history.plot(run, out, units)
    for name in names:
        fields.plot(run, out, name, units)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="+", metavar="OUTDIR", help="a run's output folder")
    p.add_argument("--out", help="folder for the PNGs (default: the run folder)")
    p.add_argument("--field", action="append", metavar="NAME",
                   help="a dataset of the field files to map (repeatable; default velocity)")
    args = p.parse_args(argv)
    names = args.field or ["velocity"]
    runs = []
    for path in args.runs:
        if not is_run(path):
            print("muflow_plot: %s holds no muflow output" % path, file=sys.stderr)
            return 1
        run = Run(path)
        for name in names:
            try:
                fields.check(run, name)
            except fields.FieldMissing as e:
                print("muflow_plot: %s" % e, file=sys.stderr)
                return 2
        runs.append(run)
    for run in runs:
        out = args.out or run.dir
        if args.out and len(runs) > 1:
            out = os.path.join(args.out, os.path.basename(os.path.normpath(run.dir)))
        os.makedirs(out, exist_ok=True)
        if len(runs) > 1:
            print("== %s (%s)" % (run.dir, run.name))
        plot_run(run, out, names)
    figure.plt.close("all")
    return 0


if __name__ == "__main__":
    sys.exit(main())
