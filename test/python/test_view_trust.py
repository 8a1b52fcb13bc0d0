"""The viewer's command and the chooser's names (issue 32, finding 10 and the class "The viewer"):
an unknown --model is refused before serving, symbolic links out of the served folder are neither
listed nor opened, "serving NAME at" names what is served, chosen models' names are file names; a
replay's trial file shows its recording (the scans read here, in the world frame, and the recorded BVC
rates), a recording given with a trial it does not belong to is refused, and the data API's errors name
the file and the true value (finding 4, the class "Messages that do not name where the fault is")."""
import json
import struct
import os
import signal
import subprocess
import urllib.error
import urllib.request

import h5py
import numpy as np
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


# ---- issue 32, finding 4: a replay's trial file shows its recording and its recorded rates ----

def blob(url):
    """GET a viewer reply: (status, header, arrays) for a blob, (status, json, None) otherwise."""
    try:
        body = urllib.request.urlopen(url, timeout=60).read()
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read()), None
    if body[:4] != b"BVC3":
        return 200, json.loads(body), None
    n = struct.unpack_from("<I", body, 4)[0]
    header = json.loads(body[8:8 + n])
    types = {"f32": "<f4", "f64": "<f8", "i32": "<i4", "u8": "u1"}
    arrays = {a["name"]: np.frombuffer(body, dtype=types[a["dtype"]], count=int(np.prod(a["shape"])),
                                       offset=8 + n + a["offset"]).reshape(a["shape"]) for a in header["arrays"]}
    return 200, header, arrays


def address(line):
    return line.split(" at ")[1].split()[0]


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    """A recording exported from a walk (KITTI scans: easy to read here) and its replay, made in
    the folder `work` (so the trial names the recording's files relative to it)."""
    work = tmp_path_factory.mktemp("replay")
    run_cli("export-scans", "--world", "cross", "--hours", 0.004, "--seed", 3, "--format", "kitti", "--out", "walk",
            check=True, cwd=work)
    run_cli("replay", "--scans", "walk", "--poses", "walk/poses.txt", "--model", "3d-0.2", "--out", "r.h5",
            check=True, cwd=work)
    return work


def scan_in_world(folder, i):
    """Scan i of an exported recording, read here: its points in the world frame (the 4x4 pose rows)."""
    xyz = np.fromfile(folder / f"{i:06d}.bin", dtype="<f4").reshape(-1, 4)[:, :3].astype(float)
    lines = (folder / "poses.txt").read_text().split("\n")
    rows = np.array([[float(v) for v in ln.replace(",", " ").split()] for ln in lines if ln.strip()]).reshape(-1, 4, 4)
    T = rows[i].copy()
    T[3] = [0, 0, 0, 1]
    return xyz @ T[:3, :3].T + T[:3, 3], T[:3, :3]


