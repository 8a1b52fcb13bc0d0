"""Every command's options come from the same groups, with the same names and true help texts (issue 41, "commands
built from option groups"; issue 43, findings 5, 6 and 11).

The commands are read from `bvc3d --help`, so a new command cannot escape the checks; each command's options and
their help from `bvc3d COMMAND --help`. The LiDAR models are the library's own list (bvc3d.lidar_models()), checked
against the names the documentation gives.
"""
import os
import pathlib
import re

import pytest

from conftest import SOURCE_DIR, run_cli

# Commands that take a world other than by --world, and how: each must still exist and say so in its help.
WORLD_ELSEWHERE = {
    "paper": "--tilts",  # the paper's cross arena, at the tilts given
    "flight": "--worlds",  # a list of worlds with a flight volume
    "sweep": "sweep",  # the sweep YAML names the worlds
    "view": "world",  # a world file or preset is one of the paths it opens
}
DOCUMENTED_LIDARS = {"vlp16", "hdl32", "hdl64", "os1-64", "os1-128"}  # docs/worlds.md#sensors
SHARED = pathlib.Path(os.environ.get("BVC3D_SHARED_DATA", SOURCE_DIR.parent / "shared" / "data"))
GAZEBO = SHARED / "gazebo" / "aws-robomaker-hospital-world"


def commands():
    text = run_cli("--help", check=True).stdout
    listed = text.split("Subcommands:", 1)[1]
    return [m.group(1) for m in re.finditer(r"^  (\S+)\s", listed, re.M)]


COMMANDS = commands()


def options(command):
    """{option: its help text} of `bvc3d COMMAND --help`, positionals under their names, "" for the command."""
    text = run_cli(command, "--help", check=True).stdout
    found, current = {"": text.splitlines()[0]}, None
    for line in text.splitlines():
        m = re.match(r"^  (?:-\w,)?(--[\w-]+|[a-z][\w-]*)\b(.*)$", line)
        if m and not line.startswith("   "):
            current = m.group(1)
            found[current] = m.group(2).strip()
        elif current and line.startswith("   "):
            found[current] += " " + line.strip()
        elif not line.strip():
            current = None
    return found


OPTIONS = {c: options(c) for c in COMMANDS}


def test_the_commands_are_read_from_the_program():
    assert {"scan", "walk", "run", "paper", "export-scans", "place-recognition", "route", "navigate"} <= set(COMMANDS)
    assert all("--help" in OPTIONS[c] for c in COMMANDS), "the help parser found no options"


@pytest.mark.parametrize("command", COMMANDS)
def test_a_command_that_takes_a_world_takes_the_whole_world_group(command):
    opts = OPTIONS[command]
    mentions_world = any(re.search(r"\bworlds?\b(?!\.md| frame)", text, re.I)  # an input, not the world frame
                         for name, text in opts.items() if name not in ("", "--help"))
    if "--world" in opts:
        missing = {"--tilt", "--lean", "--missing-models"} - set(opts)
        assert not missing, f"{command} takes --world but not {sorted(missing)}"
        help_text = opts["--world"]
        assert ".world" in help_text and "YAML" in help_text, f"{command} --world: {help_text}"
        assert "cross" in help_text and "atrium" in help_text, f"{command} --world names no presets: {help_text}"
        assert "skip" in opts["--missing-models"] and "error" in opts["--missing-models"]
    elif mentions_world:
        assert command in WORLD_ELSEWHERE, f"{command} speaks of a world but takes no --world"
        how = WORLD_ELSEWHERE[command]
        assert any(how in name or how in text for name, text in opts.items()), f"{command}: {how}"


def test_the_commands_that_take_a_world_elsewhere_exist():
    assert set(WORLD_ELSEWHERE) <= set(COMMANDS)
    assert {c for c in COMMANDS if "--world" in OPTIONS[c]} >= {
        "scan", "walk", "bvc", "run", "replay", "export-scans", "choose-elevations", "place-recognition", "route",
        "navigate"}


def lidar_names():
    try:
        import bvc3d
    except ImportError:
        return DOCUMENTED_LIDARS
    names = {m["name"] for m in bvc3d.lidar_models()}
    assert DOCUMENTED_LIDARS <= names
    return names


