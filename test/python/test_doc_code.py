"""Every ```python and ```sh block of README.md and docs/*.md runs (issue 32: a block used `np` without
importing it and named robot keys that are not the defaults).

Each block runs in a fresh folder with the repository's configs/ beside it. Blocks that run for
minutes are shortened by the substitution table SHORTER (what the block writes -> what the test
runs: durations only, never what a call means). A block that reads files the user brings is given
them by SETUP (made here, e.g. a short trial or a bag exported by bvc3d) or by SHARED (the shared
data folder beside the repository); without them it is skipped, with the reason.
"""
import os
import pathlib
import subprocess
import sys

import pytest

from conftest import CLI, SOURCE_DIR

PAGES = [SOURCE_DIR / "README.md", *sorted((SOURCE_DIR / "docs").glob("*.md"))]
SHARED = pathlib.Path(os.environ.get("BVC3D_SHARED_DATA", SOURCE_DIR.parent / "shared" / "data"))

SHORTER = {  # page -> [(text in the block, text the test runs)]
    "README.md": [("hours=1.0", "hours=0.01"),
                  ('run_trial(model="3d-3l", tilt_deg=60)',
                   'run_trial(model="3d-3l", tilt_deg=60, explore_hours=0.005, sample_hours=0.005)')],
    "python.md": [("explore_hours=4, sample_hours=4", "explore_hours=0.005, sample_hours=0.005")],
    "place-recognition.md": [("database=(0, 3000), queries=(3200, 4540)", "database=(0, 60), queries=(80, 106)")],
    "adaptive.md": [("explore_minutes=30", "explore_minutes=0.5"),
                    ('agent="flying", seed=7)', 'agent="flying", seed=7, explore_minutes=0.5)')],
}
# What a block needs that the user brings: made by the test (a bvc3d command line), or skipped.
SETUP = {
    "trial-files.md": [["run", "--world", "cross", "--tilt", "45", "--model", "3d-0.2", "--hours", "0.01",
                        "--out", "results/paper/cross-45_3d-0.2_seed0.h5", "--checkpoint-minutes", "0"]],
    "ros.md": [["export-scans", "--hours", "0.002", "--format", "ros1", "--out", "run.bag"]],
    "place-recognition.md": [["export-scans", "--hours", "0.01", "--format", "pcd", "--out", "run/"]],
}
NEEDS = {  # page -> (what the block reads, where it can come from) for blocks the test cannot feed
    "adaptive.md": "a recording in hall/ (the user's own)",
    "recordings.md": "a recording in hall/ and a point-map world (the user's own)",
    "viewer.md": "a running `bvc3d view` server",
}
GAZEBO = SHARED / "gazebo" / "aws-robomaker-hospital-world"


def python_blocks():
    out = []
    for page in PAGES:
        lines = page.read_text().splitlines(keepends=True)
        i = 0
        while i < len(lines):
            if lines[i].strip() == "```python":
                end = next(j for j in range(i + 1, len(lines)) if lines[j].strip() == "```")
                out.append((page, i + 2, "".join(lines[i + 1:end])))
                i = end
            i += 1
    return out


BLOCKS = python_blocks()


def test_there_are_python_blocks():
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("page,line,code", BLOCKS, ids=[f"{b[0].name}:{b[1]}" for b in BLOCKS])
def test_python_block_runs(page, line, code, tmp_path):
    for old, new in SHORTER.get(page.name, []):
        assert old in code, f"{page.name}: the substitution {old!r} no longer matches the block"
        code = code.replace(old, new)
    if page.name in NEEDS:
        pytest.skip(f"{page.name}:{line} needs {NEEDS[page.name]}")
    if page.name == "buildings.md":
        if not GAZEBO.is_dir():
            pytest.skip(f"{page.name}:{line} needs the hospital world, not in {GAZEBO}")
        (tmp_path / "worlds").symlink_to(GAZEBO / "worlds")
        (tmp_path / "models").symlink_to(GAZEBO / "models")
    (tmp_path / "configs").symlink_to(SOURCE_DIR / "configs")
    for argv in SETUP.get(page.name, []):
        proc = subprocess.run([CLI, *argv], cwd=tmp_path, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
    env = dict(os.environ, MPLBACKEND="Agg")
    paths = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    env["PYTHONPATH"] = os.pathsep.join(str(pathlib.Path(p).resolve()) for p in paths)  # the block runs elsewhere
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, env=env,
                          timeout=900)
    assert proc.returncode == 0, f"{page.name}:{line} fails:\n{proc.stderr[-3000:]}"


