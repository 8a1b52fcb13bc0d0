"""The viewer's command and the chooser's names (issue 32, finding 10 and the class "The viewer"):
an unknown --model is refused before serving, symbolic links out of the served folder are neither
listed nor opened, "serving NAME at" names what is served, chosen models' names are file names."""
import json
import os
import signal
import subprocess
import urllib.request

import pytest

import bvc3d
from conftest import CLI, run_cli


def serve(*args):
    """Starts `bvc3d view ARGS`; returns the process and its first line (the address)."""
    proc = subprocess.Popen([CLI, "view", *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    return proc, line


def stop(proc):
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=30)


def test_an_unknown_model_is_refused_before_serving(tmp_path):
    try:
        p = run_cli("view", "--model", "9d", "cross", timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail("bvc3d view --model 9d started serving")
    assert p.returncode == 2 and "unknown model '9d'" in p.stderr, p.stderr
    assert "serving" not in p.stdout


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    """A folder with one trial file and a symbolic link to a trial file outside it."""
    outside = tmp_path_factory.mktemp("outside")
    run_cli("run", "--hours", 0.01, "--out", outside / "secret.h5", check=True)
    folder = tmp_path_factory.mktemp("served")
    run_cli("run", "--hours", 0.01, "--out", folder / "a.h5", check=True)
    os.symlink(outside / "secret.h5", folder / "0-link.h5")  # sorts first: it would be opened first
    (folder / "w.yaml").symlink_to(bvc3d.__file__)  # a "world" out of the folder
    return folder


def test_links_out_of_the_folder_are_neither_listed_nor_opened(served):
    proc, line = serve(served, "--port", 0)
    try:
        assert f"serving {served} at http://127.0.0.1:" in line, line
        url = line.split(" at ")[1].split()[0]
        index = json.loads(urllib.request.urlopen(url + "api/index", timeout=30).read())
        assert index["trials"] == ["a.h5"], index
        assert index["open"] == ["a.h5"], index
        assert "w.yaml" not in index["worlds"], index
    finally:
        stop(proc)


def test_serving_a_recording_names_it(tmp_path):
    d = tmp_path / "walk"
    run_cli("export-scans", "--world", "cross", "--hours", 0.002, "--format", "pcd", "--out", d, check=True)
    proc, line = serve("--scans", d, "--poses", d / "poses.txt", "--port", 0)
    try:
        assert "serving recording 'walk' at http://127.0.0.1:" in line, line
    finally:
        stop(proc)


def test_chosen_models_are_named_without_brackets_or_spaces():
    c = bvc3d.choose_elevations(sets=[[0.0, 0.35]], explore_minutes=3, jobs=1)
    assert "name: adaptive-0_0.35" in c["model_yaml"], c["model_yaml"]
