"""What users read is true: the YAML in the documentation and in configs/.

Every ```yaml block of README.md and docs/*.md carries a marker on the line before it:
- `<!-- bvc3d config ARGS -->`: the block is exactly what `bvc3d config ARGS` prints (the program
  writes every key with its exact value, so the docs restate no default by hand);
- `<!-- example: trial|model|sensor|sweep -->`: the block is a configuration the program reads, and it
  restates no preset or default value rounded (e.g. `alpha_pb: 0.7071` for √0.5 gives other results);
- `<!-- example: navigate -->`: a file `bvc3d navigate --config` reads (checked with --dry-run);
- `<!-- schema: world -->`: a list of keys with letters for numbers, not a file to read.
The model files and sweeps in configs/ get the example checks, and a sweep's comment that counts its
trials must count what `bvc3d sweep --dry-run` lists.
"""
import math
import re
import shlex

import pytest
import yaml

from conftest import SOURCE_DIR, run_cli

PAGES = [SOURCE_DIR / "README.md", *sorted((SOURCE_DIR / "docs").glob("*.md"))]
MARKER = re.compile(r"^<!-- (.*) -->$")


def yaml_blocks():
    """(page, line, marker, text) of every ```yaml block; marker "" when there is none."""
    out = []
    for page in PAGES:
        lines = page.read_text().splitlines(keepends=True)
        i = 0
        while i < len(lines):
            if lines[i].strip() == "```yaml":
                start = i + 1
                end = next(j for j in range(start, len(lines)) if lines[j].strip() == "```")
                before = next((lines[j].strip() for j in range(i - 1, -1, -1) if lines[j].strip()), "")
                m = MARKER.match(before)
                out.append((page, start, m.group(1) if m else "", "".join(lines[start:end])))
                i = end
            i += 1
    return out


BLOCKS = yaml_blocks()


def block_id(b):
    return f"{b[0].name}:{b[1]}"


def by_kind(prefix):
    return [b for b in BLOCKS if b[2].startswith(prefix)]


def test_every_yaml_block_is_marked():
    assert BLOCKS, "no YAML blocks found: the pages moved?"
    kinds = re.compile(r"^(bvc3d config( .*)?|example: (trial|model|sensor|sweep|navigate)|schema: world)$")
    unmarked = [f"{block_id(b)} ({b[2] or 'no marker'})" for b in BLOCKS if not kinds.match(b[2])]
    assert not unmarked, f"YAML blocks without a known marker: {unmarked}"
    assert by_kind("bvc3d config"), "the docs show no generated configuration"


@pytest.mark.parametrize("block", by_kind("bvc3d config"), ids=block_id)
def test_generated_blocks_are_the_programs_output(block):
    page, line, marker, text = block
    proc = run_cli(*shlex.split(marker)[1:], check=True, cwd=SOURCE_DIR)
    assert text == proc.stdout, (f"{page.name}:{line} differs from `{marker}`: paste its output there\n"
                                 f"--- docs\n{text}--- program\n{proc.stdout}")


def number(v):
    """A YAML scalar as a float when it is a number (PyYAML reads 1e-3 as text), else None."""
    if isinstance(v, bool):
        return None
    if isinstance(v, (int, float)):
        return float(v)
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def flatten(tree, prefix=""):
    if isinstance(tree, dict):
        out = {}
        for k, v in tree.items():
            out.update(flatten(v, f"{prefix}{k}."))
        return out
    return {prefix[:-1]: tree}


def rounded_restatements(example, reference):
    """Keys whose numbers (or list elements) differ from the reference's by a rounding, not a choice."""
    found = []
    for key, value in flatten(example).items():
        if key not in reference:
            continue
        ref = reference[key]
        pairs = list(zip(value, ref)) if isinstance(value, list) and isinstance(ref, list) and len(value) == len(ref) \
            else [(value, ref)]
        for a, b in pairs:
            a, b = number(a), number(b)
            if a is not None and b is not None and a != b and abs(a - b) <= 1e-3 * max(abs(a), abs(b)):
                found.append(f"{key}: {a!r} is the default {b!r} rounded")
    return found


def expanded(kind, path_or_name):
    """`bvc3d config --KIND X` as a flat dict."""
    proc = run_cli("config", f"--{kind}", path_or_name, check=True, cwd=SOURCE_DIR)
    return flatten(yaml.safe_load(proc.stdout))


def check_config(kind, data, tmp_path, where):
    """Loads the configuration through the program (errors fail the test) and checks that it restates no
    default rounded: against the default trial, the model's base preset, the sensor's preset."""
    path = tmp_path / f"{kind}.yaml"
    path.write_text(yaml.safe_dump(data))
    expanded(kind, path)  # the program reads it
    problems = []
    if kind == "trial":
        problems += rounded_restatements(data, default_trial())
        model = data.get("model")
        if isinstance(model, dict):
            problems += rounded_restatements(model, expanded("model", model.get("base", "3d-0.2")))
    elif kind == "model":
        problems += rounded_restatements(data, expanded("model", data.get("base", "3d-0.2")))
        if isinstance(data.get("sensor"), dict) and "preset" in data["sensor"]:
            problems += rounded_restatements({"sensor": data["sensor"]},
                                             {f"sensor.{k}": v
                                              for k, v in expanded("sensor", data["sensor"]["preset"]).items()})
    elif kind == "sensor" and "preset" in data:
        problems += rounded_restatements(data, expanded("sensor", data["preset"]))
    assert not problems, f"{where}: {problems}"


