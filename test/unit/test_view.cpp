// bvc3d view's pieces that need no browser: the recorder's reading of any dataset, which request
// paths are inside the served folder, the blob layout, and the data API's error statuses.
// (The page and the HTTP server are tested end to end in test/browser.)
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "view/blob.hpp"
#include "view/safe_path.hpp"
#include "view/view_data.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
    const auto d = fs::temp_directory_path() / ("bvc3d_view_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// A short trial file with BVC rates recorded, in `dir`.
fs::path short_trial(const fs::path& dir) {
    TrialConfig t;
    t.world.tilt_deg = 30;
    t.protocol.explore_hours = t.protocol.sample_hours = 0.01;
    t.protocol.record_bvc = true;
    ExperimentOptions opts;
    opts.out_dir = dir;
    return run_experiment({t}, opts).files.at(0);
}

}  // namespace

TEST(TrialFileArrays, AnyDatasetAsStored) {
    const auto dir = temp_dir("arrays");
    const auto file = short_trial(dir);
    const auto samples = read_trial_samples(file);
    const auto heading = read_trial_array(file, "samples/heading");
    ASSERT_TRUE(heading);
    EXPECT_EQ(heading->shape, std::vector<std::size_t>{samples.x.size()});
    EXPECT_TRUE(std::holds_alternative<std::vector<double>>(heading->data));
    const auto rates = read_trial_array(file, "samples/rates");
    ASSERT_TRUE(rates);
    EXPECT_EQ(rates->shape, (std::vector<std::size_t>{samples.x.size(), samples.n_place}));
    EXPECT_EQ(std::get<std::vector<float>>(rates->data), samples.rates);
    const auto modality = read_trial_array(file, "metrics/modality");
    ASSERT_TRUE(modality);
    EXPECT_EQ(std::get<std::vector<std::int64_t>>(modality->data).size(), samples.n_place);
    const auto weights = read_trial_array(file, "weights");
    ASSERT_TRUE(weights);
    EXPECT_EQ(weights->shape.at(0), samples.n_place);
    EXPECT_FALSE(read_trial_array(file, "metrics/nothing"));
    EXPECT_FALSE(read_trial_array(file, "nothing/x"));
    EXPECT_FALSE(read_trial_array(file, "samples/"));
    std::ofstream(dir / "broken.h5") << "not hdf5";
    EXPECT_THROW(read_trial_array(dir / "broken.h5", "samples/x"), InputError);
    EXPECT_THROW(read_trial_array(dir / "missing.h5", "samples/x"), InputError);
    fs::remove_all(dir);
}

TEST(ViewPaths, OnlyInsideTheServedFolder) {
    const auto dir = temp_dir("paths");
    fs::create_directories(dir / "a" / "b");
    std::ofstream(dir / "a" / "t.h5") << "x";
    fs::create_directory_symlink("/etc", dir / "a" / "out");
    fs::create_directory_symlink(dir / "a" / "b", dir / "in");
    const auto canonical = fs::canonical(dir);
    EXPECT_EQ(view::path_inside(dir, "a/t.h5"), canonical / "a" / "t.h5");
    EXPECT_EQ(view::path_inside(dir, "a/./t.h5"), canonical / "a" / "t.h5");
    EXPECT_EQ(view::path_inside(dir, "in"), canonical / "a" / "b");             // a link that stays inside
    EXPECT_EQ(view::path_inside(dir, "not-yet.h5"), canonical / "not-yet.h5");  // missing is the caller's 404
    for (const char* bad :
         {"", "/etc/passwd", "../x", "a/../../x", "a/..", "..", "a/out/passwd", "a\\..\\..\\x", "//etc"})
        EXPECT_FALSE(view::path_inside(dir, bad)) << bad;
    EXPECT_FALSE(view::path_inside(dir, std::string_view("a/t.h5\0/../../x", 15)));
    EXPECT_EQ(view::relative_name(dir, dir / "a" / "t.h5"), "a/t.h5");
    fs::remove_all(dir);
}

