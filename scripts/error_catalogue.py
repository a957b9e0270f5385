#!/usr/bin/python3
"""Lists every error message cdem-run and cdem-strain can print, from the sources: each
CDEM_FAIL(err, CODE, "format", ...) in common/, solver/ and analysis/, and the usage
messages printed by the two main programs. Writes markdown to stdout (docs/errors.md is
made with it: /usr/bin/python3 scripts/error_catalogue.py > docs/errors.md).

printf conversions are shown as <...> (a file name, a value, a line number...)."""
import glob
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")



def sources(pattern):
    """The source files matching pattern (relative to the repository root), sorted."""
    return sorted(os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, pattern)))


# The run file's implementation, one file per concept (common/h5/h5_internal.h)
H5_SOURCES = sources("common/h5/*.c")
# The subcommands that draw (their messages are in the pictures group)
PICTURE_COMMANDS = ["analysis/cli/cmd_render.c", "analysis/cli/cmd_plot.c",
                    "analysis/cli/cmd_plot_series.c", "analysis/cli/cmd_plot_csv.c"]

GROUPS = [  # (title, source files, what to do)
    ("Parameter files and -s overrides", ["common/params.c", "solver/base/model.c",
                                          "solver/run/summary.c", "solver/run/run_validate.c"],
     "The message names the file, line, key and value and says what is allowed: correct that "
     "line (or the -s argument). `cdem-run --print-defaults` writes a valid file to start "
     "from; docs/parameters.md lists every key, range and rule between keys."),
    ("Fault vertex files (irregular-fault)", ["solver/modes/fault_file.c"],
     "Fix the named line of the vertex file: two plain decimal numbers `x y` in metres per "
     "line; first point at (fault_location x width x unit_scaling, 0); every later point at "
     "lower x and higher y, every segment dipping at least 1 degree and at least half the "
     "smallest radius long, no point above twice the model's height. The path is relative to "
     "the directory cdem-run runs in."),
    ("Boundary modes and the run", [*sources("solver/modes/bc_*.c"), *sources("solver/run/*.c"),
      *sources("solver/packing/*.c"), *sources("solver/step/*.c"),
      *sources("solver/contact/*.c"), *sources("solver/base/*.c")],
     "Combinations the mode cannot build are refused before the run (change the named key); "
     "a numeric blow-up (NaN/Inf) means the time step is too large for the stiffness: keep "
     "`keep_constants = off` at small unit scaling or use the default constants; "
     "\"settling > displacement\" gives the display_interval and equilibration that work."),
    ("cdem (HDF5) files", [*H5_SOURCES, "common/state.c", "common/runlock.c",
                           "common/xdmf.c", "common/outfile.c"],
     "The file is not a cdem file, is damaged (a checksum failed: copy it again or re-run) or "
     "truncated (cut short by a full disk or an interrupted copy), of another format version "
     "(re-run with this cdem-run), or the increment/dataset asked for does not exist "
     "(`cdem-strain info RUN.h5` lists the increments). A run killed while writing keeps its "
     "complete increments (`cdem-run --resume RUN.h5` continues it; cdem-strain reads it as "
     "it is, other HDF5 tools after `h5clear -s RUN.h5`). \"is being written by another "
     "process\" names the run writing the file: wait for it, stop it or write elsewhere. An "
     "existing output is replaced only with `--force`, and a file that is not a cdem run file "
     "never."),
    ("cdem2D import", ["analysis/input/cdem2d.c"],
     "Fix the named file and line of the cdem2D folder: `x y radius layer` per line "
     "(modelresults_N.txt), `sxx syy sxy` per line and the same number of lines "
     "(modelforces_N.txt); docs/formats-text.md."),
    ("Analysis (compute, element, limits, strain, stress, axes)", [
      *(f for f in sources("analysis/cli/cmd_*.c") if f not in PICTURE_COMMANDS),
      *sources("analysis/measure/*.c"),
      *sources("analysis/export/*.c"), "common/grid.c"],
     "Use a quantity name from `cdem-strain quantities`, an increment from `cdem-strain info`; "
     "stress quantities need a run with `physics.calculate_stress = on`; mohr needs biaxial "
     "runs at two or more different confining pressures; repose needs a repose run."),
    ("Pictures, plots and GIFs", [
      *sources("analysis/draw/*.c"), *PICTURE_COMMANDS],
     "Check the output name's extension (.png, .pdf, .svg; .gif for --gif), that the output "
     "directory exists and is writable, the option values (sizes, colours #RRGGBB, zoom "
     "window, ranges MIN,MAX) and, for plot-series, the column names (`h5ls RUN.h5/series`)."),
]


