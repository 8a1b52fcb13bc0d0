#!/usr/bin/env python3
"""Runs the bad-input corpus: every case must be refused cleanly.

    /usr/bin/python3 test/bad_inputs/run.py --cli build/bvc3d [--reader build/bvc3d_read_recording]
        [--pythonpath build/python] [--jobs 2] [--only WORD] [--list]

A case is one input file or one command (README.md in this folder says how they are written). For
each, the runner checks:

* the program exits with status 2 (Python calls: raise ValueError, bvc3d.InputError included);
* the message is one error line and names the file (its name) and every `expect` text (a key such
  as `objects[0].box.size`, a field, a flag);
* nothing crashed: no "internal error", no sanitizer report, no Python traceback from the report;
* no output was written: the command runs in an empty folder, which must still be empty after;
* it ends within the time limit.

Under AddressSanitizer/UBSan builds (--sanitized) the limit is larger; Python cases need
--pythonpath (they are skipped without it).
"""
import argparse
import concurrent.futures
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
SOURCE = HERE.parents[1]
sys.path.insert(0, str(HERE))


class Case:
    def __init__(self, name, argv=None, expect=(), file=None, python=None, names_file=True):
        self.name = name          # what the report calls it
        self.argv = argv          # the command after `bvc3d` ({} = the case's file, {tmp} = an output path)
        self.expect = list(expect)
        self.file = file          # the input file the message must name
        self.python = python      # a Python expression (instead of argv)
        self.names_file = names_file


def header(path):
    """`# cmd:` and `# expect:` lines at the top of a text case file."""
    cmd, expect, names = None, [], True
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()[:12]
    except OSError:
        return None
    for line in lines:
        m = re.match(r"\s*#\s*(cmd|expect|names-file):\s*(.*)$", line)
        if not m:
            continue
        if m.group(1) == "cmd":
            cmd = m.group(2).strip()
        elif m.group(1) == "expect":
            expect += [e.strip() for e in m.group(2).split(";") if e.strip()]
        else:
            names = m.group(2).strip() != "no"
    return (cmd, expect, names) if cmd else None


def manifest(folder):
    """cases.txt: `FILE | COMMAND | EXPECT; EXPECT` for files that cannot hold a comment."""
    out = {}
    path = folder / "cases.txt"
    if path.exists():
        for line in path.read_text().splitlines():
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            parts = [p.strip() for p in line.split("|")]
            if len(parts) != 3:
                raise SystemExit(f"{path}: expected 'FILE | COMMAND | EXPECT', got {line!r}")
            out[parts[0]] = (parts[1], [e.strip() for e in parts[2].split(";") if e.strip()], True)
    return out


def file_cases():
    cases = []
    for folder in sorted(p for p in HERE.iterdir() if p.is_dir() and p.name not in ("__pycache__", "data")):
        listed = manifest(folder)
        for path in sorted(folder.iterdir()):
            if path.name == "cases.txt" or path.is_dir() and path.name not in listed:
                continue
            spec = listed.get(path.name) or (header(path) if path.suffix in (".yaml", ".obj", ".txt", ".csv",
                                                                             ".ply", ".pcd") else None)
            if spec is None:
                continue  # a helper file other cases refer to
            cmd, expect, names = spec
            cases.append(Case(f"{folder.name}/{path.name}", shlex.split(cmd), expect, path, names_file=names))
    return cases