@pytest.mark.parametrize("command", [c for c in COMMANDS if "--sensor" in OPTIONS[c]])
def test_every_sensor_option_names_the_lidar_models_and_each_works(command):
    help_text = OPTIONS[command]["--sensor"]
    for name in sorted(lidar_names()) + ["horizontal", "spherical"]:
        assert re.search(rf"\b{re.escape(name)}\b", help_text), f"{command} --sensor omits {name}: {help_text}"
    assert "YAML" in help_text


def test_the_sensors_the_help_names_are_accepted():
    help_text = OPTIONS["scan"]["--sensor"]
    named = re.findall(r"\(([^)]*)\)", help_text)
    names = [n.strip() for group in named[:2] for n in group.split(",")]
    assert len(names) >= 7, help_text
    for name in names:
        run_cli("config", "--sensor", name, check=True)


FIGURES = re.compile(r"figure|report\.md", re.I)


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_that_draws_figures_takes_no_figures(command):
    opts = OPTIONS[command]
    visible = set(opts)
    assert not visible & {"--no-figure", "--no-report"}, f"{command} shows an old spelling"
    if any(FIGURES.search(text) for name, text in opts.items() if name not in ("--help", "--no-figures")):
        assert "--no-figures" in opts, f"{command} draws figures but takes no --no-figures"


@pytest.mark.parametrize("argv,says", [
    (["summarize", "/no/such/folder", "--no-report"], "is not a folder"),
    (["summarize", "/no/such/folder", "--no-figures"], "is not a folder"),
    (["localize", "--model", "2d", "--no-figure"], "give --templates and --queries"),
    (["paper", "--no-report", "--jobs", "-1"], "--jobs must be >= 0"),
])
def test_the_old_figure_switches_still_parse(argv, says):
    proc = run_cli(*argv)
    assert proc.returncode == 2 and "usage error" not in proc.stderr and says in proc.stderr, proc.stderr


PARALLEL = re.compile(r"in parallel|threads?\b|per core", re.I)


@pytest.mark.parametrize("command", COMMANDS)
def test_every_command_that_runs_in_parallel_takes_jobs(command):
    opts = OPTIONS[command]
    assert "--threads" not in opts, f"{command} shows --threads"
    if any(PARALLEL.search(text) for name, text in opts.items() if name not in ("--help", "--jobs")):
        assert "--jobs" in opts, f"{command} runs in parallel but takes no --jobs"
    if "--jobs" in opts:
        assert "0 (the default): one per core" in opts["--jobs"]


def test_place_recognition_takes_jobs_and_threads_as_its_alias(tmp_path):
    track = tmp_path / "track.csv"
    track.write_text("t,x,y,heading\n0,-3,-3,0\n0.288,-2.9,-3,0\n0.576,-2.8,-3,0\n")
    for flag in ("--jobs", "--threads"):
        proc = run_cli("place-recognition", "--descriptors", "scan-context", "--world", "cross", "--route", track,
                       "--sensor", "horizontal", flag, "-1", "--out", tmp_path / "out")
        assert proc.returncode == 2 and "--jobs must be >= 0" in proc.stderr, proc.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", COMMANDS)
def test_every_output_says_what_becomes_of_an_existing_one(command):
    opts = OPTIONS[command]
    outputs = [o for o in ("--out", "--csv", "--cells", "--export") if o in opts]
    if command in ("config", "bag-info", "summarize") or not outputs:
        return
    assert "--force" in opts, f"{command} writes {outputs} but takes no --force"
    for o in outputs:
        assert "--force" in opts[o], f"{command} {o}: {opts[o]}"


