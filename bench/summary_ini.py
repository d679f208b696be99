"""The [result] section of a muflow summary.ini, for the study scripts."""


def summary(path):
    """The [result] section of a summary.ini as a dict of strings (comment
    lines skipped; a value is kept whole, a message's own ';' included)."""
    out, section = {}, None
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith(";"):
                continue
            if line.startswith("["):
                section = line.strip("[]")
            elif section == "result" and "=" in line:
                k, v = line.split("=", 1)
                out[k.strip()] = v.strip()
    return out
