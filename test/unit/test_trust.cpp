// Faults end cleanly (issue 13): write failures name the file and the reason and leave nothing
// half-written (and HDF5 holds no file open afterwards), locks, broken checkpoints, cancellation,
// seeds over their whole range, limits checked before work.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/sweep_yaml.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/output_lock.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/world/mesh_check.hpp"

namespace fs = std::filesystem;
using namespace bvc3d;

namespace {

fs::path fresh_dir(const std::string& name) {
    const auto d = fs::temp_directory_path() / ("bvc3d-trust-" + std::to_string(::getpid()) + "-" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// Files may grow to `bytes` within the scope (RLIMIT_FSIZE); past it, write(2) fails with EFBIG.
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);
        ::getrlimit(RLIMIT_FSIZE, &previous_);
        rlimit limit = previous_;
        limit.rlim_cur = bytes;
        ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &previous_);
        std::signal(SIGXFSZ, previous_handler_);
    }

private:
    rlimit previous_{};
    void (*previous_handler_)(int) = nullptr;
};

std::size_t entries(const fs::path& d) {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
}

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

GroupResult tiny_group(std::size_t samples) {
    GroupResult g;
    for (std::size_t i = 0; i < samples; ++i) {
        g.t.push_back(0.288 * i);
        g.x.push_back(std::sin(0.01 * i));
        g.y.push_back(std::cos(0.01 * i));
        g.z.push_back(0);
        g.heading.push_back(0.1 * i);
    }
    ModelRecord m;
    m.n_place = 20;
    m.n_bvc = 30;
    for (std::size_t i = 0; i < samples * 20; ++i) m.rates.push_back(static_cast<float>((i * 7919) % 1000) / 1000.0f);
    m.weights.assign(20 * 30, 0.5f);
    g.models.push_back(m);
    return g;
}

}  // namespace

