"""The column collapse's reference and series, for the study scripts
(collapse_study.py, collapse_gerris.py); no plotting library, so that a
script timing child processes does not carry it into their peak memory."""
import csv
import os

REFERENCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cases", "data",
                         "lagree2011_collapse.csv")


def reference():
    ref = {"x_front": {}, "h_axis": {}}
    with open(REFERENCE) as f:
        rows = [r for r in f if not r.startswith("#")]
    for r in csv.DictReader(rows):
        if abs(float(r["parameter"]) - 0.5) < 1e-9:
            ref[r["dataset"]][float(r["coord"])] = float(r["value"])
    return ref


def series(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return ([float(r["t"]) for r in rows], [float(r["x_front"]) for r in rows],
            [float(r["h_axis"]) for r in rows])


def at(ts, vs, t):
    for m in range(1, len(ts)):
        if ts[m] >= t - 1e-9:  # the end time, to the rounding of the sum of steps
            w = min(1.0, (t - ts[m - 1]) / (ts[m] - ts[m - 1]))
            return vs[m - 1] + w * (vs[m] - vs[m - 1])
    return vs[0] if t == 0 else float("nan")
