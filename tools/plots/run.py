"""A run folder read once: summary.ini (its [result] and the case keys), the
CSV files, the field files, and the reference data of cases/data/."""
import csv
import math
import os
import re

import numpy as np

TOOLS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASES_DATA = os.path.join(TOOLS, "..", "cases", "data")
# a [result] value's partners: key_exact, key_reference, key_plane
PARTNERS = (("_exact", "exact"), ("_reference", "reference"), ("_plane", "plane channel"))


def read_summary(path):
    """({section: {key: value text}}, case name, [duplicate notes]).

    Comment lines are skipped, a value is kept whole (a message's own ';'
    included).  A key written twice in a section keeps its first value; the
    later ones are reported in the notes, never shown as a second key."""
    sections, name, notes, current = {}, None, [], None
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            m = re.match(r";\s*muflow case:\s*(\S+)", s)
            if m:
                name = m.group(1)
            if not s or s[0] in ";#":
                continue
            if s.startswith("[") and s.endswith("]"):
                current = sections.setdefault(s[1:-1], {})
            elif "=" in s and current is not None:
                key, value = (t.strip() for t in s.split("=", 1))
                if key in current:
                    if value != current[key]:
                        notes.append("%s written twice (%s, then %s): the first kept"
                                     % (key, current[key], value))
                else:
                    current[key] = value
    return sections, name, notes


class Table:
    """A CSV file's columns: numbers as float arrays (nan where not a
    number), the text of each column in .text."""

    def __init__(self, path):
        with open(path, newline="", encoding="utf-8") as f:
            rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
        self.header = [h.strip() for h in rows[0]] if rows else []
        body = rows[1:]
        self.text = {h: [r[c] if c < len(r) else "" for r in body]
                     for c, h in enumerate(self.header)}
        self.cols = {h: np.array([_num(t) for t in v]) for h, v in self.text.items()}
        self.rows = len(body)

    def __contains__(self, name):
        return name in self.cols

    def __getitem__(self, name):
        return self.cols[name]


def _num(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def reference_curve(path, dataset, param=None, rel=1e-3):
    """(coord, value) arrays of dataset in a reference file of cases/data
    (rows "dataset,parameter,coord,value"), at the parameter within rel, or
    every row when param is None (coord is then the parameter); sorted by
    coord, empty arrays when none match."""
    pts = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            parts = line.strip().split(",")
            if line.startswith("#") or len(parts) != 4 or parts[0] != dataset:
                continue
            try:
                p, x, y = float(parts[1]), float(parts[2]), float(parts[3])
            except ValueError:
                continue
            if param is None:
                pts.append((p, y))
            elif abs(p - param) <= rel * max(1.0, abs(param)):
                pts.append((x, y))
    pts.sort()
    return np.array([p[0] for p in pts]), np.array([p[1] for p in pts])


class Run:
    """One output folder.  Keys are read from what exists: summary.ini when
    the run finished, else the attributes of its last field file."""

    def __init__(self, path):
        self.dir = path
        self.result, self.case, self.notes = {}, {}, []
        self.name = None
        summary = os.path.join(path, "summary.ini")
        self.has_summary = os.path.exists(summary)
        if self.has_summary:
            sections, self.name, self.notes = read_summary(summary)
            self.result = sections.pop("result", {})
            for sec, keys in sections.items():
                for k, v in keys.items():
                    self.case["%s.%s" % (sec, k)] = v
        self.fields = self._field_files()
        if not self.case and self.fields:
            self._case_from_fields(self.fields[-1][1])
        self.name = self.name or os.path.basename(os.path.normpath(path))
        self.scene = self.case.get("case.scene", "")
        self.transient = self.case.get("solver.mode") == "transient"

    def _field_files(self):
        found = []
        for name in os.listdir(self.dir):
            m = re.fullmatch(r"fields_(\d+)\.h5", name)
            if m:
                found.append((int(m.group(1)), os.path.join(self.dir, name)))
        return sorted(found)

    def _case_from_fields(self, path):
        import h5py
        with h5py.File(path, "r") as f:
            for k, v in f.attrs.items():
                if isinstance(v, bytes):
                    v = v.decode()
                if k == "case_name":
                    self.name = v
                elif "." in k:
                    self.case[k] = str(v)

    def key(self, name, default=None):
        """A case key's text, 'section.key'."""
        return self.case.get(name, default)

    def num(self, name, default=math.nan):
        """A case key (section.key) or a [result] key (no dot) as a number."""
        text = self.case.get(name) if "." in name else self.result.get(name)
        try:
            return float(text)
        except (TypeError, ValueError):
            return default

    def partner(self, key):
        """(what, value text) of the [result] value key is compared with
        (key_exact, key_reference or key_plane), or None."""
        for suffix, what in PARTNERS:
            if key + suffix in self.result:
                return what, self.result[key + suffix]
        return None

    def table(self, name):
        """A CSV file of the run as a Table, or None when absent or empty."""
        path = os.path.join(self.dir, name)
        if not os.path.exists(path):
            return None
        t = Table(path)
        return t if t.rows else None

    @staticmethod
    def shipped(name):
        """cases/data/name when it exists, else None."""
        path = os.path.normpath(os.path.join(CASES_DATA, name))
        return path if os.path.exists(path) else None

    def reference(self, default_file):
        """The case's reference file (case.reference), or the shipped
        cases/data/default_file when the case names none or its path does not
        exist here (a run copied from elsewhere); None when neither exists."""
        given = self.key("case.reference", "")
        candidates = [given, os.path.join(CASES_DATA, os.path.basename(given))] if given else []
        candidates.append(os.path.join(CASES_DATA, default_file))
        for c in candidates:
            if c and os.path.exists(c):
                return os.path.normpath(c)
        return None
