"""Every ```python block of README.md and docs/*.md runs (issue 32: a block used `np` without
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
SHARED = SOURCE_DIR.parent / "shared" / "data"

SHORTER = {  # page -> [(text in the block, text the test runs)]
    "README.md": [("hours=1.0", "hours=0.01"),
                  ('run_trial(model="3d-3l", tilt_deg=60)',
                   'run_trial(model="3d-3l", tilt_deg=60, explore_hours=0.005, sample_hours=0.005)')],
    "python.md": [("explore_hours=4, sample_hours=4", "explore_hours=0.005, sample_hours=0.005")],
    "place-recognition.md": [("database=(0, 3000), queries=(3200, 4540)", "database=(0, 100), queries=(110, 200)")],
    "adaptive.md": [("explore_minutes=30", "explore_minutes=0.5"),
                    ('agent="flying", seed=7)', 'agent="flying", seed=7, explore_minutes=0.5)')],
}
# What a block needs that the user brings: made by the test (a bvc3d command line), or skipped.
SETUP = {
    "trial-files.md": [["run", "--world", "cross", "--tilt", "45", "--model", "3d-0.2", "--hours", "0.01",
                        "--out", "results/paper/cross-45_3d-0.2_seed0.h5", "--checkpoint-minutes", "0"]],
    "ros.md": [["export-scans", "--hours", "0.002", "--format", "ros1", "--out", "run.bag"]],
    "place-recognition.md": [["export-scans", "--hours", "0.02", "--out", "run"]],
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
