#!/usr/bin/python3
"""Lists every message cdem-run and cdem-strain can print, from the sources: each call of
MESSAGE_CALLS below (CDEM_FAIL, H5FAIL, the parameter rules, the context put before a
message, the reasons a run file's value is refused, both programs' usage errors,
fprintf(stderr, ...)) in every C file of common/, solver/ and analysis/ and their
subfolders (at any depth), read by a C tokenizer (comments and character literals skipped). Writes
markdown to stdout (`make errors` writes docs/errors.md with it).

printf conversions are shown as <…> (a file name, a value, a line number...); a message
put together in a buffer by snprintf is shown with that snprintf's format."""
import glob
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")



def sources(pattern):
    """The source files matching pattern (relative to the repository root; `**` matches any
    depth of folders), sorted."""
    return sorted(os.path.relpath(p, ROOT)
                  for p in glob.glob(os.path.join(ROOT, pattern), recursive=True))


# Where the messages are: every .c (and .h) file of these folders, at any depth (the
# solver's and the analysis's layers are subfolders: solver/modes/, analysis/cli/, ...).
# tests/test_error_catalogue.c walks the same folders itself and fails when a file with a
# message has no row here.
TREES = ("common", "solver", "analysis")


def all_sources():
    """Every C source and header under TREES, relative to the root, sorted."""
    out = []
    for tree in TREES:
        for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, tree)):
            dirnames.sort()
            out += [os.path.relpath(os.path.join(dirpath, f), ROOT) for f in filenames
                    if f.endswith((".c", ".h"))]
    return sorted(out)


# The subcommands that draw (their messages are in the pictures group)
PICTURE_COMMANDS = ["analysis/cli/cmd_render.c", "analysis/cli/cmd_plot.c",
                    "analysis/cli/cmd_plot_series.c", "analysis/cli/cmd_plot_csv.c"]
PARAMETER_SOURCES = ["common/params.c", "solver/base/model.c", "solver/run/summary.c",
                     "solver/run/run_validate.c"]
FAULT_FILE_SOURCES = ["solver/modes/fault_file.c"]
CDEM2D_SOURCES = ["analysis/input/cdem2d.c", "analysis/input/cdem2d_h5.c"]

# A file is listed in the first group that names it (the solver's files not named before
# are all in "Boundary modes, assembly, salt and the run"); a file in none is in "Other".
GROUPS = [  # (title, source files, what to do)
    ("Parameter files and -s overrides", PARAMETER_SOURCES,
     "The message names the file, line, key and value and says what is allowed: correct that "
     "line (or the -s argument). `cdem-run --print-defaults` writes a valid file to start "
     "from; docs/parameters.md lists every key, range and rule between keys."),
    ("Fault vertex files (irregular-fault)", FAULT_FILE_SOURCES,
     "Fix the named line of the vertex file: two plain decimal numbers `x y` in metres per "
     "line; first point at (fault_location x width x unit_scaling, 0); every later point at "
     "lower x and higher y, every segment dipping at least 1 degree and at least half the "
     "smallest radius long, no point above twice the model's height. The path is relative to "
     "the directory cdem-run runs in."),
    ("Boundary modes, assembly, salt and the run", [
      f for f in sources("solver/**/*.c") if f not in PARAMETER_SOURCES + FAULT_FILE_SOURCES],
     "Combinations the mode cannot build are refused before the run (change the named key); "
     "a numeric blow-up (NaN/Inf, a non-finite position) means the time step is too large for "
     "the stiffness: keep `keep_constants = off` at small unit scaling or use the default "
     "constants; \"settling > displacement\" gives the display_interval and equilibration "
     "that work. \"out of memory\" names what was being allocated: a smaller model (larger "
     "radii, a narrower box) or a machine with more memory; `cdem-run --dry-run` states a "
     "model's size before it runs."),
    ("cdem (HDF5) files", [*sources("common/h5/*.c"), "common/state.c", "common/runlock.c",
                           "common/xdmf.c", "common/outfile.c", "common/snapshot.c"],
     "The file is not a cdem file, is damaged (a checksum failed: copy it again or re-run) or "
     "truncated (cut short by a full disk or an interrupted copy), of another format version "
     "(re-run with this cdem-run), or the increment/dataset asked for does not exist "
     "(`cdem-strain info RUN.h5` lists the increments). A run killed while writing keeps its "
     "complete increments (`cdem-run --resume RUN.h5` continues it; cdem-strain reads it as "
     "it is, other HDF5 tools after `h5clear -s RUN.h5`). \"is being written by another "
     "process\" names the run writing the file: wait for it, stop it or write elsewhere. An "
     "existing output is replaced only with `--force`, and a file that is not a cdem run file "
     "never. A cdem2D folder is read after `cdem-strain import-cdem2d FOLDER -o run.h5`."),
    ("cdem2D import", CDEM2D_SOURCES,
     "Fix the named file and line of the cdem2D folder: `x y radius layer` per line "
     "(modelresults_N.txt), `sxx syy sxy` per line and the same number of lines "
     "(modelforces_N.txt); docs/formats-text.md."),
    ("Analysis (compute, element, limits, strain, stress, axes)", [
      *(f for f in sources("analysis/cli/*.c") if f not in PICTURE_COMMANDS),
      *sources("analysis/measure/**/*.c"), *sources("analysis/export/**/*.c"),
      *(f for f in sources("analysis/input/**/*.c") if f not in CDEM2D_SOURCES),
      "common/grid.c"],
     "Use a quantity name from `cdem-strain quantities`, an increment from `cdem-strain info`; "
     "stress quantities need a run with `physics.calculate_stress = on`; mohr needs biaxial "
     "runs at two or more different confining pressures; repose needs a repose run."),
    ("Pictures, plots and GIFs", [
      *sources("analysis/draw/**/*.c"), *PICTURE_COMMANDS],
     "Check the output name's extension (.png, .pdf, .svg; .gif for --gif), that the output "
     "directory exists and is writable, the option values (sizes, colours #RRGGBB, zoom "
     "window, ranges MIN,MAX) and, for plot-series, the column names (`h5ls RUN.h5/series`)."),
]


