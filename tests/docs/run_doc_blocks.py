#!/usr/bin/python3
"""Runs the fenced code blocks of the user documentation (issue 18: docs/guide.md's h5py
example used the old layout and failed with a KeyError; nobody ran it).

usage: run_doc_blocks.py [--all] BUILD_DIR [DOC.md ...]
    (default documents: README.md docs/guide.md docs/format.md; run from the repository root)

Every ```sh, ```python and ```make block is run, in order, in one scratch folder per
document (so a later block sees the files of an earlier one), with build/ pointing to
BUILD_DIR, cdem-run and cdem-strain on PATH, EDITOR=true, REPO = the repository root and
DOCTEST_RUN = a finished run file (a small model normally, the default model with --all).
sh blocks run with `sh -e`, python blocks with /usr/bin/python3; a block fails when a
command fails. Other fences (diagrams, XML) are not code and are left alone.

An HTML comment right before a fence (invisible in the rendered page) says how to treat
the block, one `key: value` per line:

    <!-- doc-test
    mode: validate (why)     run only with --all (make validate): long simulations.
                             Default mode: run (make test and make validate).
    mode: skip (why)         never run; the reason is required and printed
    setup: COMMAND           shell run before the block (repeatable)
    file: NAME               write the block to NAME instead of running it
    run: COMMAND             run this instead of the block (e.g. for a file: block)
    test: COMMAND            without --all, run this quick check instead of skipping a
                             validate block
    -->

Prints one line per block and "doc blocks: N ran, N quick checks, N validate-only,
N skipped, N failed"; exit status 1 when any failed.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

DOCS = ["README.md", "docs/guide.md", "docs/format.md"]
CODE = {"sh", "python", "make"}
KEYS = {"mode", "setup", "file", "run", "test"}


def blocks(path):
    """(line, language, text, options) of every fenced block of path."""
    lines = open(path, encoding="utf-8").read().split("\n")
    out, i = [], 0
    while i < len(lines):
        m = re.match(r"^```(\w*)\s*$", lines[i])
        if not m:
            i += 1
            continue
        lang, start = m.group(1), i
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        text = "\n".join(lines[i + 1:j]) + "\n"
        opts = marker(lines, start, path)
        out.append((start + 1, lang, text, opts))
        i = j + 1
    return out


def marker(lines, fence, path):
    """The doc-test comment ending on the line before the fence, parsed."""
    k = fence - 1
    if k < 0 or not lines[k].rstrip().endswith("-->"):
        return {}
    first = k
    while first >= 0 and "<!-- doc-test" not in lines[first]:
        if "<!--" in lines[first]:
            return {}
        first -= 1
    if first < 0:
        return {}
    opts = {"setup": []}
    for line in lines[first + 1:k]:
        if not line.strip():
            continue
        key, _, value = line.strip().partition(":")
        key, value = key.strip(), value.strip()
        if key not in KEYS:
            raise SystemExit(f"{path}:{first + 1}: doc-test marker: unknown key '{key}'")
        if key == "setup":
            opts["setup"].append(value)
        else:
            opts[key] = value
    mode = opts.get("mode", "run")
    word = mode.split(" ", 1)[0]
    if word not in ("run", "validate", "skip"):
        raise SystemExit(f"{path}:{first + 1}: doc-test mode must be run, validate or skip")
    if word in ("validate", "skip") and not re.search(r"\(.+\)", mode):
        raise SystemExit(f"{path}:{first + 1}: doc-test mode {word} needs a (reason)")
    return opts


def sandbox_for(repo, build):
    """A scratch copy of the repository's sources (no build output), build/ -> BUILD."""
    box = tempfile.mkdtemp(prefix="docblocks_", dir=os.environ.get("CDEM_TEST_TMP"))
    skip = {".git", "build", "build-asan", "build-fuzz", "out"}
    for name in os.listdir(repo):
        if name in skip or name.startswith("."):
            continue
        src = os.path.join(repo, name)
        if os.path.isdir(src):
            shutil.copytree(src, os.path.join(box, name), symlinks=True,
                            ignore=shutil.ignore_patterns("*.h5", "*.xmf"))
        else:
            shutil.copy2(src, box)
    os.symlink(build, os.path.join(box, "build"))
    return box