# ---------------------------------------------------------------------------------------------------
# Shell blocks: every `bvc3d ...` command line of a ```sh or ```bash block runs, in page order, in one
# folder per block (what an earlier line writes, a later one reads). Durations are shortened by
# shortened() (hours, seeds, minutes: never what a command means); lines that are not bvc3d commands
# (builds, installs, MPI launchers, ROS tools) and commands that need what the test cannot give (a
# user's recording, a running server, a shared data set that is not there) are skipped with the reason.
import glob
import re
import shlex

SH_SETUP = {  # page -> bvc3d command lines run first in the block's folder (what the block reads)
    "README.md": [["paper", "--models", "2d", "--tilts", "0", "--hours", "0.002", "--no-figures",
                   "--out", "results/paper"],
                  ["export-scans", "--hours", "0.01", "--format", "pcd", "--out", "run/"],
                  ["export-scans", "--hours", "0.002", "--format", "ros1", "--out", "run.bag"]],
    "ros.md": [["export-scans", "--hours", "0.002", "--format", "ros1", "--out", "run.bag"]],
    "place-recognition.md": [["export-scans", "--hours", "0.01", "--format", "pcd", "--out", "run/"]],
}
# A command that reads a file or folder named here is skipped with the reason, unless the file exists.
SH_NEEDS = {
    "hall/": "a LiDAR recording in hall/ (the shared data's hall-lidar, not found)",
    "hall.yaml": "a recording's chosen model (the user's own)",
    "hospital.yaml": "the page's Gazebo hospital world YAML over the shared Gazebo models",
    "worlds/hospital.world": f"the AWS hospital world (not in {GAZEBO})",
    "house.world": "a Gazebo world file (the user's own)",
    "my-building.yaml": "the user's own building",
    "room.yaml": "the user's own world",
    "track.csv": "the user's own track",
    "handheld.csv": "the user's own hand-held path",
    "day1": "two recordings of the user's (day1/, day2/)",
    "work/": "template trial files of the user's",
    "scans.txt": "the user's own scan list",
    "run.mcap": "an Ouster bag of the user's",
    "run_ros2/": "a ROS 2 bag of the user's",
    "learned.h5": "a replay with --learn of the user's recording",
    "trial.yaml": "the user's trial YAML (docs/experiments.md shows one)",
    "chosen.yaml": "the model choose-elevations wrote on the user's building",
    "FILE": "a placeholder for the user's sweep file",
    "/nfs/": "a cluster's shared file system",
    "$SCRATCH": "a cluster's scratch space",
    "build-ref/": "a reference build of another revision (scripts/bench)",
}
SH_SHORTER = {  # page -> [(text in the block, text the test runs)]: ranges of scans the short recording has
    "place-recognition.md": [("--database 0:3000 --queries 3200:4540", "--database 0:60 --queries 80:106")],
}
SH_PREFIXES = ("/usr/bin/time -v ", "srun ")  # measuring and launching wrappers: the bvc3d command runs alone
SH_SERVERS = ("view",)  # `bvc3d view` serves a page until stopped: run only with --export


def shortened(argv):
    """The command with its durations cut to seconds of simulated time."""
    cmd, out = argv[0], list(argv)

    def set_option(name, value):
        if name in out:
            out[out.index(name) + 1] = value
        else:
            out.extend([name, value])

    durations = {"paper": ["--hours"], "flight": ["--hours"], "sweep": ["--hours"], "walk": ["--hours"],
                 "export-scans": [], "run": ["--hours"]}
    if cmd in durations:
        for flag in ("--hours", "--explore-hours", "--sample-hours"):
            if flag in out:
                out[out.index(flag) + 1] = "0.002"
        if not {"--hours", "--explore-hours", "--sample-hours", "--trajectory", "--config"} & set(out):
            for flag in durations[cmd]:
                set_option(flag, "0.002")
    if cmd in ("paper", "flight", "navigate") and "--seeds" in out:
        out[out.index("--seeds") + 1] = "1"
    if cmd in ("paper", "flight", "sweep"):
        out.append("--no-figures")
    if cmd == "choose-elevations":
        set_option("--explore-minutes", "0.3")
    if cmd == "navigate":
        set_option("--max-learn-hours", "0.01")
    return out