# The calls that make a message, with the 1-based position of their format (or message)
# argument; tests/test_error_catalogue.c has the same table and fails when the sources hold
# a message source that is in neither (a printf-like function, a macro passing its
# arguments on to one of these, a function passing its parameter on as a message).
MESSAGE_CALLS = {
    "CDEM_FAIL": 3,          # common/cdem_error.h: the error record of every library call
    "cdem_error_set": 5,     # what CDEM_FAIL calls
    "H5FAIL": 3,             # common/h5/h5_internal.h: the run file's errors
    "h5i_fail_at": 5,        # what H5FAIL calls
    "cdem_error_prefix": 2,  # context put before a message on its way up
    "cdem_rule_add": 2,      # common/params.c and the solver: rules between keys, reported together
    "usage_error": 1,        # solver/main.c: cdem-run's usage errors
    "cdem_cmd_usage": 2,     # analysis/cli/cmd_support.c: cdem-strain's usage errors
    "usage": 1,              # analysis/cli/cmd_render.c: cdem_cmd_usage with render's help
    "fprintf": 2,            # only fprintf(stderr, ...)
    "say_why": 3,            # common/h5/h5_layout.c: why a value of a run file is refused
}
KIND = {"cdem_rule_add": "rule", "cdem_error_prefix": "context", "usage_error": "usage",
        "cdem_cmd_usage": "usage", "usage": "usage", "fprintf": "stderr", "say_why": "reason"}

TOKEN = re.compile(r"""
    (?P<nl>\n) | (?P<ws>[ \t\r\f\v]+) | (?P<lc>//[^\n]*) | (?P<bc>/\*.*?\*/)
  | (?P<pp>(?<![^\n])[ \t]*\#) | (?P<str>"(?:[^"\\\n]|\\.)*") | (?P<chr>'(?:[^'\\\n]|\\.)*')
  | (?P<id>[A-Za-z_]\w*) | (?P<num>\d[\w.]*) | (?P<punct>.)""", re.S | re.X)


def tokens(text):
    """The C tokens of text as (kind, text, line, brace depth before it): comments skipped,
    character literals one token (a '"' is no string), directives tokenized like code."""
    out, line, depth = [], 1, 0
    for m in TOKEN.finditer(text):
        kind, tok = m.lastgroup, m.group()
        if kind in ("str", "chr", "id", "num", "punct"):
            out.append((kind, tok[1:-1] if kind == "str" else tok, line, depth))
            if kind == "punct":
                depth += (tok == "{") - (tok == "}")
        line += tok.count("\n")
    return out