_DEFAULT_TRIAL = {}


def default_trial():
    if not _DEFAULT_TRIAL:
        _DEFAULT_TRIAL.update(flatten(yaml.safe_load(run_cli("config", check=True).stdout)))
    return _DEFAULT_TRIAL


def check_sweep(data, tmp_path, where):
    check_config("trial", data.get("base", {}), tmp_path, where + " (base)")


@pytest.mark.parametrize("block", by_kind("example:"), ids=block_id)
def test_examples_load_and_restate_no_default_rounded(block, tmp_path):
    page, line, marker, text = block
    kind = marker.split(": ")[1]
    data = yaml.safe_load(text)
    where = f"{page.name}:{line}"
    if kind == "sweep":
        check_sweep(data, tmp_path, where)
        sweep = tmp_path / "sweep.yaml"
        sweep.write_text(text)
        run_cli("sweep", sweep, "--dry-run", check=True, cwd=SOURCE_DIR)
    elif kind == "navigate":
        nav = tmp_path / "nav.yaml"
        nav.write_text(text)
        run_cli("navigate", "--config", nav, "--dry-run", check=True, cwd=SOURCE_DIR)
    else:
        check_config(kind, data, tmp_path, where)


@pytest.mark.parametrize("path", sorted((SOURCE_DIR / "configs" / "models").glob("*.yaml")), ids=lambda p: p.name)
def test_shipped_models_restate_no_default_rounded(path, tmp_path):
    check_config("model", yaml.safe_load(path.read_text()), tmp_path, path.name)


@pytest.mark.parametrize("path", sorted((SOURCE_DIR / "configs" / "sweeps").glob("*.yaml")), ids=lambda p: p.name)
def test_shipped_sweeps_say_true_counts(path, tmp_path):
    check_sweep(yaml.safe_load(path.read_text()), tmp_path, path.name)
    listed = run_cli("sweep", path, "--dry-run", check=True, cwd=SOURCE_DIR).stdout
    n = int(re.search(r"^(\d+) trials$", listed, re.M).group(1))
    comments = "".join(l for l in path.read_text().splitlines(keepends=True) if l.lstrip().startswith("#"))
    for claim in re.findall(r"(\d+) (?:independent )?(?:\w+ )?trials\b", comments):
        assert int(claim) == n, f"{path.name} says {claim} trials, `bvc3d sweep --dry-run` lists {n}"
    # "A × B × C = N": the factors multiply to N.
    for factors, total in re.findall(r"((?:\d+\s*\w*\s*×\s*)+\d+)\s*\w*\s*=\s*(\d+)", comments):
        product = math.prod(int(f) for f in re.findall(r"\d+", factors))
        assert product == int(total), f"{path.name}: {factors} = {total}"


def test_the_rounded_default_check_can_fail(tmp_path):
    """The check finds the kind of value the docs used to show."""
    with pytest.raises(AssertionError, match="alpha_pb"):
        check_config("model", {"base": "3d-0.2", "place": {"alpha_pb": 0.7071}}, tmp_path, "test")
    with pytest.raises(AssertionError, match="turn_sd"):
        check_config("trial", {"robot": {"turn_sd": 0.5236}}, tmp_path, "test")
    check_config("model", {"base": "3d-0.2", "place": {"alpha_pb": 0.5}}, tmp_path, "test")  # a choice, not a rounding


def test_documented_defaults_run_the_presets_bit_for_bit(tmp_path):
    """The default trial of docs/experiments.md and the 3d-0.2 model of docs/model.md, saved as files,
    give byte-identical trial files to the built-in defaults (shortened to 0.02 h per phase)."""
    trial = next(b[3] for b in by_kind("bvc3d config") if b[2] == "bvc3d config")
    model = next(b[3] for b in by_kind("bvc3d config") if b[2] == "bvc3d config --model 3d-0.2")
    short = re.sub(r"(explore_hours|sample_hours): 4 ", r"\1: 0.02 ", trial)
    assert short.count(": 0.02 ") == 2
    (tmp_path / "trial.yaml").write_text(short)
    (tmp_path / "model.yaml").write_text(model)
    run_cli("run", "--config", tmp_path / "trial.yaml", "--out", tmp_path / "from_docs.h5", check=True)
    run_cli("run", "--hours", "0.02", "--out", tmp_path / "builtin.h5", check=True)
    run_cli("run", "--model", tmp_path / "model.yaml", "--hours", "0.02", "--out", tmp_path / "model_docs.h5",
            check=True)
    for name in ("from_docs.h5", "model_docs.h5"):
        assert (tmp_path / name).read_bytes() == (tmp_path / "builtin.h5").read_bytes(), name
