#!/usr/bin/python3
"""Turns the --help text of cdem-run and cdem-strain into man pages (roff), so that the man
pages and --help never disagree: `make man` runs it, tests/test_man.c fails when a
committed page differs from what it generates.

usage: help2roff.py BUILD_DIR OUT_DIR     writes OUT_DIR/cdem-run.1 and OUT_DIR/cdem-strain.1

The pages depend only on the programs' help output and VERSION (no dates), so they are
reproducible. Layout of a page: NAME, SYNOPSIS (the usage lines), DESCRIPTION (the help's
prose), OPTIONS or COMMANDS (two-space indented '-x'/'name' rows with their continuation
lines), per-command usage of cdem-strain's render, mohr, repose and plot-series, EXIT
STATUS, FILES, SEE ALSO.
"""
import os
import re
import subprocess
import sys

NAMES = {
    "cdem-run": "simulate a 2-D discrete element model of a tectonic structure",
    "cdem-strain": "analyse, render and export cdem-run results (displacement, strain, stress, pictures)",
}
SUBCOMMAND_HELP = ["render", "mohr", "repose", "plot-series"]


def esc(text):
    """Escapes roff specials in running text."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return re.sub(r"^([.'])", r"\\&\1", text)


def run_help(prog, *args):
    p = subprocess.run([prog, *args, "--help"], capture_output=True, text=True,
                       env=dict(os.environ, LC_ALL="C"))
    return (p.stdout + p.stderr).rstrip("\n")


def paragraphs(text):
    out, cur = [], []
    lines = text.split("\n")
    for i, line in enumerate(lines):
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if line.startswith("Exit status") and cur:
            out.append(cur); cur = []
        if line.strip():
            cur.append(line.rstrip())
        elif line and nxt.startswith("  ") and cur:
            continue  # a whitespace-only argument line inside an indented block
        elif cur:
            out.append(cur); cur = []
    if cur:
        out.append(cur)
    return out


def rows(par):
    """Two-space indented rows '  key   text' with deeper-indented continuation lines."""
    items = []
    cols = [m.start(2) for m in (re.match(r"^  (\S.*?)\s{2,}(\S.*)$", l) for l in par) if m]
    col = max(set(cols), key=cols.count) if cols else 0
    for line in par:
        m = re.match(r"^  (\S.*?)(?:\s{2,}(\S.*))?$", line)
        if m and not m.group(2) and col and len(line) > col and line[col - 1] == " ":
            items.append([line[2:col].strip(), [line[col:].strip()]])
            continue
        if m and not line.startswith("   "):
            items.append([m.group(1), [m.group(2)] if m.group(2) else []])
        elif items:
            items[-1][1].append(line.strip())
    return items


def page(name, prog, version):
    text = run_help(prog)
    pars = paragraphs(text)
    r = [f'.TH {name.upper()} 1 "cdem-c {version}" "cdem-c {version}" "User Commands"',
         ".SH NAME", f"{name} \\- {esc(NAMES[name])}", ".SH SYNOPSIS", ".nf"]
    r += [esc(l) for l in pars[0]] + [".fi"]
    body = pars[1:]
    desc = [p for p in body if not p[0].startswith("  ") and not p[0].endswith(":")
            and not p[0].startswith("Exit status")]
    opts = [p for p in body if p[0].startswith("  ")]
    cmds = [p for p in body if p[0].endswith(":")]
    tail = [p for p in body if p[0].startswith("Exit status")]
    if desc:
        r.append(".SH DESCRIPTION")
        for p in desc:
            r += [".PP", esc(" ".join(l.strip() for l in p))]
    for p in opts:
        r.append(".SH OPTIONS")
        for key, lines in rows(p):
            r += [".TP", f"\\fB{esc(key)}\\fR", esc(" ".join(lines))]
    for p in cmds:
        r.append(f".SH {p[0].rstrip(':').upper()}")
        for key, lines in rows(p[1:]):
            r += [".TP", f"\\fB{esc(key)}\\fR"]
            r += [esc(lines[0]) if lines else "", ".br"] + [esc(l) for l in lines[1:]]
            if r[-1] == ".br":
                r.pop()
    if name == "cdem-strain":
        r.append(".SH COMMAND OPTIONS")
        for sub in SUBCOMMAND_HELP:
            h = [l for l in run_help(prog, sub).split("\n")
                 if l.strip() and not l.endswith(": help")]
            r += [".SS " + sub, ".nf"] + [esc(l) for l in h] + [".fi"]
    for p in tail:
        lines = " ".join(l.strip() for l in p)
        status, _, rest = lines.partition(". ")
        r += [".SH EXIT STATUS", esc(status.replace("Exit status: ", "") + ".")]
        if rest:
            r += [".SH NOTES", esc(rest)]
    r += [".SH FILES",
          "Parameter files are INI files (\\fBcdem\\-run \\-\\-print\\-defaults\\fR writes a complete one);",
          "results are HDF5 files with an .xmf sidecar for ParaView (docs/format.md).",
          ".SH SEE ALSO",
          "\\fBcdem\\-run\\fR(1), \\fBcdem\\-strain\\fR(1); docs/guide.md (the user guide),",
          "docs/parameters.md, docs/analysis.md, docs/rendering.md and examples/ in the cdem\\-c sources."]
    return "\n".join(r) + "\n"


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    build, out = argv[1], argv[2]
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        with open(os.path.join(here, "..", "VERSION")) as f:
            version = f.read().strip()
    except OSError:
        version = "0.0.0"
    os.makedirs(out, exist_ok=True)
    for name in NAMES:
        prog = os.path.join(build, name)
        with open(os.path.join(out, name + ".1"), "w") as f:
            f.write(page(name, prog, version))


if __name__ == "__main__":
    main(sys.argv)