def shell_blocks():
    out = []
    for page in PAGES:
        lines = page.read_text().splitlines()
        i = 0
        while i < len(lines):
            if lines[i].strip() in ("```sh", "```bash"):
                end = next(j for j in range(i + 1, len(lines)) if lines[j].strip() == "```")
                out.append((page, i + 2, "\n".join(lines[i + 1:end])))
                i = end
            i += 1
    return out


def command_lines(text):
    """Logical lines (continuations joined) as argument lists, comments dropped, the block's shell variables
    (`P="..."`) expanded, wrappers (SH_PREFIXES, `mpirun ...`) dropped; heredoc bodies skipped."""
    text = text.replace("\\\n", " ")
    lines, heredoc, variables = [], None, {}
    for line in text.splitlines():
        if heredoc:
            heredoc = None if line.strip() == heredoc else heredoc
            continue
        if m := re.search(r"<<\s*'?(\w+)'?", line):
            heredoc = m.group(1)
        if m := re.fullmatch(r"(\w+)=\"([^\"]*)\"", line.strip()):
            variables[m.group(1)] = m.group(2)
            continue
        for name, value in variables.items():
            line = line.replace("$" + name, value)
        for prefix in SH_PREFIXES:
            line = line.replace(prefix, "")
        line = re.sub(r"^mpirun .*?(?=build/bvc3d )", "", line)
        argv = shlex.split(line, comments=True)
        if argv:
            lines.append(argv)
    return lines


SH_BLOCKS = shell_blocks()


def test_there_are_shell_blocks():
    assert len(SH_BLOCKS) >= 20
    for page, subs in SH_SHORTER.items():
        for old, _ in subs:
            assert any(b[0].name == page and old in b[2] for b in SH_BLOCKS), f"{page}: {old!r} matches no block"


@pytest.mark.parametrize("page,line,text", SH_BLOCKS, ids=[f"{b[0].name}:{b[1]}" for b in SH_BLOCKS])
def test_shell_block_runs(page, line, text, tmp_path):
    (tmp_path / "configs").symlink_to(SOURCE_DIR / "configs")
    if (SHARED / "hall-lidar").is_dir():  # the docs' hall/: a real recording, 60 scans with poses.csv
        (tmp_path / "hall").symlink_to(SHARED / "hall-lidar")
    if GAZEBO.is_dir():  # the README's worlds/hospital.world: the AWS hospital's folder, as a user has it
        (tmp_path / "worlds").symlink_to(GAZEBO / "worlds")
        (tmp_path / "models").symlink_to(GAZEBO / "models")
    for argv in SH_SETUP.get(page.name, []):
        proc = subprocess.run([CLI, *argv], cwd=tmp_path, capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
    for old, new in SH_SHORTER.get(page.name, []):
        text = text.replace(old, new)
    ran, skipped = 0, []
    for argv in command_lines(text):
        words = [w for w in argv if "=" not in w or w.startswith("-")]  # VAR=value prefixes dropped
        if not words or words[0] not in ("build/bvc3d", "bvc3d"):
            skipped.append(f"{' '.join(argv)[:60]}: not a bvc3d command")
            continue
        args = words[1:]
        if args and args[0] in SH_SERVERS and "--export" not in args:
            skipped.append(f"bvc3d {' '.join(args)[:50]}: starts a server")
            continue
        need = next((why for name, why in SH_NEEDS.items()
                     if any(name in a for a in args) and not (tmp_path / name).exists()), None)
        if need:
            skipped.append(f"bvc3d {' '.join(args)[:50]}: needs {need}")
            continue
        expanded = []
        args = [re.sub(r"^/tmp/", "tmp/", a) for a in args]  # outputs stay in the test's folder
        for a in (shortened(args) if args and args[0] != "--help" else args):
            matches = sorted(glob.glob(str(tmp_path / a))) if any(c in a for c in "*?[") else []
            expanded += [str(pathlib.Path(m).relative_to(tmp_path)) for m in matches] or [a]
        proc = subprocess.run([CLI, *expanded], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                              env=dict(os.environ, MPLBACKEND="Agg"))
        assert proc.returncode == 0, f"{page.name}:{line}: bvc3d {' '.join(expanded)} fails:\n{proc.stderr[-2000:]}"
        ran += 1
    if not ran:
        pytest.skip(f"{page.name}:{line}: " + "; ".join(skipped))