def split_args(toks, open_):
    """[(start, end)] token ranges of the arguments of the call whose '(' is toks[open_]."""
    args, depth, start = [], 0, open_ + 1
    for i in range(open_ + 1, len(toks)):
        kind, tok = toks[i][0], toks[i][1]
        if kind == "punct" and tok in "([{":
            depth += 1
        elif kind == "punct" and tok in ")]}":
            if depth == 0:
                if i > open_ + 1:
                    args.append((start, i))
                return args
            depth -= 1
        elif kind == "punct" and tok == "," and depth == 0:
            args.append((start, i))
            start = i + 1
    return args


def literals(toks, a, b):
    """The literal alternatives of the argument toks[a:b]: each run of adjacent string
    literals (a ternary has two)."""
    out, i = [], a
    while i < b:
        if toks[i][0] != "str":
            i += 1
            continue
        j = i
        while j < b and toks[j][0] == "str":
            j += 1
        out.append("".join(t[1] for t in toks[i:j]))
        i = j
    return out


def snprintf_format(toks, call, buf):
    """The literal alternatives of the snprintf(buf, ...) before toks[call] in the same
    function, or []."""
    i = call
    while i > 0 and toks[i][3] > 0:
        i -= 1
        if (toks[i][1] == "snprintf" and toks[i + 1][1] == "(" and toks[i + 2][1] == buf
                and toks[i + 2][0] == "id"):
            args = split_args(toks, i + 1)
            if len(args) >= 3:
                return literals(toks, *args[2])
    return []


def enclosing(toks, i):
    """(name, parameter names) of the function whose body holds toks[i]."""
    k = i
    while k > 0 and toks[k][3] > 0:
        k -= 1
    close = k
    while close > 0 and toks[close][1] != ")":
        close -= 1
    depth, open_ = 0, close
    while open_ > 0:
        depth += (toks[open_][1] == ")") - (toks[open_][1] == "(")
        if depth == 0:
            break
        open_ -= 1
    params = {toks[j][1] for j in range(open_ + 1, close)
              if toks[j][0] == "id" and toks[j + 1][1] in (",", ")")}
    return toks[open_ - 1][1], params


def messages(text):
    """(line, kind, format) of every message call of a C source."""
    toks = tokens(text)
    for i, (kind, tok, line, depth) in enumerate(toks[:-1]):
        if kind != "id" or tok not in MESSAGE_CALLS or toks[i + 1][1] != "(":
            continue
        if i > 0 and ((toks[i - 1][0] == "id" and toks[i - 1][1] != "return")
                      or toks[i - 1][1] == "*"):
            continue  # a declaration or definition, or a macro's own name
        fn, params = enclosing(toks, i) if depth > 0 else ("", set())
        if fn in MESSAGE_CALLS:
            continue  # the message function's own implementation
        args = split_args(toks, i + 1)
        pos = MESSAGE_CALLS[tok]
        if len(args) < pos:
            continue
        if tok == "fprintf" and [t[1] for t in toks[slice(*args[0])]] != ["stderr"]:
            continue
        what = KIND.get(tok)
        if what is None:
            code = re.sub(r"([=!<>]) =", r"\1=", " ".join(t[1] for t in toks[slice(*args[1])]))
            what = code.replace("CDEM_ERR_", "").lower()
        a, b = args[pos - 1]
        fmts = literals(toks, a, b)
        lone = toks[a][1] if b == a + 1 and toks[a][0] == "id" else None
        if not fmts and lone:
            if lone == "__VA_ARGS__" or lone in params:
                continue  # passes its caller's message on: the caller's call is listed
            fmts = snprintf_format(toks, i, lone)
        if fmts == ["%s"] and len(args) > pos:
            # "%s", buf: the message is what filled buf, when an snprintf did it here
            c, d = args[pos]
            if d == c + 1 and toks[c][0] == "id":
                fmts = snprintf_format(toks, i, toks[c][1]) or fmts
        if not fmts:
            fmts = ["(message built at run time: " + "".join(t[1] for t in toks[a:b]) + ")"]
        for fmt in fmts:
            yield line, what, fmt


