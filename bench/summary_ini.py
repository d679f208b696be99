"""Reading a muflow run for the study scripts: its summary.ini, and the
machine's load and the process's own cost for a timed run."""
import os
import time


def summary(path, section_name="result"):
    """The [result] section (or another) of a summary.ini as a dict of
    strings (comment lines skipped; a value is kept whole, a message's own
    ';' included)."""
    out, section = {}, None
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line.startswith(";"):
                continue
            if line.startswith("["):
                section = line.strip("[]")
            elif section == section_name and "=" in line:
                k, v = line.split("=", 1)
                out[k.strip()] = v.strip()
    return out


def loadavg():
    """The 1-minute load average, to record beside a timing."""
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def timed_run(args, **popen):
    """Runs one process to its end: (exit code, wall s, CPU s of all its
    threads, peak resident MB), the last two from its own rusage (wait4).
    Linux counts the caller's resident size at the fork into the child's
    peak, so the peak of a child smaller than this script reads as the
    script's (a script that imports matplotlib: about 59 MB)."""
    import subprocess
    t0 = time.monotonic()
    p = subprocess.Popen(args, **popen)
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    return (os.waitstatus_to_exitcode(status), wall, ru.ru_utime + ru.ru_stime,
            ru.ru_maxrss / 1024.0)
