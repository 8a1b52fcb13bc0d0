"""Broken trial files, each made from one good trial file (run.py makes it with `bvc3d run`): one
function per case. `bvc3d analyze` and `bvc3d summarize` must refuse each with a message naming
the file and the dataset or attribute."""
import h5py
import numpy as np

CASES = []


def case(cmd, *expect):
    def register(make):
        CASES.append((make.__name__.replace("_", "-"), make, cmd, list(expect)))
        return make
    return register


def edit(path, fn):
    with h5py.File(path, "r+") as f:
        fn(f)


def replace(f, name, data):
    del f[name]
    f[name] = data


@case("analyze {}", "is not an HDF5 file")
def text_file(path):
    path.write_text("t,x,y\n0,0,0\n")


@case("analyze {}", "is not an HDF5 file")
def truncated(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


@case("analyze {}", "is not an HDF5 file")
def empty(path):
    path.write_bytes(b"")


@case("analyze {}", "is not a bvc3d trial file")
def wrong_format(path):
    edit(path, lambda f: f.attrs.__setitem__("format", "bvc3d-checkpoint"))


@case("analyze {}", "is not a bvc3d trial file")
def no_format(path):
    edit(path, lambda f: f.attrs.__delitem__("format"))


@case("analyze {}", "format_version 99 is not supported")
def future_version(path):
    edit(path, lambda f: f.attrs.__setitem__("format_version", np.int64(99)))


@case("analyze {}", "format_version 0 is not supported")
def version_zero(path):
    edit(path, lambda f: f.attrs.__setitem__("format_version", np.int64(0)))


@case("analyze {}", "'format_version' is not an integer")
def version_text(path):
    edit(path, lambda f: f.attrs.__setitem__("format_version", "one"))


@case("analyze {}", "group '/samples' is missing")
def no_samples(path):
    edit(path, lambda f: f.__delitem__("samples"))


@case("analyze {}", "dataset '/samples/x' is missing")
def no_x(path):
    edit(path, lambda f: f.__delitem__("samples/x"))


@case("analyze {}", "dataset '/samples/rates' is missing")
def no_rates(path):
    edit(path, lambda f: f.__delitem__("samples/rates"))


@case("analyze {}", "'/samples/x'", "floating-point")
def x_as_text(path):
    edit(path, lambda f: replace(f, "samples/x", np.array([b"a"] * f["samples/x"].shape[0])))


@case("analyze {}", "'/samples/y'", "floating-point")
def y_as_integers(path):
    edit(path, lambda f: replace(f, "samples/y", np.zeros(f["samples/y"].shape[0], dtype=np.int64)))


@case("analyze {}", "'/samples/x' has 2 dimensions")
def x_2d(path):
    edit(path, lambda f: replace(f, "samples/x", np.zeros((f["samples/x"].shape[0], 2))))


@case("analyze {}", "'/samples/x' and '/samples/y' differ in length")
def x_short(path):
    edit(path, lambda f: replace(f, "samples/x", f["samples/x"][:-3]))


@case("analyze {}", "'/samples/rates' has 1 dimensions")
def rates_1d(path):
    edit(path, lambda f: replace(f, "samples/rates", f["samples/rates"][:, 0]))


@case("analyze {}", "'/samples/rates' has", "rows for")
def rates_rows(path):
    edit(path, lambda f: replace(f, "samples/rates", f["samples/rates"][:-1]))


@case("analyze {}", "'/samples/rates' has no cells")
def rates_no_cells(path):
    edit(path, lambda f: replace(f, "samples/rates", np.zeros((f["samples/x"].shape[0], 0), dtype=np.float32)))


@case("analyze {}", "'/samples/x' holds a non-finite value", "sample 5")
def nan_position(path):
    def fn(f):
        x = f["samples/x"][:]
        x[5] = np.nan
        replace(f, "samples/x", x)
    edit(path, fn)


@case("analyze {}", "'/samples/rates' holds a non-finite value", "sample 2, column 7")
def inf_rate(path):
    def fn(f):
        r = f["samples/rates"][:]
        r[2, 7] = np.inf
        replace(f, "samples/rates", r)
    edit(path, fn)


@case("analyze {}", "'/seed'", "negative")
def negative_seed(path):
    edit(path, lambda f: f.attrs.__setitem__("seed", np.int64(-1)))


@case("analyze {}", "'/seed'", "not an integer")
def float_seed(path):
    edit(path, lambda f: f.attrs.__setitem__("seed", 1.5))


@case("analyze {}", "attribute '/name' is missing")
def no_name(path):
    edit(path, lambda f: f.attrs.__delitem__("name"))


@case("analyze {}", "attribute '/world' is not text")
def world_number(path):
    edit(path, lambda f: f.attrs.__setitem__("world", 3.0))


@case("analyze {}", "group '/metrics' is missing")
def no_metrics(path):
    edit(path, lambda f: f.__delitem__("metrics"))


@case("analyze {}", "'/metrics/gridsize'", "must be in [2, 2000]")
def gridsize_one(path):
    edit(path, lambda f: f["metrics"].attrs.__setitem__("gridsize", np.int64(1)))


@case("analyze {}", "'/metrics/gridsize'", "wrong type")
def gridsize_text(path):
    edit(path, lambda f: f["metrics"].attrs.__setitem__("gridsize", "fifty"))


@case("analyze {}", "'/metrics/quantile'", "must be in [0, 1]")
def quantile_nan(path):
    edit(path, lambda f: f["metrics"].attrs.__setitem__("quantile", np.nan))


@case("analyze {}", "'/metrics/decoding_templates'", "rate_maps, means")
def templates_unknown(path):
    edit(path, lambda f: f["metrics"].attrs.__setitem__("decoding_templates", "medians"))


@case("analyze {}", "'/metrics/extent' holds 3 values")
def extent_three(path):
    edit(path, lambda f: f["metrics"].__setitem__("extent", np.array([0.0, 1.0, 2.0])))


@case("analyze {}", "'/metrics/extent' needs xmin < xmax")
def extent_inverted(path):
    edit(path, lambda f: f["metrics"].__setitem__("extent", np.array([5.0, -5.0, -5.0, 5.0])))


@case("analyze {} --extent arena", "--extent arena", "cannot be loaded again")
def extent_arena_world_gone(path):
    edit(path, lambda f: f.attrs.__setitem__("world_source", "/no/such/world.yaml"))


@case("summarize {dir}/broken-folder --no-report", "is not an HDF5 file", "--skip-unreadable")
def summarize_broken(path):
    folder = path.parent / "broken-folder"
    folder.mkdir()
    (folder / "good.h5").write_bytes(path.read_bytes())
    (folder / path.name).write_bytes(b"not hdf5")


@case("summarize {dir}/mixed-folder --no-report", "differ in sample_hours", "--allow-mixed")
def summarize_mixed(path):
    folder = path.parent / "mixed-folder"
    folder.mkdir()
    (folder / "a.h5").write_bytes(path.read_bytes())
    edit(path, lambda f: f.attrs.__setitem__("sample_hours", 4.0))
    (folder / path.name).write_bytes(path.read_bytes())


@case("summarize {dir}/gridsize-folder --no-report", "differ in analysis gridsize", "--allow-mixed")
def summarize_mixed_analysis(path):
    folder = path.parent / "gridsize-folder"
    folder.mkdir()
    (folder / "a.h5").write_bytes(path.read_bytes())
    edit(path, lambda f: f["metrics"].attrs.__setitem__("gridsize", np.int64(30)))
    (folder / path.name).write_bytes(path.read_bytes())


@case("replay --world cross --trajectory {dir}/track.csv --sensor spherical --model 3d-0.1 --weights {} "
      "--out {dir}/out.h5", "weights-of-another-model.h5", "trained by model '3d-0.2'", "bvc.elevations")
def weights_of_another_model(path):
    """The good file's weights are 3d-0.2's, 250 × 960 as 3d-0.1's: the shapes agree, the BVCs do not."""
    (path.parent / "track.csv").write_text("t,x,y,heading\n0,-4,-4,0\n0.288,-3.856,-4,0\n")


def cases():
    return CASES