def c_strings(args):
    """Concatenates the C string literals at the start of an argument."""
    return "".join(re.findall(r'"((?:[^"\\]|\\.)*)"', args))


def calls(text, token="CDEM_FAIL("):
    i = 0
    while True:
        i = text.find(token, i)
        if i < 0:
            return
        j, depth, in_str = i + len(token), 1, False
        while j < len(text) and depth:
            ch = text[j]
            if in_str:
                if ch == "\\":
                    j += 1
                elif ch == '"':
                    in_str = False
            elif ch == '"':
                in_str = True
            elif ch == "(":
                depth += 1
            elif ch == ")":
                depth -= 1
            j += 1
        yield i, text[i + len(token):j - 1]
        i = j


def split_args(s):
    out, depth, in_str, cur = [], 0, False, ""
    k = 0
    while k < len(s):
        ch = s[k]
        if in_str:
            cur += ch
            if ch == "\\":
                cur += s[k + 1]; k += 1
            elif ch == '"':
                in_str = False
        elif ch == '"':
            in_str = True; cur += ch
        elif ch in "([{":
            depth += 1; cur += ch
        elif ch in ")]}":
            depth -= 1; cur += ch
        elif ch == "," and depth == 0:
            out.append(cur.strip()); cur = ""
        else:
            cur += ch
        k += 1
    out.append(cur.strip())
    return out


def show(fmt):
    fmt = fmt.replace('\\"', '"').replace("\\n", " ").replace("\\t", " ")
    fmt = re.sub(r"%[-+ #0]*[0-9*]*(?:\.[0-9*]+)?(?:hh|h|ll|l|z|j|t)?[diouxXeEfgGcsp]", "<…>", fmt)
    return fmt.replace("%%", "%").replace("|", "\\|")


def main():
    files = sorted(glob.glob(os.path.join(ROOT, d, "*.c"))
                   for d in ("common", "common/h5", "solver", "solver/base", "solver/contact",
                             "solver/modes", "solver/step", "solver/packing", "solver/run",
                             "analysis", "analysis/cli",
                             "analysis/input", "analysis/measure", "analysis/draw",
                             "analysis/export"))
    files = [f for group in files for f in group]
    rows = {}
    for path in files:
        rel = os.path.relpath(path, ROOT)
        text = open(path, encoding="utf-8").read()
        for pos, args in calls(text):
            a = split_args(args)
            if len(a) < 3:
                continue
            line = text.count("\n", 0, pos) + 1
            code = a[1].replace("CDEM_ERR_", "").lower()
            fmt = c_strings(a[2])
            if not fmt:
                fmt = "(message built at run time: " + a[2] + ")"
            rows.setdefault(rel, []).append((line, code, show(fmt)))
        # parameter rules collected by cdem_params_validate and reported together
        for pos, args in calls(text, "cdem_rule_add("):
            fmt = c_strings(split_args(args)[1])
            if fmt:
                line = text.count("\n", 0, pos) + 1
                rows.setdefault(rel, []).append((line, "rule", show(fmt)))
    print("# Error messages of cdem-run and cdem-strain")
    print()
    print("Generated by `/usr/bin/python3 scripts/error_catalogue.py > docs/errors.md` from the")
    print("`CDEM_FAIL` calls in common/, solver/ and analysis/ and the parameter rules")
    print("(`cdem_rule_add`, kind \"rule\": reported together, one per line, after \"the")
    print("parameters cannot be used as they are:\"); do not edit by hand (`test_man` fails when")
    print("it is stale). `<…>` stands for a value filled in at run time (a file name, line, key,")
    print("value). The programs print")
    print("`cdem-run: <message>` or `cdem-strain: <message>` and exit with status 1 (2 for usage")
    print("errors). What to do for each group is in docs/guide.md, section Troubleshooting; the")
    print("group's advice is repeated here.")
    print()
    done = set()
    total = 0
    for title, srcs, fix in GROUPS + [("Other", sorted(rows), "See the message; it names what is wrong.")]:
        srcs = [s for s in srcs if s in rows and s not in done]
        if not srcs:
            continue
        print(f"## {title}")
        print()
        print(fix)
        print()
        print("| source | kind | message |")
        print("|---|---|---|")
        for s in srcs:
            done.add(s)
            for line, code, msg in rows[s]:
                print(f"| {s}:{line} | {code} | {msg} |")
                total += 1
        print()
    print(f"{total} messages.")


if __name__ == "__main__":
    main()