def test_the_analysis_options_are_the_analysis_table(tmp_path):
    """analyze takes every key of the analysis table (as `bvc3d config` prints it), checked as the table checks it."""
    import yaml
    trial = yaml.safe_load(run_cli("config", check=True).stdout)
    keys = [k for k in trial["analysis"] if k != "extent"]
    opts = OPTIONS["analyze"]
    for key in keys:
        assert "--" + key.replace("_", "-") in opts, key
    assert "DBSCAN neighborhood radius" in opts["--eps"] and "(rate_maps or means)" in opts["--decoding-templates"]
    h5 = tmp_path / "t.h5"
    run_cli("run", "--hours", "0.002", "--model", "2d", "--out", h5, check=True)
    for argv, says in ((["--gridsize", "1"], "--gridsize: must be in [2, 2000], got 1"),
                       (["--gridsize", "1.5"], "--gridsize '1.5' is not a whole number"),
                       (["--decoding-templates", "median"], "--decoding-templates: "),
                       (["--mi-quantile", "2"], "--mi-quantile: must be in [-1, 1], got 2")):
        proc = run_cli("analyze", h5, *argv)
        assert proc.returncode == 2 and says in proc.stderr, (argv, proc.stderr)
    proc = run_cli("analyze", h5, "--min-samples", "5", "--out", tmp_path / "m.csv", check=True)
    header, row = (tmp_path / "m.csv").read_text().splitlines()[:2]
    assert row.split(",")[header.split(",").index("min_samples")] == "5"


# ---------------------------------------------------------------------------------------------------
# Issue 43, finding 5: --missing-models wherever a world is named.

WORLD_WITH_A_MISSING_MODEL = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="room">
    <include><uri>model://no_such_chair</uri><pose>0 0 0 0 0 0</pose></include>
    <model name="floor"><static>true</static><link name="l">
      <visual name="v"><pose>0 0 -0.05 0 0 0</pose><geometry><box><size>12 12 0.1</size></box></geometry></visual>
    </link></model>
    <model name="walls"><static>true</static><link name="l">
      <visual name="n"><pose>0 5 1 0 0 0</pose><geometry><box><size>10 0.2 2</size></box></geometry></visual>
      <visual name="s"><pose>0 -5 1 0 0 0</pose><geometry><box><size>10 0.2 2</size></box></geometry></visual>
      <visual name="e"><pose>5 0 1 0 0 0</pose><geometry><box><size>0.2 10 2</size></box></geometry></visual>
      <visual name="w"><pose>-5 0 1 0 0 0</pose><geometry><box><size>0.2 10 2</size></box></geometry></visual>
    </link></model>
  </world>
</sdf>
"""


@pytest.fixture
def room(tmp_path):
    path = tmp_path / "room.world"
    path.write_text(WORLD_WITH_A_MISSING_MODEL)
    return path


def test_missing_models_skip_loads_a_gazebo_world_with_a_missing_model(room, tmp_path):
    refused = run_cli("scan", "--world", room, "--pose", "0,0,0", "--sensor", "horizontal")
    assert refused.returncode == 2 and "no_such_chair" in refused.stderr, refused.stderr
    proc = run_cli("scan", "--world", room, "--missing-models", "skip", "--pose", "0,0,0", "--sensor", "horizontal",
                   check=True)
    assert "1 included model was not found and is left out (first: no_such_chair" in proc.stderr
    ranges = [float(line.split(",")[0]) for line in proc.stdout.splitlines()[1:]]
    assert len(ranges) > 100 and min(ranges) == pytest.approx(4.9, abs=0.01)  # the walls' inner faces


@pytest.mark.parametrize("argv", [
    ["walk", "--hours", "0.001"],
    ["route", "--tour", "--out", "{tmp}/tour.csv"],
    ["run", "--hours", "0.002", "--model", "2d", "--out", "{tmp}/trial.h5"],
    ["export-scans", "--hours", "0.001", "--sensor", "horizontal", "--out", "{tmp}/scans"],
])
def test_missing_models_skip_reaches_every_kind_of_command(room, tmp_path, argv):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    refused = run_cli(*argv, "--world", room)
    assert refused.returncode == 2 and "no_such_chair" in refused.stderr, refused.stderr
    run_cli(*argv, "--world", room, "--missing-models", "skip", check=True)


def test_missing_models_is_refused_where_it_means_nothing():
    proc = run_cli("scan", "--world", "cross", "--missing-models", "skip", "--pose", "0,-2,0")
    assert proc.returncode == 2 and "applies to Gazebo world files" in proc.stderr, proc.stderr
    proc = run_cli("scan", "--world", "cross", "--missing-models", "maybe", "--pose", "0,-2,0")
    assert proc.returncode == 2 and "--missing-models: must be 'error' or 'skip', got 'maybe'" in proc.stderr


def test_a_trial_remembers_missing_models_skip(room, tmp_path):
    """The choice changes the world, so it is in the trial's configuration (YAML and fingerprint)."""
    trial = tmp_path / "trial.yaml"
    trial.write_text(f"world: {{source: {room}, missing_models: skip}}\nmodel: 2d\n")
    text = run_cli("config", "--trial", trial, check=True).stdout
    assert "missing_models: skip" in text