def test_a_replay_shows_its_scans_poses_and_recorded_rates(replay):
    # Served from another folder: the recording is found beside the trial file.
    proc = subprocess.Popen([CLI, "view", replay / "r.h5", "--port", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd="/")
    url = address(proc.stdout.readline())
    try:
        status, trial, _ = blob(url + "api/trial?path=r.h5")
        assert status == 200 and trial["world_problem"] == "", trial["world_problem"]
        rec = trial["recording"]
        assert rec["name"] == "walk" and rec["shown"] and rec["bvc_recorded"], rec
        assert rec["reading"] == {"min_range": 0.3, "max_range": 20.0, "selection": "upper_half",
                                  "slice_half_width": pytest.approx(np.radians(1))}, rec
        assert "drawn_sensor" not in trial, "a replay has no simulated scanner to draw"
        status, world, arrays = blob(url + "api/world?trial=r.h5")
        assert status == 200 and world["points"] > 1000, world  # the recording's map
        with h5py.File(replay / "r.h5") as f:
            bvc = f["samples/bvc_rates"][:]
            xs = f["samples/x"][:]
        for i in (0, len(xs) // 2, len(xs) - 1):
            status, step, a = blob(url + f"api/step?path=r.h5&i={i}")
            assert status == 200, step
            assert step["scan"] == i and step["bvc_source"] == "recorded"
            np.testing.assert_array_equal(a["bvc"], bvc[i], err_msg=f"sample {i}: not the recorded BVC rates")
            world_points, _ = scan_in_world(replay / "walk", i)
            np.testing.assert_allclose(a["points"], world_points, atol=1e-4)
            rel = world_points - np.asarray(step["sensor_origin"])
            r = np.linalg.norm(rel, axis=1)
            phi = np.arcsin(np.clip(rel[:, 2] / r, -1, 1))
            read = (r >= 0.3) & (r <= 20) & (rel[:, 2] >= 0)
            assert step["returns"] == int(read.sum()), (step["returns"], int(read.sum()))
            near = read & ((np.abs(phi) <= 0.04) | (np.abs(phi - 0.2) <= 0.04))  # 4 sigma_phi of 0 and 0.2 rad
            np.testing.assert_array_equal(a["kept"].astype(bool), near)
    finally:
        stop(proc)


def test_a_replay_whose_recording_is_not_found_says_so(replay, tmp_path):
    moved = tmp_path / "moved.h5"
    moved.write_bytes((replay / "r.h5").read_bytes())
    proc = subprocess.Popen([CLI, "view", moved, "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path)
    url = address(proc.stdout.readline())
    try:
        status, trial, _ = blob(url + "api/trial?path=moved.h5")
        assert status == 200
        problem = trial["world_problem"]
        assert "recording 'walk'" in problem and "--scans" in problem and "folder, not a file" not in problem, problem
        status, err, _ = blob(url + "api/world?trial=moved.h5")
        assert status == 422 and "recording 'walk'" in err["error"], err
    finally:
        stop(proc)
    # Given with --scans/--poses, it is used.
    proc = subprocess.Popen([CLI, "view", moved, "--scans", replay / "walk", "--poses", replay / "walk/poses.txt",
                             "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    url = address(proc.stdout.readline())
    try:
        status, trial, _ = blob(url + "api/trial?path=moved.h5")
        assert trial["world_problem"] == "" and trial["recording"]["shown"], trial["world_problem"]
        # The recording's own page computes the BVC rates from each scan as the replay did.
        with h5py.File(moved) as f:
            recorded = f["samples/bvc_rates"][:]
        for i in range(len(recorded)):
            status, scan, a = blob(url + f"api/scan?i={i}")
            np.testing.assert_allclose(a["bvc"], recorded[i], atol=1e-6, err_msg=f"scan {i}")
    finally:
        stop(proc)


def test_scans_given_with_a_trial_they_do_not_belong_to_are_refused(replay, tmp_path):
    other = tmp_path / "other"
    run_cli("export-scans", "--world", "cross", "--hours", 0.003, "--seed", 4, "--format", "kitti", "--out", other,
            check=True)
    p = run_cli("view", replay / "r.h5", "--scans", other, "--poses", other / "poses.txt", timeout=60)
    assert p.returncode == 2 and "r.h5" in p.stderr and "not those the trial replayed" in p.stderr, p.stderr
    run_cli("run", "--hours", 0.01, "--out", tmp_path / "sim.h5", check=True)
    p = run_cli("view", tmp_path / "sim.h5", "--scans", other, "--poses", other / "poses.txt", timeout=60)
    assert p.returncode == 2 and "sim.h5" in p.stderr and "did not replay a recording" in p.stderr, p.stderr


# ---- the viewer API's errors name the file and the true value ----

def test_api_errors_name_the_file_and_the_value(tmp_path):
    run_cli("run", "--hours", 0.01, "--out", tmp_path / "good.h5", check=True)
    broken = tmp_path / "broken.h5"
    broken.write_bytes((tmp_path / "good.h5").read_bytes())
    with h5py.File(broken, "r+") as f:
        f["metrics"].attrs["gridsize"] = np.int64(2 ** 40)
    proc, line = serve(tmp_path, "--port", 0)
    try:
        status, err, _ = blob(address(line) + "api/trial?path=broken.h5")
        assert status == 422, err
        assert "broken.h5" in err["error"] and "gridsize" in err["error"] and str(2 ** 40) in err["error"], err
        status, err, _ = blob(address(line) + "api/step?path=broken.h5&i=0")
        assert status == 422 and "broken.h5" in err["error"], err
    finally:
        stop(proc)
