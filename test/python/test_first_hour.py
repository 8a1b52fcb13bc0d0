"""What a robotics engineer and a neuroscientist hit in their first hour with the newer features (issue 43):
bags and scan folders in place recognition, Python signatures as documented, grid cells fed by path
integration, one page of the Python API, worlds given as paths or objects, the analysis at a building's
scale, figures of routes, and messages that say what is wrong without printing the input."""
import csv
import inspect
import math
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import bvc3d
from conftest import CLI, SOURCE_DIR, run_cli


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def error_line(proc):
    """The one `bvc3d: error:` line of a refused command (exit 2, nothing else gone wrong)."""
    assert proc.returncode == 2, proc.stderr
    lines = [l for l in proc.stderr.splitlines() if l.startswith("bvc3d: error:")]
    assert len(lines) == 1, proc.stderr
    return lines[0]


def plain_message(text):
    """A message that names what is wrong without printing an object's repr or an array."""
    assert "object at 0x" not in text and "array(" not in text and "Invoked with" not in text, text
    assert len(text) < 600, text


# ---- 1, 4: place recognition on bags and on scan folders ----------------------------------------------

@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """One walk of the cross arena exported three ways: a scan folder (with scans.txt and its times), a
    ROS 1 bag and an MCAP file."""
    d = tmp_path_factory.mktemp("exported")
    walk = ["--world", "cross", "--hours", "0.012", "--seed", "5", "--sensor", "horizontal"]
    run_cli("export-scans", *walk, "--format", "pcd-f8", "--out", d / "run", check=True)
    run_cli("export-scans", *walk, "--format", "ros1", "--out", d / "run.bag", check=True)
    run_cli("export-scans", *walk, "--format", "mcap", "--out", d / "run.mcap", check=True)
    return d


def place_recognition_cli(out, *source):
    proc = run_cli("place-recognition", *source, "--descriptors", "bvc:2d,scan-context", "--out", out,
                   "--no-figure", check=True)
    return proc.stdout, read_table(out / "summary.csv"), read_table(out / "queries.csv")


@pytest.mark.parametrize("bag", ["run.bag", "run.mcap"])
def test_place_recognition_reads_a_bag_as_its_help_says(exported, tmp_path, bag):
    """Finding 1: --bag with its topics is a recording, as in every other command that reads one; the
    bag's scans give what the same scans written as files give."""
    _, files, files_q = place_recognition_cli(tmp_path / "files", "--scans", exported / "run" / "scans.txt",
                                              "--poses", exported / "run" / "poses.txt")
    _, bags, bags_q = place_recognition_cli(tmp_path / "bag", "--bag", exported / bag, "--cloud-topic", "/points",
                                            "--pose-topic", "/odom")
    assert [(r["descriptor"], r["queries"], r["revisits"]) for r in bags] == \
        [(r["descriptor"], r["queries"], r["revisits"]) for r in files]
    assert [q["match"] for q in bags_q] == [q["match"] for q in files_q]
    np.testing.assert_allclose([float(q["distance"]) for q in bags_q], [float(q["distance"]) for q in files_q],
                               atol=1e-4)
    proc = run_cli("place-recognition", "--bag", exported / bag, "--cloud-topic", "/points", "--pose-topic", "/odom",
                   "--scans", exported / "run", "--descriptors", "scan-context", "--out", tmp_path / "both")
    assert "not both" in error_line(proc) and not (tmp_path / "both").exists()


def kitti_poses(exported, path):
    """The export's poses without their times: KITTI rows (the 3 x 4 matrix), as the KITTI conversion writes."""
    m = np.loadtxt(exported / "run" / "poses.txt", delimiter=",", usecols=range(4)).reshape(-1, 4, 4)
    np.savetxt(path, m[:, :3, :].reshape(-1, 12), fmt="%.17g")
    return path


def test_a_scan_folder_reads_its_times_file(exported, tmp_path):
    """Finding 4: a folder holding scans.txt (as export-scans and the KITTI conversion write it) is read
    with the list's times, as the list itself is: the same queries, the exclusion window in seconds."""
    poses = kitti_poses(exported, tmp_path / "poses.kitti")
    out_list, list_summary, list_q = place_recognition_cli(tmp_path / "list", "--scans",
                                                           exported / "run" / "scans.txt", "--poses", poses)
    out_dir, dir_summary, dir_q = place_recognition_cli(tmp_path / "dir", "--scans", exported / "run", "--poses",
                                                        poses)
    assert dir_q == list_q
    assert [{k: v for k, v in r.items() if not k.endswith("_s")} for r in dir_summary] == \
        [{k: v for k, v in r.items() if not k.endswith("_s")} for r in list_summary]
    assert all(r["timed"] == "1" for r in dir_summary)
    # Scans 0.288 s apart: the 30 s window (104 scans) leaves fewer queries than 50 scans would.
    t = np.array([float(r["t"]) for r in read_table(tmp_path / "dir" / "scans.csv")])
    np.testing.assert_allclose(t, np.loadtxt(exported / "run" / "scans.txt", usecols=1))
    assert int(dir_summary[0]["queries"]) < len(t) - 51
    assert "no times" not in out_dir
    rec = bvc3d.Recording.open(exported / "run", poses)
    np.testing.assert_array_equal(rec.times, t)


def test_a_recording_without_times_says_so(exported, tmp_path):
    """Finding 4: scans without times (a list without them, KITTI poses) are excluded by scan count only and
    counted one a second for the drift; the output and the summary say so."""
    listing = tmp_path / "untimed.txt"
    listing.write_text("".join(f"{p}\n" for p in sorted((exported / "run").glob("*.pcd"))))
    out, summary, _ = place_recognition_cli(tmp_path / "untimed", "--scans", listing, "--poses",
                                            kitti_poses(exported, tmp_path / "poses.kitti"))
    assert "no times" in out, out
    assert all(r["timed"] == "0" for r in summary)
    assert all(r["timed"] == "0" for r in read_table(tmp_path / "untimed" / "details.csv"))


# ---- 12: messages and figures -------------------------------------------------------------------------

def test_place_recognition_without_revisits_says_so(tmp_path):
    """Finding 12: a drive that never comes back has no revisit: the output says why recall is nan, the
    figure says it in words; and no part of the time printed exceeds the total."""
    route = tmp_path / "line.csv"
    n = 200
    np.savetxt(route, np.column_stack([np.arange(n) * 0.288, np.linspace(-4.5, 4.5, n), np.full(n, -4.0),
                                       np.zeros(n)]), delimiter=",", header="t,x,y,heading", comments="")
    out = tmp_path / "pr"
    proc = run_cli("place-recognition", "--world", "cross", "--route", route, "--sensor", "horizontal",
                   "--descriptors", "scan-context", "--exclude-seconds", 5, "--revisit-m", 0.01, "--out", out,
                   check=True)
    assert "no query has a revisit" in proc.stdout, proc.stdout
    total, part = map(float, re.search(r"([\d.]+) s in all \(([\d.]+) s describing", proc.stdout).groups())
    assert part <= total
    import matplotlib
    matplotlib.use("Agg")
    from bvc3d import place_recognition_figure
    fig = place_recognition_figure.draw(out)
    assert any("no query has a revisit" in t.get_text() for t in fig.axes[0].texts)