@pytest.mark.skipif(not GAZEBO.is_dir(), reason=f"needs the AWS hospital world in {GAZEBO}")
def test_the_readme_hospital_scan_runs_as_written(tmp_path):
    readme = (SOURCE_DIR / "README.md").read_text()
    line = next(l for l in readme.splitlines() if "scan --world" in l and "hospital" in l)
    args = line.split("#")[0].split()[1:]
    assert "--missing-models" in args
    (tmp_path / "worlds").symlink_to(GAZEBO / "worlds")
    (tmp_path / "models").symlink_to(GAZEBO / "models")
    proc = run_cli(*args, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert len(proc.stdout.splitlines()) > 10000


# ---------------------------------------------------------------------------------------------------
# Issue 43, finding 6: navigate --model takes a list, as its YAML's models: does.

def test_navigate_model_takes_a_list_as_its_yaml_does():
    proc = run_cli("navigate", "--world", "cross", "--goals", "3,3", "--model", "2d,3d-0.2", "--seeds", "2",
                   "--dry-run", check=True)
    assert "2 model(s) × 2 seed(s) = 4 learning runs" in proc.stdout, proc.stdout
    assert "comma-separated" in OPTIONS["navigate"]["--model"]


# ---------------------------------------------------------------------------------------------------
# Issue 43, finding 11: the format and the name agree; nothing that exists is written over unasked.

def export(tmp_path, *args):
    return run_cli("export-scans", "--hours", "0.001", "--sensor", "horizontal", *args, cwd=tmp_path)


@pytest.mark.parametrize("fmt,out,says", [
    ("ros1", "new/", "must end in .bag"),
    ("ros1", "new", "must end in .bag"),
    ("ros1", "walk.mcap", "must end in .bag"),
    ("mcap", "x.bag", "must end in .mcap"),
    ("pcd", "walk.bag", "--format ros1 for a .bag file"),
    ("kitti", "walk.mcap", "--format mcap for a .mcap file"),
])
def test_export_format_and_name_must_agree(tmp_path, fmt, out, says):
    proc = export(tmp_path, "--format", fmt, "--out", out)
    assert proc.returncode == 2 and says in proc.stderr, proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_an_existing_bag_is_refused_unless_force(tmp_path):
    bag = tmp_path / "walk.bag"
    export(tmp_path, "--format", "ros1", "--out", bag).check_returncode()
    first = bag.read_bytes()
    proc = export(tmp_path, "--format", "ros1", "--seed", "1", "--out", bag)
    assert proc.returncode == 2 and f"--out '{bag}' exists" in proc.stderr and "--force" in proc.stderr
    assert bag.read_bytes() == first
    export(tmp_path, "--format", "ros1", "--seed", "1", "--out", bag, "--force").check_returncode()
    assert bag.read_bytes() != first
    info = run_cli("bag-info", bag, check=True)
    assert "ROS 1" in info.stdout or "ros1" in info.stdout.lower()


def test_an_existing_recording_folder_is_refused_unless_force(tmp_path):
    out = tmp_path / "walk"
    export(tmp_path, "--out", out).check_returncode()
    proc = export(tmp_path, "--out", f"{out}/")
    assert proc.returncode == 2 and "exists and holds files" in proc.stderr
    export(tmp_path, "--out", out, "--force").check_returncode()
    (out / "notes.txt").write_text("mine")
    proc = export(tmp_path, "--out", out, "--force")  # --force never removes what bvc3d did not write
    assert proc.returncode == 2 and "notes.txt" in proc.stderr
    assert (out / "notes.txt").read_text() == "mine"


def test_place_recognition_refuses_an_existing_folder_unless_force(tmp_path):
    route = tmp_path / "track.csv"
    xs = [-4 + 0.07 * i for i in range(40)] + [-4 + 0.07 * (39 - i) for i in range(40)]  # there and back
    rows = "\n".join(f"{i * 0.288},{x},-3,0" for i, x in enumerate(xs))
    route.write_text("t,x,y,heading\n" + rows + "\n")
    args = ["place-recognition", "--descriptors", "scan-context", "--world", "cross", "--route", route, "--sensor",
            "horizontal", "--exclude-scans", "5", "--exclude-seconds", "1", "--no-figures", "--out", tmp_path / "pr"]
    run_cli(*args, check=True)
    before = (tmp_path / "pr" / "summary.csv").read_text()
    proc = run_cli(*args, "--revisit-m", "1")
    assert proc.returncode == 2 and "--force" in proc.stderr and "pr'" in proc.stderr, proc.stderr
    assert (tmp_path / "pr" / "summary.csv").read_text() == before
    run_cli(*args, "--revisit-m", "1", "--force", check=True)


def test_single_files_are_refused_unless_force(tmp_path):
    out = tmp_path / "scan.csv"
    run_cli("scan", "--pose", "0,-2,0", "--sensor", "horizontal", "--out", out, check=True)
    proc = run_cli("scan", "--pose", "0,-3,0", "--sensor", "horizontal", "--out", out)
    assert proc.returncode == 2 and "--out" in proc.stderr and "--force" in proc.stderr
    run_cli("scan", "--pose", "0,-3,0", "--sensor", "horizontal", "--out", out, "--force", check=True)
    assert run_cli("scan", "--pose", "0,-3,0", "--sensor", "horizontal", "--out", "-").returncode == 0


def test_results_folders_resume_without_force_and_refuse_other_kinds(tmp_path):
    out = tmp_path / "paper"
    args = ["paper", "--models", "2d", "--tilts", "0", "--hours", "0.002", "--no-figures", "--jobs", "1"]
    run_cli(*args, "--out", out, check=True)
    again = run_cli(*args, "--out", out, check=True)  # resumes: nothing to run
    assert "(0 run, 1 already complete)" in again.stdout
    scans = tmp_path / "scans"
    export(tmp_path, "--out", scans).check_returncode()
    proc = run_cli(*args, "--out", scans)
    assert proc.returncode == 2 and "holds files of another kind" in proc.stderr and "--force" in proc.stderr
    assert not list(scans.glob("*.h5"))
    nav = run_cli("navigate", "--world", "cross", "--goals", "3,3", "--out", out, "--dry-run")
    assert nav.returncode == 2 and "holds files of another kind" in nav.stderr, nav.stderr


def test_a_trial_file_is_run_again_in_place_but_another_file_is_refused(tmp_path):
    out = tmp_path / "trial.h5"
    args = ["run", "--hours", "0.002", "--model", "2d", "--out", out]
    run_cli(*args, check=True)
    assert "nothing to do" in run_cli(*args, check=True).stderr
    run_cli(*args, "--seed", "1", check=True)  # another trial into its own kind of file: run again
    other = tmp_path / "notes.h5"
    other.write_text("not a trial file")
    proc = run_cli("run", "--hours", "0.002", "--model", "2d", "--out", other)
    assert proc.returncode == 2 and "exists and is not a trial file" in proc.stderr
    assert other.read_text() == "not a trial file"


def test_docs_show_no_old_option_spellings():
    """The pages use the options' names; an old spelling only where an older build runs (build-ref/)."""
    pages = [SOURCE_DIR / "README.md", *sorted((SOURCE_DIR / "docs").glob("*.md"))]
    for page in pages:
        for n, line in enumerate(page.read_text().splitlines(), 1):
            line = line.split("build-ref/")[0]
            for old in (r"--no-report\b", r"--no-figure\b", r"--threads\b"):
                assert not re.search(old, line), f"{page.name}:{n} shows {old[:-2]}: {line}"