def show(fmt):
    """The page's form of a format: escapes undone, each conversion as <…>, '|' escaped
    (tests/test_error_catalogue.c's page_form does the same)."""
    out, k = [], 0
    conv = re.compile(r"%[-+ #0]*[0-9*]*(?:\.[0-9*]*)?[hlzjt]*.?")
    while k < len(fmt):
        ch = fmt[k]
        if ch == "\\" and k + 1 < len(fmt):
            out.append(" " if fmt[k + 1] in "nt" else fmt[k + 1])
            k += 2
        elif fmt.startswith("%%", k):
            out.append("%")
            k += 2
        elif ch == "%":
            k = conv.match(fmt, k).end()
            out.append("<…>")
        elif ch == "|":
            out.append("\\|")
            k += 1
        else:
            out.append(ch)
            k += 1
    return "".join(out).rstrip(" ")


USAGE_TITLE = "Command lines (usage errors, exit status 2)"
USAGE_FIX = ("The program prints the message, its usage line and \"Try '... --help' for more "
             "information.\"; `cdem-run --help`, `cdem-strain COMMAND --help` and the man pages "
             "list every option.")
STDERR_TITLE = "Printed directly on standard error"
STDERR_FIX = ("cdem-run's refusals of its command line and output (exit status 1 or 2), and the "
              "notes and summaries cdem-strain's commands print beside their results (exit "
              "status 0): read the note; nothing failed unless the status says so.")


def main():
    rows, special = {}, {"usage": {}, "stderr": {}}
    for rel in all_sources():
        text = open(os.path.join(ROOT, rel), encoding="utf-8").read()
        for line, kind, fmt in messages(text):
            table = special[kind] if kind in special else rows
            table.setdefault(rel, []).append((line, kind, show(fmt)))
    for table in (rows, *special.values()):
        for found in table.values():
            found.sort()
    print("# Error messages of cdem-run and cdem-strain")
    print()
    print("Generated by `make errors` (`/usr/bin/python3 scripts/error_catalogue.py >")
    print("docs/errors.md`) from every message call in the C files of common/, solver/ and")
    print("analysis/ and their subfolders:")
    print("`CDEM_FAIL` and `H5FAIL` (the run file's errors; HDF5's own reason may follow in")
    print("\"(HDF5: …)\"), the context `cdem_error_prefix` puts before a message (kind")
    print("\"context\"), the parameter rules of `cdem_params_validate` (kind \"rule\": reported")
    print("together, one per line, after \"the parameters cannot be used as they are:\"), why a")
    print("value of a run file is refused (kind \"reason\": put into the reader's or the writer's")
    print("message, docs/format.md \"Physical bounds\"), the")
    print("usage errors of both programs and what they print directly on standard error. Do")
    print("not edit by hand: `test_man` fails when the page is stale and `test_error_catalogue`")
    print("when a message of the sources is missing from it. `<…>` stands for a value filled")
    print("in at run time (a file name, line, key, value). The programs print")
    print("`cdem-run: <message>` or `cdem-strain: <message>` and exit with status 1 (2 for usage")
    print("errors). What to do for each group is in docs/guide.md, section Troubleshooting; the")
    print("group's advice is repeated here.")
    print()
    done = set()
    total = 0
    groups = [(t, s, f, rows) for t, s, f in GROUPS]
    groups.append(("Other", sorted(rows), "See the message; it names what is wrong.", rows))
    groups.append((USAGE_TITLE, sorted(special["usage"]), USAGE_FIX, special["usage"]))
    groups.append((STDERR_TITLE, sorted(special["stderr"]), STDERR_FIX, special["stderr"]))
    for title, srcs, fix, table in groups:
        srcs = [s for s in srcs if s in table and (id(table), s) not in done]
        if not srcs:
            continue
        print(f"## {title}")
        print()
        print(fix)
        print()
        print("| source | kind | message |")
        print("|---|---|---|")
        for s in srcs:
            done.add((id(table), s))
            for line, code, msg in table[s]:
                print(f"| {s}:{line} | {code} | {msg} |")
                total += 1
        print()
    print(f"{total} messages.")


if __name__ == "__main__":
    main()
