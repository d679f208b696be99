#!/usr/bin/python3
"""The commands of README.md's code blocks, as a user on a fresh clone types them.

    /usr/bin/python3 readme_commands.py REPO MUFLOW

Every line of a fenced code block (without a language, or `sh`) that starts
with `make`, `build/muflow`, `/usr/bin/python3 tools/` or a one-line
`for V in ...; do ...; done` over them is a command; a `#` after a blank
starts a comment, and a comment saying "exit status N" sets the status
the command must end with (0 otherwise).  Each command is checked, and the
cheap ones are run:

  make TARGET [VAR=value ...]   the Makefile has a rule for TARGET and
      `make -n` in REPO exits 0
  build/muflow --version, --list, --list=markdown, --help    run, exit 0
  build/muflow CASE [section.key=value ...]   CASE exists in REPO, every
      section.key is a key `muflow --list` prints; run (exit 0) when CASE
      is one of the quick scenes
  build/muflow --restart DIR [overrides]   the keys as above; run when DIR
      was written by a command run before it
  /usr/bin/python3 tools/SCRIPT ARGS   the script exists; run when its run
      folder was written by a command run before it
  [VAR=value ...] mpirun OPTIONS build/muflow ...   OPTIONS of the forms
      -np N, --hostfile FILE, --map-by SPEC; the muflow command as above;
      run (as root with --allow-run-as-root, without the environment's
      Open MPI variables) when N <= 2, no hostfile and a quick case

Every picture `![...](path)` and every linked case file `(cases/...)` must
exist in REPO.  The runs happen in order in a scratch folder holding `cases`, `tools` and
`build/muflow` (links to REPO's and MUFLOW), so `out/...` lands there.  A line
of any other form in a code block is an error: the README would show a
command this check does not know.  Exit status 0, or 1 with the failures.
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

QUICK = {"cases/bagnold.ini", "cases/chute.ini", "cases/couette.ini",
         "cases/bingham_channel.ini", "cases/bedload.ini", "cases/duct_square.ini"}
TIMEOUT = 120


def code_lines(readme):
    """The lines of the shell code blocks, comments stripped, each with the
    exit status its comment expects."""
    out, inside, shell = [], False, False
    for line in readme.splitlines():
        fence = re.match(r"^```(\S*)", line)
        if fence:
            if not inside:
                inside, shell = True, fence.group(1) in ("", "sh", "shell")
            else:
                inside = False
            continue
        if inside and shell:
            status = re.search(r"\s#.*exit status (\d+)", line)
            line = re.sub(r"\s+#.*$", "", line).strip()
            if line:
                out.append((line, int(status.group(1)) if status else 0))
    return out


def expand(line):
    """A one-line for loop as its commands; any other line as itself."""
    m = re.match(r"^for (\w+) in ([^;]+); do (.+); done$", line)
    if not m:
        return [line]
    var, values, body = m.group(1), m.group(2).split(), m.group(3)
    return [re.sub(r"\$\{?%s\}?" % var, v, body) for v in values]


MPIRUN_OPTIONS = ("-np", "--hostfile", "--map-by")


def is_command(line):
    words = line.split()
    while words and re.match(r"^[A-Z_]+=\S+$", words[0]):
        words = words[1:]
    if words and words[0] == "mpirun":
        return True
    return line.startswith(("make", "build/muflow", "/usr/bin/python3 tools/", "for "))


def mpirun_split(words):
    """(environment, mpirun's words, the command's words, why not) of a
    command under mpirun; (None, None, words, None) for any other."""
    env, i = {}, 0
    while i < len(words) and re.match(r"^[A-Z_]+=\S+$", words[i]):
        k, v = words[i].split("=", 1)
        env[k] = v
        i += 1
    if i >= len(words) or words[i] != "mpirun":
        return None, None, words, None
    j = i + 1
    while j < len(words) and words[j] in MPIRUN_OPTIONS and j + 1 < len(words):
        j += 2
    if j >= len(words) or words[j] != "build/muflow":
        return env, words[i:j], words[j:], "an mpirun option this check does not know"
    return env, words[i:j], words[j:], None


def main():
    repo, muflow = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    with open(os.path.join(repo, "README.md")) as f:
        readme = f.read()
    lines = code_lines(readme)
    with open(os.path.join(repo, "Makefile")) as f:
        makefile = f.read()
    listed = subprocess.run([muflow, "--list"], capture_output=True, text=True, check=True).stdout
    keys = set(re.findall(r"^  (\w+\.\w+) = ", listed, re.M))
    failures, ran, checked = [], 0, 0
    for path in re.findall(r"!\[[^]]*\]\(([^)]+)\)", readme) + re.findall(r"\((cases/[^)]+)\)", readme):
        if not os.path.isfile(os.path.join(repo, path)):
            failures.append("no file " + path)
    scratch = tempfile.mkdtemp(prefix="muflow_readme_")
    try:
        os.makedirs(os.path.join(scratch, "build"))
        os.symlink(muflow, os.path.join(scratch, "build", "muflow"))
        for d in ("cases", "tools"):
            os.symlink(os.path.join(repo, d), os.path.join(scratch, d))
        for line, status in lines:
            if not is_command(line):
                # output shown in a block (a run's printout) starts otherwise
                if re.match(r"^(muflow |step |\w+: |output: |checkpoint: )", line):
                    continue
                failures.append("not a command this check knows: " + line)
                continue
            for cmd in expand(line):
                env, mpirun, words, why = mpirun_split(shlex.split(cmd))
                run_it = False
                if why:
                    failures.append("%s: %s" % (cmd, why))
                    continue
                if words[0] == "make":
                    targets = [w for w in words[1:] if "=" not in w and not w.startswith("-")]
                    for target in targets:
                        if not re.search(r"^([^:#=\s]+ )*%s( [^:#=\s]+)*:" % re.escape(target),
                                         makefile, re.M):
                            why = "the Makefile has no rule for " + target
                    r = subprocess.run(["make", "-n", "-C", repo] + words[1:],
                                       capture_output=True, text=True)
                    if r.returncode != 0:
                        why = "`make -n` failed: " + r.stderr.strip()[-300:]
                elif words[0] == "build/muflow":
                    args = words[1:]
                    if args and args[0] in ("--version", "--list", "--list=markdown", "--help"):
                        run_it = True
                    else:
                        if args and args[0] == "--restart":
                            overrides = args[2:]
                            run_it = os.path.isdir(os.path.join(scratch, args[1]))
                        else:
                            overrides = args[1:]
                            if not args or not os.path.isfile(os.path.join(repo, args[0])):
                                why = "no case file " + (args[0] if args else "given")
                            run_it = bool(args) and args[0] in QUICK
                        for ov in overrides:
                            key = ov.split("=", 1)[0]
                            if "=" not in ov or key not in keys:
                                why = "%s: not a key of muflow --list" % key
                elif words[:2] == ["/usr/bin/python3", words[1]] and words[1].startswith("tools/"):
                    if not os.path.isfile(os.path.join(repo, words[1])):
                        why = "no script " + words[1]
                    folders = [w for w in words[2:] if not w.startswith("-")]
                    run_it = bool(folders) and os.path.isdir(os.path.join(scratch, folders[0]))
                else:
                    why = "not a command this check knows"
                if why:
                    failures.append("%s: %s" % (cmd, why))
                    continue
                checked += 1
                run_env = None
                if mpirun is not None:
                    ranks = int(mpirun[mpirun.index("-np") + 1]) if "-np" in mpirun else 0
                    run_it = run_it and 0 < ranks <= 2 and "--hostfile" not in mpirun
                    run_env = {k: v for k, v in os.environ.items()
                               if not k.startswith(("OMPI_", "PMIX_", "OPAL_"))}
                    run_env.update(env)
                    # under the sanitizers: Open MPI's own allocations at exit
                    # are no leak of ours (as test_mpi.c's mpirun runs)
                    if "ASAN_OPTIONS" in run_env:
                        run_env["ASAN_OPTIONS"] = "detect_leaks=0"
                    root = ["--allow-run-as-root"] if os.geteuid() == 0 else []
                    words = mpirun[:1] + root + mpirun[1:] + words
                if run_it:
                    r = subprocess.run(words, cwd=scratch, capture_output=True, text=True,
                                       timeout=TIMEOUT, env=run_env)
                    ran += 1
                    if r.returncode != status:
                        failures.append("%s: exit %d\n%s" % (cmd, r.returncode,
                                                            (r.stdout + r.stderr)[-600:]))
    finally:
        shutil.rmtree(scratch)
    for f in failures:
        print("README:", f)
    print("README: %d commands, %d checked, %d run, %d failed" %
          (sum(len(expand(l)) for l, _ in lines if is_command(l)), checked, ran, len(failures)))
    return 1 if failures or ran == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
