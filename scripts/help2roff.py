#!/usr/bin/python3
"""Turns the --help text of cdem-run and cdem-strain into man pages (roff), so that the man
pages and --help never disagree: `make man` runs it, tests/test_man.c fails when a
committed page differs from what it generates.

usage: help2roff.py BUILD_DIR OUT_DIR     writes OUT_DIR/cdem-run.1 and OUT_DIR/cdem-strain.1

The pages depend only on the programs' help output and VERSION (no dates), so they are
reproducible. The help layout is the one common/cli_help.h describes: usage forms, prose
paragraphs, headed lists ("Commands:", "Options:") of two-space indented rows, notes,
"Exit status: ...". Page layout: NAME, SYNOPSIS, DESCRIPTION, COMMANDS (cdem-strain),
OPTIONS, one subsection per command with its own usage, description and options
(`cdem-strain help COMMAND`), EXIT STATUS, NOTES, FILES, SEE ALSO.
"""
import os
import re
import subprocess
import sys

NAMES = {
    "cdem-run": "simulate a 2-D discrete element model of a tectonic structure",
    "cdem-strain": "analyse, render and export cdem-run results (displacement, strain, stress, pictures)",
}


def esc(text):
    """Escapes roff specials in running text."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return re.sub(r"^([.'])", r"\\&\1", text)


def run_help(prog, *args):
    p = subprocess.run([prog, *args], capture_output=True, text=True,
                       env=dict(os.environ, LC_ALL="C"))
    if p.returncode != 0 or p.stderr:
        sys.exit(f"help2roff: {prog} {' '.join(args)} exited {p.returncode}: {p.stderr}")
    return p.stdout.rstrip("\n")


def blocks(text):
    """Blank-line separated blocks of lines."""
    out, cur = [], []
    for line in text.split("\n"):
        if line.strip():
            cur.append(line.rstrip())
        elif cur:
            out.append(cur)
            cur = []
    if cur:
        out.append(cur)
    return out


def rows(lines):
    """Two-space indented rows 'key   text' with deeper-indented continuation lines."""
    items = []
    for line in lines:
        if re.match(r"^  \S", line):
            m = re.match(r"^  (\S.*?)(?:\s{2,}(\S.*))?$", line)
            items.append([m.group(1), [m.group(2)] if m.group(2) else []])
        elif items:
            items[-1][1].append(line.strip())
    return items


def parse(text):
    """The parts of one help text: synopsis lines, description paragraphs, headed row
    lists, notes paragraphs, exit status."""
    bs = blocks(text)
    usage = [re.sub(r"^(usage: |       )", "", l) for l in bs[0]]
    desc, lists, notes, status = [], [], [], None
    seen_list = False
    for b in bs[1:]:
        if b[0].startswith("Exit status: "):
            status = " ".join(l.strip() for l in b)[len("Exit status: "):]
        elif b[0].endswith(":") and not b[0].startswith(" "):
            lists.append((b[0][:-1], rows(b[1:])))
            seen_list = True
        else:
            (notes if seen_list else desc).append(b)
    return usage, desc, lists, notes, status


def prose(pars):
    r = []
    for p in pars:
        if p[0].startswith(" "):
            r += [".PP", ".nf"] + [esc(l) for l in p] + [".fi"]
        else:
            r += [".PP", esc(" ".join(l.strip() for l in p))]
    return r


def row_list(items):
    r = []
    for key, lines in items:
        r += [".TP", f"\\fB{esc(key)}\\fR", esc(" ".join(lines))]
    return r


def page(name, prog, version):
    usage, desc, lists, notes, status = parse(run_help(prog, "--help"))
    r = [f'.TH {name.upper()} 1 "cdem-c {version}" "cdem-c {version}" "User Commands"',
         ".SH NAME", f"{name} \\- {esc(NAMES[name])}", ".SH SYNOPSIS", ".nf"]
    r += [esc(l) for l in usage] + [".fi"]
    if desc:
        r += [".SH DESCRIPTION"] + prose(desc)
    commands = []
    for heading, items in lists:
        r += [f".SH {heading.upper()}"] + row_list(items)
        if heading == "Commands":
            commands = [k for k, _ in items]
    if commands:
        r.append(".SH COMMAND USAGE AND OPTIONS")
        for cmd in commands:
            cu, cd, cl, cn, _ = parse(run_help(prog, "help", cmd))
            r += [f".SS {esc(cmd)}", ".nf"] + [esc(l) for l in cu] + [".fi"]
            r += prose(cd)
            for heading, items in cl:
                r += [".PP", f"{esc(heading)}:", ".RS"] + row_list(items) + [".RE"]
            r += prose(cn)
    if status:
        r += [".SH EXIT STATUS", esc(status)]
    if notes:
        r += [".SH NOTES"] + prose(notes)
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
