// bvc3d view: the interactive viewer in the browser (docs/viewer.md).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/world/gazebo_world.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "recording_options.hpp"
#include "view/export.hpp"
#include "view/safe_path.hpp"
#include "view/server.hpp"

namespace bvc3d::cli {

namespace {

namespace fs = std::filesystem;

bool is_trial_name(const fs::path& p) { return p.extension() == ".h5"; }
// A world YAML, or a Gazebo world (.world, .sdf: docs/buildings.md).
bool is_world_name(const fs::path& p) {
    return p.extension() == ".yaml" || p.extension() == ".yml" || is_gazebo_file(p.string());
}

// Trial files in a folder (and below it when `recursive`), sorted by path.
std::vector<std::string> list_trials(const fs::path& root, const fs::path& folder, bool recursive) {
    std::vector<std::string> out;
    auto take = [&](const fs::directory_entry& e) {
        if (!e.is_regular_file() || !is_trial_name(e.path())) return;
        // Only files that resolve inside the served folder (a symbolic link out of it is neither listed nor opened).
        const std::string name = view::relative_name(root, e.path());
        if (view::path_inside(root, name)) out.push_back(name);
    };
    if (recursive)
        for (const auto& e : fs::recursive_directory_iterator(folder, fs::directory_options::skip_permission_denied))
            take(e);
    else
        for (const auto& e : fs::directory_iterator(folder)) take(e);
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<std::string> list_worlds(const fs::path& root) {
    std::vector<std::string> out = config::world_preset_names();
    if (root.empty()) return out;
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(root))
        if (e.is_regular_file() && is_world_name(e.path()) &&
            view::path_inside(root, view::relative_name(root, e.path())))
            files.push_back(view::relative_name(root, e.path()));
    std::sort(files.begin(), files.end());
    out.insert(out.end(), files.begin(), files.end());
    return out;
}

fs::path common_folder(const fs::path& a, const fs::path& b) {
    fs::path out;
    for (auto i = a.begin(), j = b.begin(); i != a.end() && j != b.end() && *i == *j; ++i, ++j) out /= *i;
    return out;
}

// What the arguments ask to show (see the command's help).
view::ViewTarget make_target(const std::vector<std::string>& args, const std::string& scans, const std::string& poses,
                             const RecordingOptions& recording, const std::string& model) {
    view::ViewTarget t;
    config::resolve_model(model);  // an unknown model is refused before anything is served
    t.model = model;
    if (scans.empty() != poses.empty()) throw InputError("--scans and --poses go together");
    if (!scans.empty() || recording.has_bag()) {
        for (const auto& p : {scans, poses})
            if (!p.empty() && !fs::exists(p)) throw InputError("'" + p + "' does not exist");
        t.recording = recording.open_any(scans, poses);
    }
    if (args.size() > 2) throw InputError("bvc3d view takes at most two trial files (to compare them)");
    std::vector<fs::path> files;
    for (const auto& a : args) {
        const fs::path p(a);
        std::error_code ec;
        if (fs::is_directory(p, ec)) {
            if (args.size() > 1)
                throw InputError("'" + a + "' is a folder: compare two trial files, or view one folder");
            t.root = fs::canonical(p);
            t.trials = list_trials(t.root, t.root, true);
            if (t.trials.empty()) throw InputError("'" + a + "' holds no trial files (*.h5)");
            t.open = {t.trials.front()};
        } else if (fs::exists(p, ec)) {
            if (is_world_name(p)) {
                if (args.size() > 1) throw InputError("a world file is viewed on its own");
                t.root = fs::canonical(p).parent_path();
                t.world = p.filename().string();
            } else if (is_trial_name(p)) {
                files.push_back(fs::canonical(p));
            } else {
                throw InputError("'" + a +
                                 "' is neither a trial file (.h5), a results folder nor a world (.yaml, .world, .sdf)");
            }
        } else {
            const auto presets = config::world_preset_names();
            if (std::find(presets.begin(), presets.end(), a) != presets.end() && args.size() == 1) {
                t.world = a;
            } else {
                std::string names;
                for (const auto& n : presets) names += (names.empty() ? "" : ", ") + n;
                throw InputError("'" + a +
                                 "' does not exist (expected a trial file, a results folder, a world YAML or "
                                 "a world preset: " +
                                 names + ")");
            }
        }
    }
    if (!files.empty()) {
        t.root =
            files.size() == 2 ? common_folder(files[0].parent_path(), files[1].parent_path()) : files[0].parent_path();
        for (const auto& f : files) {
            auto listed = list_trials(t.root, f.parent_path(), false);
            for (auto& l : listed)
                if (std::find(t.trials.begin(), t.trials.end(), l) == t.trials.end()) t.trials.push_back(l);
            t.open.push_back(view::relative_name(t.root, f));
        }
    }
    if (args.empty() && !t.recording) t.world = "cross";
    t.worlds = list_worlds(t.root);
    return t;
}

fs::path web_dir() {
    const char* env = std::getenv("BVC3D_VIEWER_DIR");
    const fs::path dir = env && *env ? fs::path(env) : fs::path(BVC3D_VIEWER_DIR);
    if (!fs::is_regular_file(dir / "viewer.js") || !fs::is_regular_file(dir / "index.html"))
        throw InputError("the viewer's front end is not built in '" + dir.string() +
                         "': run scripts/setup (npm ci) and build again, or set BVC3D_VIEWER_DIR");
    return dir;
}

}  // namespace

void add_view_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("view", "Explore trials, worlds and recordings in the browser (docs/viewer.md)");
    struct Options {
        std::vector<std::string> paths;
        int port = 0;
        std::string export_dir, scans, poses, model = "3d-0.2";
        std::size_t export_steps = 40;
        RecordingOptions recording;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("paths", o->paths,
                    "A trial file (.h5), two to compare side by side, a results folder, a world YAML or Gazebo world, "
                    "or a world preset (default: the cross arena)");
    cmd->add_option("--port", o->port, "Port on 127.0.0.1 (default: a free one)")->check(CLI::Range(0, 65535));
    cmd->add_option("--scans", o->scans,
                    "A recording's scans: a folder of .pcd/.ply/.bin files or a scan list (with a replay's trial "
                    "file: the recording it replayed, when it is not found beside it)");
    cmd->add_option("--poses", o->poses, "The recording's sensor poses (KITTI, TUM or 4x4 matrices)");
    o->recording.add_to(*cmd);
    add_model_option(*cmd, o->model, ModelCount::one, "--model",
                     "Whose scanner and BVCs the page of a recording or a world shows: ");
    o->outputs.add(*cmd, "--export", o->export_dir, OutputKind::folder,
                   "Write the page as static files into this folder instead of serving it (--force replaces only a "
                   "page exported earlier)");
    cmd->add_option("--export-steps", o->export_steps,
                    "Samples per trial (or scans) whose returns and rates are exported")
        ->capture_default_str()
        ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
    cmd->footer(
        "Serves the page on http://127.0.0.1:PORT/ only (never on other interfaces), read-only, until Ctrl-C.\n"
        "Everything the page uses is installed with bvc3d; it fetches nothing from elsewhere.");
    cmd->callback([o] {
        view::ViewData data(make_target(o->paths, o->scans, o->poses, o->recording, o->model));
        const fs::path web = web_dir();
        if (!o->export_dir.empty()) {
            const auto s = view::export_view(data, web, o->export_dir, o->export_steps, o->outputs.force);
            std::printf("wrote %s: open %s/index.html (%zu data files, %.1f MB, %zu steps)\n", o->export_dir.c_str(),
                        o->export_dir.c_str(), s.files, s.bytes / 1e6, s.steps);
            return;
        }
        InterruptGuard guard;
        view::serve(data, web, o->port, stop_flag(), [&](int port) {
            const auto& target = data.target();
            const std::string served = !target.root.empty()    ? target.root.string()
                                       : !target.world.empty() ? target.world
                                       : target.recording      ? "recording '" + target.recording->name + "'"
                                                               : std::string("the page");
            std::printf("bvc3d view: serving %s at http://127.0.0.1:%d/ (Ctrl-C stops)\n", served.c_str(), port);
            std::fflush(stdout);
        });
        std::printf("bvc3d view: stopped\n");
    });
}

}  // namespace bvc3d::cli