TEST(WriteFailures, AtomicFileNamesTheFileAndTheReasonAndLeavesNothing) {
    const auto d = fresh_dir("atomic");
    const auto target = d / "table.csv";
    const std::string msg = message_of([&] {
        FileSizeLimit limit(1000);
        AtomicFile f(target);
        for (int i = 0; i < 10000; ++i) f.stream() << "row " << i << ",0.123456789\n";
        f.commit();
    });
    EXPECT_NE(msg.find("cannot write '" + target.string() + "'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("File too large"), std::string::npos) << msg;
    EXPECT_EQ(entries(d), 0u);
    // The same through write().
    const std::string again = message_of([&] {
        FileSizeLimit limit(100);
        AtomicFile f(target);
        f.write(std::string(5000, 'x'));
        f.commit();
    });
    EXPECT_NE(again.find("File too large"), std::string::npos) << again;
    EXPECT_EQ(entries(d), 0u);
    fs::remove_all(d);
}

TEST(WriteFailures, TrialFilesAndCheckpointsFailCleanlyAndHdf5KeepsNothingOpen) {
    const auto d = fresh_dir("hdf5");
    const GroupResult g = tiny_group(2000);
    TrialIdentity id;
    id.name = "t";
    id.seed = 18446744073709551615ull;
    const std::string msg = message_of([&] {
        FileSizeLimit limit(20000);
        write_trial_file(d / "t.h5", id, g, 0, MetricsRecord{});
    });
    EXPECT_NE(msg.find("cannot write '" + (d / "t.h5").string() + "': File too large"), std::string::npos) << msg;
    GroupCheckpoint c;
    c.fingerprint = "f";
    c.partial = g;
    c.states.assign(2, {StateArray{"membrane", {20}, std::vector<float>(20, 0.0f)}});
    const std::string ckpt = message_of([&] {
        FileSizeLimit limit(20000);
        write_checkpoint(d / "c.h5", c);
    });
    EXPECT_NE(ckpt.find("c.h5.seg0': File too large"), std::string::npos) << ckpt;
    EXPECT_EQ(entries(d), 0u);
    EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);  // nothing left for HDF5's exit handler
    // With room, the same calls work, and the largest seed comes back unchanged.
    write_trial_file(d / "t.h5", id, g, 0, MetricsRecord{});
    EXPECT_EQ(read_trial_samples(d / "t.h5").seed, 18446744073709551615ull);
    fs::remove_all(d);
}

TEST(Locks, OneHolderAtATimeAndReleasedOnDestruction) {
    const auto d = fresh_dir("lock");
    {
        const OutputLock first(folder_lock_path(d), "output folder 'x'");
        const std::string msg = message_of([&] { OutputLock second(folder_lock_path(d), "output folder 'x'"); });
        EXPECT_NE(msg.find("output folder 'x' is in use by bvc3d process " + std::to_string(::getpid())),
                  std::string::npos)
            << msg;
    }
    EXPECT_FALSE(fs::exists(folder_lock_path(d)));
    EXPECT_NO_THROW(OutputLock(folder_lock_path(d), "output folder 'x'"));
    fs::remove_all(d);
}

TEST(Checkpoints, BrokenOnesSayWhatIsWrong) {
    const auto d = fresh_dir("ckpt");
    EXPECT_EQ(read_checkpoint(d / "none.h5").problem, "");  // no checkpoint: nothing to say
    GroupCheckpoint c;
    c.fingerprint = "f";
    c.partial = tiny_group(50);
    c.states.assign(2, {StateArray{"membrane", {20}, std::vector<float>(20, 0.0f)}});
    write_checkpoint(d / "c.h5", c);
    const auto good = read_checkpoint(d / "c.h5");
    ASSERT_TRUE(good.checkpoint) << good.problem;
    EXPECT_EQ(good.checkpoint->partial.t.size(), 50u);
    fs::remove(d / "c.h5.seg0");
    EXPECT_NE(read_checkpoint(d / "c.h5").problem.find("c.h5.seg0' is missing"), std::string::npos);
    std::ofstream(d / "c.h5", std::ios::trunc) << "garbage";
    const auto broken = read_checkpoint(d / "c.h5");
    EXPECT_FALSE(broken.checkpoint);
    EXPECT_NE(broken.problem.find("checkpoint '" + (d / "c.h5").string() + "' is unreadable"), std::string::npos)
        << broken.problem;
    fs::remove_all(d);
}

TEST(Cancellation, PollThrowsOnlyInsideAScopeWithItsFlagSet) {
    std::atomic<bool> stop{false};
    EXPECT_NO_THROW(poll_cancel());
    {
        const CancelScope scope(&stop);
        EXPECT_NO_THROW(poll_cancel());
        stop = true;
        EXPECT_THROW(poll_cancel(), Interrupted);
    }
    EXPECT_NO_THROW(poll_cancel());
}

TEST(Seeds, EveryValueOfSixtyFourBitsAndNothingElse) {
    const auto seed_of = [](const std::string& text) {
        return config::trial_from_yaml(
                   config::YamlView::load_string("seed: " + text + "\nprotocol: {sample_hours: 0.01}\n", "t.yaml"))
            .seed;
    };
    EXPECT_EQ(seed_of("0"), 0u);
    EXPECT_EQ(seed_of("18446744073709551615"), 18446744073709551615ull);
    for (const char* bad : {"-1", "18446744073709551616", "1.5", "1e3", "0x10", "seven"})
        EXPECT_THROW(seed_of(bad), ConfigError) << bad;
}

TEST(Limits, AHugeSweepGridIsRefusedBeforeItIsBuilt) {
    const auto d = fresh_dir("sweep");
    std::ofstream f(d / "s.yaml");
    f << "grid:\n";
    for (int k = 0; k < 10; ++k) f << "  key" << k << ": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n";  // counted before read
    f.close();
    const std::string msg = message_of([&] { config::load_sweep_file((d / "s.yaml").string()); });
    EXPECT_NE(msg.find("1e+10 conditions; the limit is 100000"), std::string::npos) << msg;
    fs::remove_all(d);
}

TEST(MeshChecks, ValidFilesPassAndTheHeaderMustMatchTheData) {
    for (const char* name : {"panel.ply", "panel.obj", "panel.stl"}) {
        std::ifstream in(fs::path(BVC3D_SOURCE_DIR) / "test/data" / name, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), {});
        EXPECT_NO_THROW(check_mesh_file(name, bytes)) << name;
    }
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 100\nproperty float x\nproperty float y\n"
        "property float z\nelement face 50\nproperty list uchar int vertex_indices\nend_header\n";
    EXPECT_THROW(check_mesh_file("a.ply", header + "0 0 0\n1 0 1\n0 1 1\n"), InputError);
    EXPECT_THROW(check_mesh_file("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), InputError);
    EXPECT_NO_THROW(check_mesh_file("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -3 -2 -1\n"));
    EXPECT_THROW(check_mesh_file("a.stl", std::string(84, '\0') + "x"), InputError);
}

// Issue 32: output paths with a trailing slash, and nothing left behind by an output not written.
TEST(Outputs, TrailingSlashesNameTheFolderOrFile) {
    EXPECT_EQ(without_trailing_slash("walk/"), fs::path("walk"));
    EXPECT_EQ(without_trailing_slash("a/walk//"), fs::path("a/walk"));
    EXPECT_EQ(without_trailing_slash("/"), fs::path("/"));
    EXPECT_EQ(without_trailing_slash("walk.csv"), fs::path("walk.csv"));
}

TEST(Outputs, AnAtomicFolderLeavesNothingUnlessCommittedAndReplacesOnCommit) {
    const fs::path dir = fresh_dir("atomic-folder");
    {
        AtomicFolder out(dir / "new" / "deeper" / "walk/");
        std::ofstream(out.temp_path() / "a.txt") << "a";
        EXPECT_TRUE(fs::exists(dir / "new" / "deeper"));
    }  // an error before commit: the temporary and the folders made for it are gone
    EXPECT_TRUE(fs::is_empty(dir));
    fs::create_directories(dir / "walk");
    std::ofstream(dir / "walk" / "old.txt") << "old";
    {
        AtomicFolder out(dir / "walk/");
        std::ofstream(out.temp_path() / "new.txt") << "new";
        out.commit();
    }
    EXPECT_TRUE(fs::exists(dir / "walk" / "new.txt"));
    EXPECT_FALSE(fs::exists(dir / "walk" / "old.txt"));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
    std::ofstream(dir / "file") << "x";
    EXPECT_THROW(AtomicFolder(dir / "file" / "walk"), InputError);  // below a file: a clear error
    fs::remove_all(dir);
}

TEST(Outputs, AFailedAtomicFileRemovesTheFoldersMadeForIt) {
    const fs::path dir = fresh_dir("atomic-file");
    { AtomicFile f(dir / "a" / "b" / "out.csv/"); }
    EXPECT_TRUE(fs::is_empty(dir));
    {
        AtomicFile f(dir / "a" / "out.csv/");
        f.write("x");
        f.commit();
    }
    EXPECT_TRUE(fs::is_regular_file(dir / "a" / "out.csv"));
    fs::remove_all(dir);
}

// Issue 32: a trajectory's rows resampled to the model step. Two rows 1 s apart: the steps at 0, 0.288,
// 0.576, 0.864 s lie at fractions 0, 0.288, 0.576, 0.864 of the way; heading and roll cross ±π along the
// shorter arc (3 rad to −3 rad is 0.283 rad through π), pitch and positions move linearly.
TEST(TrajectoryResampling, InterpolatesPosesBetweenRows) {
    const double h0 = 3.0, h1 = -3.0, arc = 2 * std::acos(-1.0) - 6.0;  // from h0 to h1 the short way
    std::vector<ModelStep> rows(2);
    rows[0].t = 10.0;
    rows[0].pose = Pose{0.0, 1.0, 0.5, h0, -0.2, h0};
    rows[1].t = 11.0;
    rows[1].pose = Pose{2.0, -1.0, 1.5, h1, 0.4, h1};
    const auto steps = resample_steps(rows, 0.288, "two rows");
    ASSERT_EQ(steps.size(), 4u);
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const double f = 0.288 * static_cast<double>(k);
        EXPECT_NEAR(steps[k].t, f, 1e-12);
        EXPECT_NEAR(steps[k].pose.x, 2 * f, 1e-12);
        EXPECT_NEAR(steps[k].pose.y, 1 - 2 * f, 1e-12);
        EXPECT_NEAR(steps[k].pose.z, 0.5 + f, 1e-12);
        EXPECT_NEAR(steps[k].pose.pitch, -0.2 + 0.6 * f, 1e-12);
        const double expected = std::remainder(h0 + f * arc, 2 * std::acos(-1.0));
        EXPECT_NEAR(std::remainder(steps[k].pose.heading - expected, 2 * std::acos(-1.0)), 0, 1e-12);
        EXPECT_NEAR(std::remainder(steps[k].pose.roll - expected, 2 * std::acos(-1.0)), 0, 1e-12);
    }
    EXPECT_FALSE(rows_at_model_step(rows, 0.288));
    EXPECT_TRUE(rows_at_model_step(rows, 1.0));
    // Rows at the model step are the steps, unchanged.
    const TrajectorySpec at_step(steps, "steps", TrajectoryParams{});
    EXPECT_FALSE(at_step.resampled());
    const TrajectorySpec off_step(rows, "rows", TrajectoryParams{});
    EXPECT_TRUE(off_step.resampled());
    EXPECT_EQ(off_step.steps().size(), 4u);
    TrajectoryParams per_row;
    per_row.step_per_row = true;
    EXPECT_FALSE(TrajectorySpec(rows, "rows", per_row).resampled());
}