def line_cases(filename, kind):
    """cli.txt / python.txt: one case per line, `CASE  # expect: A; B`."""
    cases = []
    for n, line in enumerate((HERE / filename).read_text().splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        body, _, expect = line.partition("# expect:")
        body = body.strip()
        expect = [e.strip() for e in expect.split(";") if e.strip()]
        if kind == "cli":
            cases.append(Case(f"{filename}:{n} {body}", shlex.split(body), expect, names_file=False))
        else:
            cases.append(Case(f"{filename}:{n} {body}", python=body, expect=expect, names_file=False))
    return cases


def substitute(arg, case, tmp):
    arg = arg.replace("{tmp}", str(tmp)).replace("{corpus}", str(HERE)).replace("{source}", str(SOURCE))
    if case.file is not None:
        arg = arg.replace("{dir}", str(case.file.parent)).replace("{}", str(case.file))
    return arg


CRASH_SIGNS = ("internal error", "AddressSanitizer", "LeakSanitizer", "runtime error:", "Traceback", "Segmentation",
               "core dumped", "terminate called", "ai_assert")


def check_message(case, text):
    problems = []
    lines = [l for l in text.splitlines() if l.strip()]
    errors = [l for l in lines if l.startswith("bvc3d: error:") or l.startswith("bvc3d: usage error:")]
    if len(errors) != 1:
        problems.append(f"expected one 'bvc3d: error:' line, got {len(errors)}")
    for sign in CRASH_SIGNS:
        if sign in text:
            problems.append(f"a crash sign: {sign!r}")
    message = errors[0] if errors else text
    if case.names_file and case.file is not None and case.file.name not in message:
        problems.append(f"the message does not name the file {case.file.name!r}")
    for e in case.expect:
        if e not in message:
            problems.append(f"the message lacks {e!r}")
    return problems


def snapshot(folder):
    """Every file under `folder` with its size and modification time."""
    return {str(p): (p.stat().st_size, p.stat().st_mtime_ns) for p in folder.rglob("*") if p.is_file()}


def run_cli_case(case, args, hdf5_dir):
    before = snapshot(case.file.parent) if case.file is not None else {}
    with tempfile.TemporaryDirectory(prefix="bvc3d-bad-") as work:
        work = pathlib.Path(work)
        cwd = work / "cwd"
        cwd.mkdir()
        tmp = work / "out"  # an output path that must not come into being
        argv = [args.cli] + [substitute(a, case, tmp).replace("{h5}", str(hdf5_dir)) for a in case.argv]
        if case.argv and case.argv[0] == "read-recording":
            argv = [args.reader] + argv[2:]
        start = time.monotonic()
        try:
            proc = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, errors="replace",
                                  timeout=args.timeout, env=args.env)
        except subprocess.TimeoutExpired:
            return [f"took more than {args.timeout} s"], ""
        took = time.monotonic() - start
        problems = []
        if proc.returncode != 2:
            problems.append(f"exit status {proc.returncode}, not 2")
        problems += check_message(case, proc.stderr)
        left = sorted(str(p.relative_to(work)) for p in work.rglob("*") if p != cwd)
        if left or tmp.exists():
            problems.append(f"output was written: {left}")
        if case.file is not None and snapshot(case.file.parent) != before:
            problems.append(f"files beside the input changed: {sorted(set(snapshot(case.file.parent)) ^ set(before))}")
        return problems, f"{took:.2f} s: {proc.stderr.strip()}"


PY_RUNNER = r'''
import sys, json, traceback, signal
import numpy as np
import bvc3d
from bvc3d import analysis
corpus = sys.argv[1]
results = []
for line in sys.stdin.read().split("\n\x00\n"):
    if not line.strip():
        continue
    expr = line.replace("{corpus}", corpus)
    try:
        eval(expr, {"bvc3d": bvc3d, "analysis": analysis, "np": np, "corpus": corpus})
        results.append(["no exception", ""])
    except ValueError as e:
        results.append(["ValueError", str(e)])
    except BaseException as e:
        results.append([type(e).__name__, str(e)])
print(json.dumps(results))
'''