def shell(cmd, cwd, env, timeout):
    t = time.time()
    p = subprocess.run(["sh", "-e", "-c", cmd], cwd=cwd, env=env, capture_output=True,
                       text=True, timeout=timeout)
    return p.returncode, p.stdout + p.stderr, time.time() - t


def make_run_file(build, full, env):
    """The run file the examples read: the default model with --all, else a small one."""
    folder = tempfile.mkdtemp(prefix="docrun_", dir=os.environ.get("CDEM_TEST_TMP"))
    path = os.path.join(folder, "run.h5")
    cmd = [os.path.join(build, "cdem-run"), "-q", "-o", path]
    if not full:
        cmd += ["-s", "assembly.height=2.5", "-s", "time.equilibration=100",
                "-s", "time.runtime=150", "-s", "time.display_interval=10"]
    subprocess.run(cmd, check=True, env=env, timeout=900)
    return path


def main(argv):
    full = "--all" in argv
    args = [a for a in argv[1:] if a != "--all"]
    if not args:
        sys.exit(__doc__)
    repo = os.getcwd()
    build = os.path.abspath(args[0])
    docs = args[1:] or DOCS
    env = dict(os.environ)
    bindir = tempfile.mkdtemp(prefix="docbin_", dir=os.environ.get("CDEM_TEST_TMP"))
    for prog in ("cdem-run", "cdem-strain"):
        os.symlink(os.path.join(build, prog), os.path.join(bindir, prog))
    env.update(PATH=bindir + os.pathsep + env.get("PATH", ""), EDITOR="true", REPO=repo,
               OMP_NUM_THREADS=env.get("OMP_NUM_THREADS", "1"))
    env["DOCTEST_RUN"] = make_run_file(build, full, env)
    timeout = 1800 if full else 300
    counts = {"ran": 0, "quick": 0, "validate": 0, "skipped": 0, "failed": 0}
    folders = [bindir, os.path.dirname(env["DOCTEST_RUN"])]
    for doc in docs:
        box = None
        for line, lang, text, opts in blocks(doc):
            if lang not in CODE:
                continue
            where = f"{doc}:{line} ({lang})"
            mode = opts.get("mode", "run")
            word = mode.split(" ", 1)[0]
            if word == "skip":
                counts["skipped"] += 1
                print(f"{where}: skipped {mode[4:].strip()}")
                continue
            quick = word == "validate" and not full
            if quick and "test" not in opts:
                counts["validate"] += 1
                print(f"{where}: make validate only {mode[8:].strip()}")
                continue
            if box is None:
                box = sandbox_for(repo, build)
                folders.append(box)
            steps = list(opts["setup"])
            if "file" in opts:
                with open(os.path.join(box, opts["file"]), "w") as f:
                    f.write(text)
            if quick:
                steps.append(opts["test"])
            elif "run" in opts:
                steps.append(opts["run"])
            elif "file" in opts:
                pass
            elif lang == "python":
                with open(os.path.join(box, "_block.py"), "w") as f:
                    f.write(text)
                steps.append("/usr/bin/python3 _block.py")
            elif lang == "sh":
                steps.append(text)
            else:
                raise SystemExit(f"{where}: a {lang} block needs file: and run: in its marker")
            rc, out, secs = 0, "", 0.0
            for step in steps:
                try:
                    rc, out, dt = shell(step, box, env, timeout)
                except subprocess.TimeoutExpired:
                    rc, out, dt = 124, f"timed out after {timeout} s", timeout
                secs += dt
                if rc != 0:
                    break
            if rc != 0:
                counts["failed"] += 1
                print(f"{where}: FAILED (exit {rc}) running:\n{step}\n--- output:\n{out[-3000:]}")
            elif quick:
                counts["quick"] += 1
                print(f"{where}: quick check passed ({secs:.1f} s); all of it in make validate")
            else:
                counts["ran"] += 1
                print(f"{where}: ran ({secs:.1f} s)")
    for folder in folders:
        shutil.rmtree(folder, ignore_errors=True)
    print("doc blocks: {ran} ran, {quick} quick checks, {validate} validate-only, {skipped} "
          "skipped, {failed} failed".format(**counts))
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
