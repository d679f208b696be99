#!/usr/bin/python3
"""The layers of docs/architecture.md, checked on the sources.

usage: include_layers.py ROOT

Every file of src/, include/ and kernels/ belongs to a layer (its folder;
kernels/ is the kernels layer).  The layers, top to bottom:

    app scenes diagnostics io physics march solvers kernels config grid platform

and a file may include a header of its own layer or of one below.  Three
checks, each printing one line per finding:

  upward include    a quoted #include of a header of a higher layer (or one
                    that names no file of the tree);
  header cycle      headers that include each other;
  file cycle        source files that use each other's definitions: a.c uses
                    b.c when it names a function or object that b.c defines
                    (not static); a cycle means neither can be read, built or
                    tested without the other (a loop calling its stages,
                    which call helpers of the loop's file).  Every use also
                    goes downward, as the includes do.

Exit status 0 when nothing is found, 1 otherwise.  Standard library only.
"""
import os
import re
import sys

LAYERS = ["app", "scenes", "diagnostics", "io", "physics", "march", "solvers", "kernels",
          "config", "grid", "platform"]
RANK = {name: i for i, name in enumerate(LAYERS)}

INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.M)
IDENT = re.compile(r"[A-Za-z_]\w*")
KEYWORDS = {"if", "for", "while", "switch", "return", "sizeof", "do", "else", "case"}


def sources(root):
    """Every file of the layers, as paths relative to root."""
    out = []
    for top in ("src", "include"):
        base = os.path.join(root, top)
        for layer in sorted(os.listdir(base)):
            d = os.path.join(base, layer)
            if os.path.isdir(d):
                out += [f"{top}/{layer}/{f}" for f in sorted(os.listdir(d))
                        if f.endswith((".c", ".h"))]
    out += [f"kernels/{f}" for f in sorted(os.listdir(os.path.join(root, "kernels")))
            if f.endswith((".c", ".h"))]
    return out


def layer_of(path):
    parts = path.split("/")
    return "kernels" if parts[0] == "kernels" else parts[1]


def resolve(root, path, name):
    """An include as the compiler finds it: beside the file, then in include/."""
    for cand in (os.path.normpath(os.path.join(os.path.dirname(path), name)),
                 os.path.normpath(os.path.join("include", name))):
        if os.path.isfile(os.path.join(root, cand)):
            return cand
    return None


def strip_code(text):
    """The text without comments, string and character literals and
    preprocessor lines (their line breaks kept)."""
    out, i, n = [], 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c == "#":
            while i < n and (text[i] != "\n" or text[i - 1] == "\\"):
                i += 1
            continue
        if c == "/" and text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
            continue
        if c == "/" and text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
            continue
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
            continue
        if c == "\n":
            at_line_start = True
        elif not c.isspace():
            at_line_start = False
        out.append(c)
        i += 1
    return "".join(out)


def top_level(code):
    """The file's top-level declarations: (text before its body or end, has
    a body) for each, where a body is a brace block at depth 0."""
    out, depth, start = [], 0, 0
    for i, c in enumerate(code):
        if c == "{":
            if depth == 0:
                out.append((code[start:i], True))
            depth += 1
        elif c == "}":
            depth -= 1
            if depth == 0:
                start = i + 1
        elif c == ";" and depth == 0:
            out.append((code[start:i], False))
            start = i + 1
    return out


def without_macro_calls(head):
    """A declaration without the macro invocations before it (a scene's
    SCENE_PARAMS(...) block), which end with no semicolon."""
    while True:
        m = re.match(r"\s*[A-Z][A-Z0-9_]*\s*\(", head)
        if not m:
            return head.strip()
        depth, i = 1, m.end()
        while i < len(head) and depth:
            depth += {"(": 1, ")": -1}.get(head[i], 0)
            i += 1
        head = head[i:]


def definitions(code):
    """The names of the functions and objects a source file defines for
    other files (neither static nor extern declarations)."""
    names = set()
    for head, body in top_level(code):
        head = without_macro_calls(head)
        if not head:
            continue
        words = IDENT.findall(head)
        if not words or words[0] in ("static", "typedef", "extern", "_Static_assert"):
            continue
        if "static" in words[:3] or any(w.endswith("INLINE") for w in words[:2]):
            continue  # static, or a macro that says so (KERNEL_INLINE)
        if body and "=" not in head:
            m = re.search(r"(\w+)\s*\([^{]*\)\s*$", head, re.S)
            if m and m.group(1) not in KEYWORDS:
                names.add(m.group(1))  # a function's definition
            continue  # else a struct, union or enum type
        if "(" in head.split("=")[0] and "=" not in head:
            continue  # a prototype
        decl = re.sub(r"\[[^\]]*\]", "", head.split("=")[0]).strip()
        m = re.search(r"(\w+)\s*$", decl)
        if m and len(IDENT.findall(decl)) > 1:
            names.add(m.group(1))
    return names


def uses(code):
    """The identifiers a file names as written (a macro's expansion is not
    seen: its header's include is), member and tag names aside (after . or
    ->, struct, union, enum; offsetof's member)."""
    code = re.sub(r"\boffsetof\s*\([^()]*\)", "", code)
    return {m.group(0) for m in IDENT.finditer(code)
            if not re.search(r"(\.|->|\bstruct|\bunion|\benum)\s*$",
                             code[max(0, m.start() - 8):m.start()])}


def cycles(graph):
    """The strongly connected components of more than one node (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        work = [(v, iter(sorted(graph.get(v, ()))))]
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        while work:
            node, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                    advanced = True
                    break
                if w in on:
                    low[node] = min(low[node], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def check(root):
    files = sources(root)
    findings = []
    includes = {}
    for path in files:
        with open(os.path.join(root, path), encoding="utf-8") as f:
            text = f.read()
        includes[path] = []
        for m in INCLUDE.finditer(text):
            target = resolve(root, path, m.group(1))
            line = text.count("\n", 0, m.start()) + 1
            if target is None:
                findings.append(f"{path}:{line}: includes \"{m.group(1)}\", no file of the tree")
                continue
            includes[path].append(target)
            if target in RANK or layer_of(target) not in RANK:
                continue
            if RANK[layer_of(target)] < RANK[layer_of(path)]:
                findings.append(f"{path}:{line}: upward include of {target} "
                                f"({layer_of(path)} -> {layer_of(target)})")
    headers = {p: [t for t in ts if t.endswith(".h")] for p, ts in includes.items()
               if p.endswith(".h")}
    for comp in cycles(headers):
        findings.append("header cycle: " + " <-> ".join(comp))

    code = {}
    for path in files:
        if path.endswith(".c"):
            with open(os.path.join(root, path), encoding="utf-8") as f:
                code[path] = strip_code(f.read())
    defined = {}
    for path, c in code.items():
        for name in definitions(c):
            defined.setdefault(name, set()).add(path)
    graph = {}
    for path, c in code.items():
        graph[path] = set()
        for name in uses(c):
            for other in defined.get(name, ()):
                if other == path:
                    continue
                graph[path].add(other)
                if RANK[layer_of(other)] < RANK[layer_of(path)]:
                    findings.append(f"{path}: uses {name} of the higher layer's {other}")
    for comp in cycles(graph):
        findings.append("file cycle: " + " <-> ".join(comp))
    return findings, len(files)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    findings, n = check(sys.argv[1])
    for f in findings:
        print(f)
    if findings:
        print(f"include_layers: {len(findings)} findings in {n} files")
        return 1
    print(f"include_layers: {n} files, includes and uses downward, no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