def run_python_cases(cases, args):
    import json
    env = dict(args.env)
    env["PYTHONPATH"] = args.pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory(prefix="bvc3d-bad-py-") as cwd:
        proc = subprocess.run([args.python, "-c", PY_RUNNER, str(HERE)], input="\n\x00\n".join(c.python for c in cases),
                              cwd=cwd, capture_output=True, text=True, timeout=args.timeout * 4, env=env)
        left = os.listdir(cwd)
    if proc.returncode != 0:
        return [(c, [f"the Python runner failed: {proc.stderr[-2000:]}"], "") for c in cases]
    out = []
    for case, (kind, message) in zip(cases, json.loads(proc.stdout)):
        problems = []
        if kind != "ValueError":
            problems.append(f"raised {kind}, not ValueError")
        if not message.strip():
            problems.append("the message is empty")
        for e in case.expect:
            if e not in message:
                problems.append(f"the message lacks {e!r}")
        if left:
            problems.append(f"output was written: {left}")
        out.append((case, problems, f"{kind}: {message}"))
    return out


def make_hdf5_cases(args, folder):
    """Builds the bad trial files of hdf5_cases.py from one good trial file made by the CLI."""
    import hdf5_cases
    good = folder / "good.h5"
    proc = subprocess.run([args.cli, "run", "--hours", "0.02", "--seed", "1", "--out", str(good),
                           "--checkpoint-minutes", "0"],
                          capture_output=True, text=True, env=args.env, timeout=args.timeout * 4)
    if proc.returncode != 0:
        raise SystemExit(f"cannot make the good trial file: {proc.stderr}")
    cases = []
    for name, make, cmd, expect in hdf5_cases.cases():
        (folder / name).mkdir()
        path = folder / name / f"{name}.h5"
        shutil.copy(good, path)
        make(path)
        argv = [a.replace("{}", str(path)).replace("{dir}", str(path.parent)) for a in shlex.split(cmd)]
        cases.append(Case(f"hdf5/{name}", argv, expect, path))
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True)
    parser.add_argument("--reader", help="the recording-reader harness (bvc3d_read_recording)")
    parser.add_argument("--pythonpath", help="build/python, for the Python cases")
    parser.add_argument("--python", default="/usr/bin/python3")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=30)
    parser.add_argument("--sanitized", action="store_true", help="the CLI is built with sanitizers: allow more time")
    parser.add_argument("--only", help="run only cases whose name contains this")
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--verbose", action="store_true")
    args = parser.parse_args()
    args.cli = os.path.abspath(args.cli)
    args.reader = args.reader and os.path.abspath(args.reader)
    args.pythonpath = args.pythonpath and os.path.abspath(args.pythonpath)
    if args.sanitized:
        args.timeout *= 4
    args.env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:exitcode=99",
                    UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=99")
    args.env["BVC3D_PYTHONPATH"] = args.pythonpath or ""

    cases = file_cases() + line_cases("cli.txt", "cli")
    py_cases = line_cases("python.txt", "python")
    with tempfile.TemporaryDirectory(prefix="bvc3d-bad-h5-") as h5_dir:
        h5_dir = pathlib.Path(h5_dir)
        cases += make_hdf5_cases(args, h5_dir)
        if not args.reader:
            cases = [c for c in cases if c.argv[0] != "read-recording"]
        if args.only:
            cases = [c for c in cases if args.only in c.name]
            py_cases = [c for c in py_cases if args.only in c.name]
        if args.list:
            for c in cases + py_cases:
                print(c.name)
            print(f"{len(cases) + len(py_cases)} cases")
            return 0
        start = time.monotonic()
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            results = list(pool.map(lambda c: (c, *run_cli_case(c, args, h5_dir)), cases))
        if args.pythonpath and py_cases:
            results += run_python_cases(py_cases, args)
        elif py_cases:
            print(f"skipping {len(py_cases)} Python cases (no --pythonpath)")
    failed = [(c, p, d) for c, p, d in results if p]
    for c, p, d in results:
        if p or args.verbose:
            print(f"{'FAIL' if p else 'ok  '} {c.name}\n      {d[:400]}")
            for problem in p:
                print(f"      - {problem}")
    print(f"{len(results) - len(failed)}/{len(results)} bad inputs refused cleanly in {time.monotonic() - start:.0f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