TEST(ViewBlobs, HeaderThenAlignedLittleEndianArrays) {
    const std::vector<float> f{1.5f, -2.0f, 3.25f};
    const std::vector<std::uint8_t> u{7, 8, 9, 10, 11};
    const std::vector<double> d{0.1, 0.2};
    const std::string blob =
        view::encode_blob({{"kind", "test"}}, {view::f32_array("f", std::span<const float>(f)), view::u8_array("u", u),
                                               view::f64_array("d", std::span<const double>(d), {1, 2})});
    ASSERT_EQ(blob.substr(0, 4), "BVC3");
    std::uint32_t length = 0;
    std::memcpy(&length, blob.data() + 4, 4);
    EXPECT_EQ(length % 8, 0u);
    const auto header = nlohmann::json::parse(blob.substr(8, length));
    EXPECT_EQ(header["kind"], "test");
    const auto& arrays = header["arrays"];
    ASSERT_EQ(arrays.size(), 3u);
    const std::size_t base = 8 + length;
    for (const auto& a : arrays) EXPECT_EQ((base + a["offset"].get<std::size_t>()) % 8, 0u) << a["name"];
    std::vector<float> f_back(3);
    std::memcpy(f_back.data(), blob.data() + base + arrays[0]["offset"].get<std::size_t>(), 12);
    EXPECT_EQ(f_back, f);
    EXPECT_EQ(blob.substr(base + arrays[1]["offset"].get<std::size_t>(), 5), std::string("\x07\x08\x09\x0a\x0b"));
    double d1 = 0;
    std::memcpy(&d1, blob.data() + base + arrays[2]["offset"].get<std::size_t>() + 8, 8);
    EXPECT_EQ(d1, 0.2);
    EXPECT_EQ(arrays[2]["shape"], nlohmann::json::array({1, 2}));
    EXPECT_EQ(blob.size(), base + 16 + 8 + 16);
}

TEST(ViewData, ErrorsAreRepliesWithAStatus) {
    const auto dir = temp_dir("data");
    const auto file = short_trial(dir);
    std::ofstream(dir / "broken.h5") << "not hdf5";
    view::ViewTarget target;
    target.root = dir;
    target.trials = {file.filename().string(), "broken.h5"};
    view::ViewData data(target);
    const std::string name = file.filename().string();
    EXPECT_EQ(data.get("index", {}).status, 200);
    const auto trial = data.get("trial", {{"path", name}});
    EXPECT_EQ(trial.status, 200);
    EXPECT_EQ(trial.content_type, "application/octet-stream");
    EXPECT_EQ(data.get("step", {{"path", name}, {"i", "0"}}).status, 200);
    EXPECT_EQ(data.get("world", {{"trial", name}}).status, 200);
    EXPECT_EQ(data.get("world", {{"source", "cross-45"}}).status, 200);
    EXPECT_EQ(data.get("step", {{"path", name}, {"i", "100000000"}}).status, 404);
    EXPECT_EQ(data.get("step", {{"path", name}, {"i", "x"}}).status, 400);
    EXPECT_EQ(data.get("step", {{"path", name}}).status, 400);
    EXPECT_EQ(data.get("trial", {{"path", "../" + name}}).status, 403);
    EXPECT_EQ(data.get("trial", {{"path", "missing.h5"}}).status, 404);
    EXPECT_EQ(data.get("trial", {{"path", "broken.h5"}}).status, 422);
    EXPECT_EQ(data.get("world", {{"source", "/etc/passwd"}}).status, 403);
    EXPECT_EQ(data.get("probe", {{"source", "cross-45"}, {"x", "1"}, {"y", "-2.5"}, {"heading", "0.3"}}).status, 200);
    EXPECT_EQ(data.get("probe", {{"source", "cross-45"}, {"x", "nan"}, {"y", "0"}, {"heading", "0"}}).status, 400);
    EXPECT_EQ(data.get("probe", {{"source", "cross-45"}, {"x", "1m"}, {"y", "0"}, {"heading", "0"}}).status, 400);
    EXPECT_EQ(data.get("probe", {{"source", "../w.yaml"}, {"x", "1"}, {"y", "0"}, {"heading", "0"}}).status, 403);
    EXPECT_EQ(data.get("recording", {}).status, 404);
    EXPECT_EQ(data.get("nothing", {}).status, 404);
    const auto error = nlohmann::json::parse(data.get("trial", {{"path", "broken.h5"}}).body);
    EXPECT_NE(error["error"].get<std::string>().find("broken.h5"), std::string::npos);
    // A trial or world file that is a folder is said to be one (issue 43), not "does not exist".
    fs::create_directory(dir / "folder.h5");
    fs::create_directory(dir / "folder.yaml");
    for (const auto& [endpoint, query] : {std::pair{"trial", view::Query{{"path", "folder.h5"}}},
                                          std::pair{"world", view::Query{{"source", "folder.yaml"}}}}) {
        const auto reply = data.get(endpoint, query);
        EXPECT_EQ(reply.status, 422) << endpoint;
        EXPECT_NE(nlohmann::json::parse(reply.body)["error"].get<std::string>().find("is a folder"), std::string::npos)
            << reply.body;
    }
    fs::remove_all(dir);
}
