"""bvc3d.report on hand-made experiment folders, checked with matplotlib's own objects and geometry:
figures say what they show (worlds, models, seeds, axes with units), legends cover no data, bars too
low to see are marked with their value, error bars of non-negative quantities stop at 0, and
report.md states the protocol, durations, seeds and analysis parameters read from the trial files."""
import csv
import math
import pathlib
import re

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.container import BarContainer, ErrorbarContainer
from matplotlib.lines import Line2D
from matplotlib.text import Annotation

import bvc3d
from bvc3d import report

# The metrics with figures in a ground experiment's report (the 3-D ones: test_flying.py).
METRICS = [m for m in bvc3d.metric_table if m["title"] and m["dims"] == 0]


def make_folder(path, modality_by_model):
    """An experiment folder with one trial per model in the cross-60 world; each trial's cells have
    the given modality indices (cell k has k + 1 active bins, so the last candidate is the pick)."""
    models = list(modality_by_model)
    with open(path / "trials.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "model", "world", "seed"])
        for m in models:
            w.writerow([f"cross-60_{m}_seed0", m, "cross-60", 0])
    with open(path / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["condition", "model", "world", "tilt_deg"])
        for m in models:
            w.writerow([f"cross-60_{m}", m, "cross-60", 60])
    centers = np.column_stack([np.linspace(-4, 4, 10), np.linspace(-3, 3, 10)])
    for m, mi in modality_by_model.items():
        mi = np.asarray(mi, dtype=np.int64)
        maps = np.zeros((10, len(mi)), dtype=np.float32)
        for k in range(len(mi)):
            if mi[k] > 0:
                maps[:k + 1, k] = 1
        with h5py.File(path / f"cross-60_{m}_seed0.h5", "w") as f:
            f["metrics/modality"] = mi
            f["metrics/rate_maps"] = maps
            f["metrics/bin_centers"] = centers
    return report.Folder(str(path))


@pytest.mark.parametrize("first,last,titles", [
    ([0, 2, 1, 3], [1, 2, 1], ["multimodal: A cell 3 (MI = 3)", "unimodal: B cell 2 (MI = 1)"]),
    ([0, 1, 1], [2, 3, 0], ["no multimodal cell; showing a unimodal one:\nA cell 2 (MI = 1)",
                            "no unimodal cell; showing a multimodal one:\nB cell 1 (MI = 3)"]),
    ([0, 0], [0, 1], ["A: no multimodal cell; no cell has a field (every MI = 0)", "unimodal: B cell 1 (MI = 1)"]),
])
def test_place_field_panels_say_what_they_show(tmp_path, first, last, titles):
    folder = make_folder(tmp_path, {"A": first, "B": last})
    out = tmp_path / "place_fields.png"
    got = report.fig_place_fields(folder, str(out))
    assert [t.rsplit("\n", 1)[0] for t in got] == titles
    assert all(t.endswith("\n60° tilt, seed 0") for t in got)
    assert out.stat().st_size > 0


def test_pick_example_cell():
    maps = np.zeros((5, 4))
    maps[:2, 1] = maps[:4, 2] = maps[:1, 3] = 1
    assert report.pick_example_cell([0, 2, 2, 1], maps, "multimodal") == (2, "multimodal")
    assert report.pick_example_cell([0, 2, 2, 1], maps, "unimodal") == (3, "unimodal")
    assert (report.pick_example_cell([0, 1, 1, 0], maps, "multimodal")
            == (2, "no multimodal cell; showing a unimodal one"))
    assert report.pick_example_cell([0, 0], maps[:, :2], "unimodal")[0] is None


def test_failed_report_hint_works_as_printed(tmp_path):
    """When the figures fail, the error prints the command that redoes them; run verbatim in a shell
    with nothing of ours in its environment (no PYTHONPATH; `python3` on PATH may lack numpy), it
    works."""
    import os
    import shlex
    import subprocess

    from conftest import run_cli

    out = tmp_path / "exp"
    out.mkdir()
    (out / "figures").write_text("a file where the figures folder goes: the report fails")
    # --force: the folder holds a file of another kind (the outputs rule would refuse it before any trial runs).
    proc = run_cli("paper", "--hours", "0.02", "--models", "2d", "--tilts", "0", "--out", "exp", "--force",
                   cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    i = next(k for k, line in enumerate(lines) if line.endswith("rerun it with:"))
    command = lines[i + 1].strip()
    assert command.startswith("PYTHONPATH=") and " -m bvc3d.report exp" in command
    interpreter = shlex.split(command)[1]
    assert os.path.isabs(interpreter), command  # an interpreter by path, not whatever `python3` is first on PATH
    (out / "figures").unlink()
    env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": str(tmp_path)}
    done = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (out / "report.md").exists() and (out / "figures" / "msai.png").exists()
    # The interpreter the program is told to use is the one it names.
    env = dict(os.environ,
               BVC3D_PYTHON="/usr/bin/python3.11" if os.path.exists("/usr/bin/python3.11") else "/usr/bin/python3")
    (out / "report.md").unlink()
    (out / "figures" / "msai.png").unlink()
    (out / "figures").rename(out / "figures.old")
    (out / "figures").write_text("blocker")
    proc = run_cli("summarize", "exp", cwd=tmp_path, env=env)
    assert proc.returncode == 2 and f" {env['BVC3D_PYTHON']} -m bvc3d.report exp" in proc.stderr, proc.stderr



# ---- figures and report.md of a whole experiment folder ----

ANALYSIS = {"gridsize": 50, "quantile": 0.1, "eps": 1.0, "min_samples": 20, "d_th": 2.0,
            "decoding_templates": "rate_maps"}


def metric_values(model, tilt, seed, n_seeds):
    """Per-trial metric values chosen to exercise the figures: frac_multimodal is exactly 0 for the
    second model (zero-height bars), msai is 0.03 for the last seed only (sd > mean: an unclipped error
    bar would go below 0), decode_median_m is 0 at 60° for the first model and tiny elsewhere for one."""
    last = seed == n_seeds - 1
    return {
        "frac_active": 0.5 + 0.01 * seed + 0.001 * tilt,
        "mean_mi_active": 1.0 + 0.1 * model + 0.01 * seed,
        "frac_multimodal": 0.0 if model == 1 else 0.2 - 0.002 * tilt + 0.01 * seed,
        "msai": 0.03 if last or n_seeds == 1 else 0.0,
        "decode_median_m": 0.0 if (model == 0 and tilt == 60) else (1e-4 if model == 2 else 0.3 + 0.01 * seed),
        "decode_mean_m": 1.0, "n_bins": 30.0, "n_decoded": 90.0, "n_undecoded": 10.0,
        "frac_undecoded": 0.1 + 0.01 * seed, "decode_median_all_m": 0.4 + 0.01 * seed, "decode_mean_all_m": 1.5,
    }


def make_experiment(path, models=("A", "B", "C"), tilts=(0, 30, 45, 60), seeds=(0, 1, 2),
                    sample_hours=lambda t, s: 4.0):
    """An experiment folder as `bvc3d paper` writes it: trial files with the attributes and /metrics the
    report reads, trials.csv, summary.csv (mean and sd with numpy) and summary.md."""
    names = [m["name"] for m in bvc3d.metric_table if m["dims"] == 0]
    trials, rng = [], np.random.default_rng(0)
    centers = np.column_stack([np.linspace(-4, 4, 30), np.linspace(-3, 3, 30)])
    for seed in seeds:
        for tilt in tilts:
            for i, m in enumerate(models):
                name = f"cross-{tilt}_{m}_seed{seed}"
                values = metric_values(i, tilt, seed, len(seeds))
                trials.append((name, m, f"cross-{tilt}", tilt, seed, values))
                with h5py.File(path / f"{name}.h5", "w") as f:
                    f.attrs.update({"protocol": "explore_then_sample", "explore_hours": 4.0,
                                    "sample_hours": sample_hours(tilt, seed), "seed": seed, "model": m})
                    g = f.create_group("metrics")
                    g.attrs.update(ANALYSIS)
                    g.attrs.update(values)
                    mi = np.array([0, 1, 2, 1, 3] * 2)
                    maps = (rng.random((30, 10)) > 0.7).astype(np.float32)
                    g["modality"], g["rate_maps"], g["bin_centers"] = mi, maps, centers
                    g["sai"] = rng.random(30) * 0.05
                    f["samples/x"], f["samples/y"] = rng.random(50) * 8 - 4, rng.random(50) * 8 - 4
                    f["samples/t"] = np.arange(50) * 0.288
    with open(path / "trials.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["name", "condition", "model", "world", "tilt_deg", "seed", *names])
        for name, m, world, tilt, seed, v in trials:
            w.writerow([name, f"{world}_{m}", m, world, tilt, seed, *[v[n] for n in names]])
    with open(path / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["condition", "model", "world", "tilt_deg", "n_seeds",
                    *[f"{n}_{s}" for n in names for s in ("mean", "sd")]])
        for tilt in tilts:
            for m in models:
                rows = [t[5] for t in trials if t[1] == m and t[3] == tilt]
                stats = []
                for n in names:
                    v = np.array([r[n] for r in rows])
                    stats += [v.mean(), v.std(ddof=1) if len(v) > 1 else math.nan]
                w.writerow([f"cross-{tilt}_{m}", m, f"cross-{tilt}", tilt, len(rows), *stats])
    (path / "summary.md").write_text("| model | world |\n|---|---|\n")
    return report.Folder(str(path))


@pytest.fixture
def three_seeds(tmp_path):
    (tmp_path / "three").mkdir()
    return make_experiment(tmp_path / "three")


@pytest.fixture
def one_seed(tmp_path):
    (tmp_path / "one").mkdir()
    return make_experiment(tmp_path / "one", seeds=(0,))


def display_box(ax, xs, ys):
    pts = ax.transData.transform(np.column_stack([xs, ys]))
    return pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max()


def overlap(a, b):
    """Closed boxes (x0, y0, x1, y1) in pixels share a point."""
    return a[0] <= b[2] and b[0] <= a[2] and a[1] <= b[3] and b[1] <= a[3]


def errorbar_segments(ax):
    """Every error-bar segment (data coordinates) of bars and errorbar lines: [(x, low, high)]."""
    out, seen = [], set()
    for c in ax.containers:
        eb = c.errorbar if isinstance(c, BarContainer) else c if isinstance(c, ErrorbarContainer) else None
        if eb is None:
            continue
        for col in eb.lines[2]:
            if id(col) in seen:  # a bar chart's error bars are also a container of their own
                continue
            seen.add(id(col))
            for seg in col.get_segments():
                seg = np.asarray(seg)
                out.append((seg[0, 0], seg[:, 1].min(), seg[:, 1].max()))
    return out


def data_boxes(fig, ax):
    """Pixel boxes of everything that shows data: bars, error bars (and caps), lines and markers, value labels."""
    renderer = fig.canvas.get_renderer()
    boxes = [tuple(p.get_window_extent(renderer).extents) for p in ax.patches if p.get_height() != 0]
    boxes += [display_box(ax, [x, x], [lo, hi]) for x, lo, hi in errorbar_segments(ax)]
    for line in ax.lines:
        xs, ys = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        ok = np.isfinite(xs) & np.isfinite(ys)
        if ok.any():
            boxes.append(display_box(ax, xs[ok], ys[ok]))
    boxes += [tuple(t.get_window_extent(renderer).extents) for t in ax.texts]
    return boxes


def check_legend_hides_nothing(fig):
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    checked = 0
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        box = tuple(legend.get_window_extent(renderer).extents)
        page = tuple(fig.bbox.extents)
        assert page[0] <= box[0] and box[2] <= page[2] and page[1] <= box[1] and box[3] <= page[3], "legend cut off"
        hidden = [b for b in data_boxes(fig, ax) if overlap(box, b)]
        assert not hidden, f"legend at {box} covers data at {hidden[:3]}"
        checked += 1
    return checked


@pytest.mark.parametrize("folder_name", ["three_seeds", "one_seed"])
@pytest.mark.parametrize("metric", [m["name"] for m in METRICS])
def test_bar_legends_cover_no_data(request, folder_name, metric):
    fig = report.bars_figure(request.getfixturevalue(folder_name), metric)
    assert check_legend_hides_nothing(fig) == 1
    plt.close(fig)


def test_the_legend_check_can_fail(three_seeds):
    """The old layout (legend inside the axes, upper right) covers bars: the check sees it."""
    fig = report.bars_figure(three_seeds, "frac_active")
    ax = fig.axes[0]
    ax.legend(loc="upper right", fontsize=8, ncol=3)
    with pytest.raises(AssertionError, match="covers data"):
        check_legend_hides_nothing(fig)
    plt.close(fig)


def bars_of(ax):
    return [(c.get_label(), list(c)) for c in ax.containers if isinstance(c, BarContainer)]


def test_bars_too_low_to_see_are_marked_with_their_value(three_seeds):
    fig = report.bars_figure(three_seeds, "frac_multimodal")  # model B: 0 everywhere
    fig.canvas.draw()
    ax = fig.axes[0]
    lo, hi = ax.get_ylim()
    notes = [t for t in ax.texts if isinstance(t, Annotation)]
    for label, bars in bars_of(ax):
        for bar in bars:
            x0, x1, h = bar.get_x(), bar.get_x() + bar.get_width(), bar.get_height()
            here = [t for t in notes if x0 <= t.xy[0] <= x1]
            if label == "B":
                assert h == 0
                marks = [l for l in ax.lines if l.get_linewidth() >= 2 and np.allclose(l.get_ydata(), 0)
                         and min(l.get_xdata()) <= x0 + 1e-9 and max(l.get_xdata()) >= x1 - 1e-9]
                assert marks, f"zero bar at {x0} has no mark"
                box = marks[0].get_window_extent(fig.canvas.get_renderer())  # its path; the stroke adds the width
                assert box.width > 10 and marks[0].get_linewidth() * fig.dpi / 72 >= 3, "the mark is not visible"
                assert [t.get_text() for t in here] == ["0.000"]
            else:
                assert h > report.TINY * (hi - lo) and not here
    # A tiny nonzero bar (1e-4 m next to 0.3 m) is labeled with its value too; a zero one as 0.00.
    fig2 = report.bars_figure(three_seeds, "decode_median_m")
    texts = sorted(t.get_text() for t in fig2.axes[0].texts)
    assert texts == ["0.00"] + ["0.00"] * 4
    plt.close(fig)
    plt.close(fig2)


def test_error_bars_stop_at_zero_and_keep_the_sd_above(three_seeds):
    fig = report.bars_figure(three_seeds, "msai")  # values 0, 0, 0.03: mean 0.01, sd 0.0173
    ax = fig.axes[0]
    v = np.array([0.0, 0.0, 0.03])
    mean, sd = v.mean(), v.std(ddof=1)
    segments = errorbar_segments(ax)
    assert len(segments) == 12
    for x, low, high in segments:
        assert low == pytest.approx(max(mean - sd, 0.0)) and low >= 0
        assert high == pytest.approx(mean + sd)
    plt.close(fig)


def test_sweep_lines_keep_error_bars_above_zero_and_legends_outside(three_seeds):
    folder = three_seeds
    for r in folder.summary:  # as a sweep over the tilt, one line per model
        r["swept:world.tilt_deg"], r["swept:model"] = r["tilt_deg"], r["model"]
    fig = report.sweep_figure(folder, ["swept:world.tilt_deg", "swept:model"], "msai")
    assert check_legend_hides_nothing(fig) == 1
    assert all(low >= 0 for _, low, _ in errorbar_segments(fig.axes[0]))
    assert fig.axes[0].get_xlabel() == "world.tilt_deg"
    plt.close(fig)


def all_text(fig):
    return [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]


def test_one_seed_shows_no_means_or_spreads(one_seed):
    for m in METRICS:
        fig = report.bars_figure(one_seed, m["name"])
        assert not errorbar_segments(fig.axes[0])
        text = " ".join(all_text(fig))
        assert "seed 0" in text and "one trial" in text
        assert "±" not in text and not re.search(r"\bsd\b|over \d+ seeds", text), text
        plt.close(fig)
    lines = "\n".join(report.setting_lines(one_seed))
    assert "one trial per condition" in lines and "±" not in lines and "standard deviation" not in lines


def test_every_figure_names_what_it_shows_with_axis_units(three_seeds):
    folder = three_seeds
    for m in METRICS:
        fig = report.bars_figure(folder, m["name"])
        ax = fig.axes[0]
        assert ax.get_xlabel() == "tilt of the central walls (°), cross arena"
        assert ax.get_ylabel() == m["label"]
        assert [t.get_text() for t in ax.get_xticklabels()] == ["0", "30", "45", "60"]
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["A", "B", "C"]
        assert "mean ± sd over 3 seeds (0–2)" in ax.get_title()
        plt.close(fig)
    fig = report.sai_grid_figure(folder)
    assert "one trial per panel, seed 0 of seeds 0–2" in fig._suptitle.get_text()
    grid = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    assert len(grid) == 12
    for k, ax in enumerate(grid):
        model, tilt = "ABC"[k // 4], (0, 30, 45, 60)[k % 4]
        assert ax.get_title().startswith(f"{model}, {tilt}° tilt: MSAI ")
        assert ax.get_xlabel() in ("x (m)", "") and ax.get_ylabel() in ("y (m)", "")
    assert {a.get_xlabel() for a in grid[-4:]} == {"x (m)"} and {grid[k].get_ylabel() for k in (0, 4, 8)} == {"y (m)"}
    assert any("SAI" in a.get_ylabel() for a in fig.axes if a not in grid)  # the colorbar says what it shows
    plt.close(fig)
    fig, titles = report.place_fields_figure(folder)
    assert all(t.endswith("60° tilt, seed 0") for t in titles)
    assert all(a.get_xlabel() == "x (m)" and a.get_ylabel() == "y (m)" for a in fig.axes[:2])
    plt.close(fig)
    fig = report.trajectory_figure(folder)
    assert "cross-0, seed 0" in fig.axes[0].get_title() and fig.axes[0].get_xlabel() == "x (m)"
    plt.close(fig)
    fig = report.environments_figure(folder)
    assert [a.get_title().split("\n")[0] for a in fig.axes] == [f"cross-{t}: central walls tilted {t}°"
                                                                for t in (0, 30, 45, 60)]
    assert all(a.get_title().endswith("arena 10 × 10 × 2.5 m (x × y × z)") for a in fig.axes)
    plt.close(fig)


def test_report_states_protocol_durations_seeds_and_analysis(tmp_path):
    (tmp_path / "mixed").mkdir()
    folder = make_experiment(tmp_path / "mixed", sample_hours=lambda tilt, seed: 2.0 if tilt == 60 else 4.0)
    lines = "\n".join(report.setting_lines(folder))
    assert "**Protocol differs between trials**" in lines
    assert ("explore_then_sample: 4 h of exploration with learning on (not recorded), then 4 h of sampling with "
            "learning frozen (recorded) (27 trials)") in lines
    assert "then 2 h of sampling with learning frozen (recorded) (9 trials)" in lines
    assert ("**Analysis** (the same for all 36 trials): d_th 2 m, decoding_templates rate_maps, eps 1 m, gridsize 50, "
            "min_samples 20, quantile 0.1, grid over each trial's trajectory.") in lines
    assert "**Seeds**: 0–2 (3 per condition)" in lines and "mean over seeds ± the sample standard deviation" in lines
    report.write_report(folder, [])
    text = (tmp_path / "mixed" / "report.md").read_text()
    assert lines in text


def test_the_paper_report_lists_its_bar_figures_from_the_metric_table(three_seeds, monkeypatch):
    """As the sweep report does, a ground experiment's report draws a bar figure for every metric of the
    table with a title that ground trials report (the figures of old keep their file names), and one
    for a metric added to the table, with no other change."""
    from bvc3d import figures
    fake = {"name": "fake_metric", "heading": "fake", "label": "fake (units)", "title": "A metric only this test has",
            "digits": 2, "dims": 0}
    monkeypatch.setattr(report, "metric_table", [*bvc3d.metric_table, fake])
    monkeypatch.setitem(figures.METRICS, "fake_metric", (fake["label"], fake["title"]))
    drawn = dict(report.make_report(three_seeds.path))
    expected = [report.bar_file(m["name"]) for m in bvc3d.metric_table if m["title"] and m["dims"] in (0, 2)]
    assert expected and set(expected) <= set(drawn)
    assert {"mi_active.png", "mi_mean.png", "mi_multimodal.png", "msai.png", "decoding.png",
            "decoding_coverage.png"} <= set(drawn)
    assert not [m for m in bvc3d.metric_table if m["dims"] == 3 and report.bar_file(m["name"]) in drawn]
    assert drawn["fake_metric.png"] == ("A metric only this test has, per model and tilt. Bars: mean ± sd over 3 "
                                        "seeds (0–2); error bars stop at 0.")
    assert drawn["msai.png"].startswith("Mean spatial aliasing index, per model and tilt: lower is better.")
    path = pathlib.Path(three_seeds.path)
    text = (path / "report.md").read_text()
    for name in drawn:
        assert f"(figures/{name})" in text and (path / "figures" / name).stat().st_size > 1000
