#include "bvc3d/world/gazebo_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>

// SDFormat's headers are not warning-clean under our flags (and use deprecated members of their own).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#include <sdf/sdf.hh>
#pragma GCC diagnostic pop
#include <console_bridge/console.h>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

namespace fs = std::filesystem;
using Iso = Eigen::Isometry3d;

// Where a reader of the SDF files is sent: a file, a line, an element path.
struct Place {
    std::string file;
    int line = 0;
    std::string path;
    std::string str() const {
        std::string s = file.empty() ? std::string("<SDF>") : "'" + file + "'";
        if (line > 0) s += ", line " + std::to_string(line);
        if (!path.empty()) s += ", " + path;
        return s;
    }
};

[[noreturn]] void fail(const Place& at, const std::string& reason) { throw InputError(at.str() + ": " + reason); }

Place place_of(const sdf::ElementPtr& e, std::string path) {
    Place p;
    p.path = std::move(path);
    if (e) {
        p.file = e->FilePath();
        p.line = e->LineNumber().value_or(0);
    }
    return p;
}

Iso to_iso(const ignition::math::Pose3d& p) {
    Iso m = Iso::Identity();
    m.translation() = Vec3(p.Pos().X(), p.Pos().Y(), p.Pos().Z());
    const auto& q = p.Rot();
    m.linear() = Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()).normalized().toRotationMatrix();
    return m;
}

void check_pose(const Iso& pose, const Place& at, const char* what) {
    if (!pose.matrix().allFinite()) fail(at, std::string(what) + " is not finite (NaN or infinite values)");
    if (pose.translation().cwiseAbs().maxCoeff() > max_coordinate)
        fail(at, std::string(what) + " places it at (" + format_number(pose.translation().x()) + ", " +
                     format_number(pose.translation().y()) + ", " + format_number(pose.translation().z()) +
                     "): coordinates must lie within ±" + format_number(max_coordinate) + " m");
}

double size_value(double v, const Place& at, const std::string& what) {
    if (!std::isfinite(v) || v <= 0 || v > max_coordinate)
        fail(at, what + " is " + format_number(v) + ": it must be a finite size above 0 and at most " +
                     format_number(max_coordinate) + " m");
    return v;
}

// ---------------------------------------------------------------------------------------------
// The geometry of one <visual> or <collision>, in the frame of the model it belongs to.

enum class Shape { box, cylinder, sphere, plane, mesh };
const char* shape_name(Shape s) {
    switch (s) {
        case Shape::box:
            return "box";
        case Shape::cylinder:
            return "cylinder";
        case Shape::sphere:
            return "sphere";
        case Shape::plane:
            return "plane";
        case Shape::mesh:
            return "mesh";
    }
    return "";
}

struct Piece {
    std::string path;  // relative to its model: link/visual, nested/link/visual
    Place at;
    Shape shape = Shape::box;
    Vec3 size = Vec3::Zero();  // box; plane: (x, y, 0); cylinder: (radius, radius, length); sphere: radius in x
    Vec3 normal = Vec3::UnitZ();
    std::string mesh_file;
    Vec3 scale = Vec3::Ones();
    Iso pose = Iso::Identity();  // in the model frame
    bool ground_plane = false;
};

// One <include> of model://NAME that SDFormat handed to us (the custom model parser below): a model
// to place by its file's own geometry. Its pose comes from SDFormat's pose graph.
struct Include {
    std::string name;             // its <name>, else NAME (until the model's file is read)
    bool named = false;           // the <include> gave a <name>
    std::string parent;           // the enclosing model's scoped name ("a::b"), "" for the world
    std::string model;            // NAME of model://NAME
    std::string folder;           // the model's folder; "" for a built-in
    bool has_pose = false;        // the <include> gave a <pose> (it replaces the model's own)
    Place at;                     // the <include> element
    Iso frame = Iso::Identity();  // the model frame (without its own pose) in the parsed document's world frame
    bool posed = false;
};

// A model file read once, whatever the number of its includes.
struct Template {
    std::string model;  // NAME
    std::string folder, file;
    std::string name;                // its <model> name
    std::string where;               // the element path of its first <include>, for messages
    Iso own_pose = Iso::Identity();  // its own <pose>, used when an <include> gives none
    std::vector<Piece> pieces;       // in its model frame
    std::vector<Include> includes;   // nested includes, frames in its model frame
    bool builtin = false;
};

constexpr const char* builtin_marker = "/bvc3d-built-in-model/";

// SDFormat writes its messages to one console (a singleton): while we parse, they are kept here
// and quoted in our errors instead of printed. One parse at a time.
std::mutex& sdformat_mutex() {
    static std::mutex m;
    return m;
}

// SDFormat 12 reads the includes inside an included file with its global configuration, not the
// one given to Root::Load. While a loader parses (holding sdformat_mutex), the global configuration's
// find-file callback and model parser ask that loader's; at other times they find nothing and parse
// nothing, as SDFormat's own defaults do.
struct ActiveParse {
    std::function<std::string(const std::string&)>* find = nullptr;
    sdf::CustomModelParser* parser = nullptr;
};
ActiveParse& active_parse() {
    static ActiveParse active;
    return active;
}

class GlobalConfig {
public:
    GlobalConfig(std::function<std::string(const std::string&)>* find, sdf::CustomModelParser* parser) {
        static std::once_flag once;
        std::call_once(once, [] {
            auto& global = sdf::ParserConfig::GlobalConfig();
            global.SetFindCallback([](const std::string& uri) {
                return active_parse().find ? (*active_parse().find)(uri) : std::string();
            });
            global.RegisterCustomModelParser([](const sdf::NestedInclude& include, sdf::Errors& errors) {
                return active_parse().parser ? (*active_parse().parser)(include, errors) : nullptr;
            });
        });
        active_parse() = ActiveParse{find, parser};
    }
    ~GlobalConfig() { active_parse() = ActiveParse{}; }
    GlobalConfig(const GlobalConfig&) = delete;
    GlobalConfig& operator=(const GlobalConfig&) = delete;
};

class ConsoleCapture {
public:
    // urdfdom (SDFormat's fallback for a file it cannot read) logs through console_bridge: quiet
    // meanwhile, then as it was.
    ConsoleCapture() : bridge_level_(console_bridge::getLogLevel()) {
        sdf::Console::Instance()->GetMsgStream().SetStream(&text_);
        console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    }
    ~ConsoleCapture() {
        sdf::Console::Instance()->GetMsgStream().SetStream(&std::cerr);
        console_bridge::setLogLevel(bridge_level_);
    }
    ConsoleCapture(const ConsoleCapture&) = delete;
    ConsoleCapture& operator=(const ConsoleCapture&) = delete;
    // The messages, without their colours and source locations, one per line.
    std::vector<std::string> messages() const {
        std::vector<std::string> out;
        std::istringstream in(text_.str());
        for (std::string line; std::getline(in, line);) {
            std::string clean;
            for (std::size_t i = 0; i < line.size(); ++i) {
                if (line[i] == '\033') {  // an ANSI colour: ESC [ ... m
                    while (i < line.size() && line[i] != 'm') ++i;
                    continue;
                }
                clean += line[i];
            }
            if (const auto close = clean.find("] "); clean.find('[') < close && close != std::string::npos)
                clean = clean.substr(close + 2);  // "Error [Param.cc:576] "
            while (!clean.empty() && std::isspace(static_cast<unsigned char>(clean.back()))) clean.pop_back();
            if (!clean.empty()) out.push_back(clean);
        }
        return out;
    }

private:
    std::ostringstream text_;
    console_bridge::LogLevel bridge_level_;
};

// "/sdf/world[@name="w"]/model[@name="m"]/include[0]/uri" -> "w/m/include/uri"
std::string element_path(const std::string& xml_path) {
    std::string out;
    std::istringstream in(xml_path);
    for (std::string seg; std::getline(in, seg, '/');) {
        if (seg.empty() || seg == "sdf") continue;
        std::string label = seg.substr(0, seg.find('['));
        if (const auto n = seg.find("[@name=\""); n != std::string::npos) {
            const auto end = seg.find('"', n + 8);
            label = seg.substr(n + 8, end == std::string::npos ? std::string::npos : end - n - 8);
        }
        out += (out.empty() ? "" : "/") + label;
    }
    return out;
}

// The text between the first '[' and the last ']' of a message ("" if none).
std::string bracketed(const std::string& m) {
    const auto open = m.find('['), close = m.rfind(']');
    return open == std::string::npos || close == std::string::npos || close < open
               ? ""
               : m.substr(open + 1, close - open - 1);
}

// SDFormat's scoped name "a::b::c" as an element path "a/b/c".
std::string slashed(const std::string& scoped) {
    std::string out;
    for (std::size_t i = 0; i < scoped.size(); ++i) {
        if (scoped.compare(i, 2, "::") == 0) {
            out += '/';
            ++i;
        } else {
            out += scoped[i];
        }
    }
    return out;
}

std::string join(const std::vector<std::string>& items, const std::string& sep) {
    std::string s;
    for (const auto& i : items) s += (s.empty() ? "" : sep) + i;
    return s;
}

// ---------------------------------------------------------------------------------------------

class Loader {
public:
    Loader(const Loader&) = delete;  // its callbacks hold `this`
    Loader& operator=(const Loader&) = delete;
    Loader(const std::string& file, const GazeboOptions& options)
        : file_(file), options_(options), resolver_(file, options) {
        find_ = [this](const std::string& uri) { return find(uri); };
        parser_ = [this](const sdf::NestedInclude& include, sdf::Errors&) { return intercept(include); };
        config_.SetFindCallback(find_);
        config_.RegisterCustomModelParser(parser_);
    }

    GazeboScene load();

private:
    // model://NAME -> the folder's model.config (a file SDFormat does not read as SDF, so that the
    // custom parser gets the include), a marker for the built-in models, or "" (not found).
    std::string find(const std::string& uri) const {
        const std::string scheme = "model://";
        if (uri.rfind(scheme, 0) != 0) return "";
        const std::string name = uri.substr(scheme.size());
        const std::string folder = resolver_.model_folder(name);
        if (!folder.empty()) return (fs::path(folder) / "model.config").string();
        if (name == "ground_plane" || name == "sun") return builtin_marker + name;
        return "";
    }

    sdf::InterfaceModelPtr intercept(const sdf::NestedInclude& inc);
    void parse(sdf::Root& root, const std::function<sdf::Errors(sdf::Root&)>& load);
    void check_errors(const sdf::Errors& errors, const std::vector<std::string>& messages);
    void walk_model(const sdf::Model& m, const Iso& frame, const std::string& path, std::vector<Piece>& out) const;
    void read_geometry(const sdf::Geometry& g, const sdf::ElementPtr& e, const std::string& path, const Iso& pose,
                       std::vector<Piece>& out) const;
    void load_templates();
    void read_templates(const std::vector<std::size_t>& todo);
    sdf::Errors read_into(sdf::Root& root, const std::string& file);
    // The model an include places (read later by load_templates); `where` is the include's element
    // path, for messages about the model's file.
    int template_of(const Include& inc, const std::string& where);
    void expand(const std::vector<Piece>& pieces, const std::vector<Include>& includes, const Iso& frame,
                const std::string& prefix, std::vector<int>& stack);
    void emit(const Piece& piece, const Iso& pose, const std::string& path);
    const TriangleMesh& mesh(const Piece& piece);

    std::string file_;
    GazeboOptions options_;
    GazeboResolver resolver_;
    sdf::ParserConfig config_;
    std::function<std::string(const std::string&)> find_;
    sdf::CustomModelParser parser_;
    std::vector<Include>* includes_ = nullptr;  // the includes of the parse in progress
    sdf::SDFPtr blank_;                         // SDFormat's element descriptions, made once (read_templates)
    std::deque<Template> templates_;            // stable references: expand() recurses while reading it
    std::map<std::string, int> template_by_folder_;
    std::map<std::string, TriangleMesh> meshes_;
    std::set<std::string> files_;
    GazeboScene scene_;
    std::map<double, int> sphere_set_;  // radius -> index in scene_.spheres
};

sdf::InterfaceModelPtr Loader::intercept(const sdf::NestedInclude& inc) {
    // Ours are the models find() gave (their model.config, or a built-in's marker); anything else (a
    // URDF file) SDFormat reads itself, into an ordinary model.
    const std::string& resolved = inc.ResolvedFileName();
    const bool builtin = resolved.rfind(builtin_marker, 0) == 0;
    if (!builtin && fs::path(resolved).filename() != "model.config") return nullptr;
    Include i;
    i.model = inc.Uri().rfind("model://", 0) == 0 ? inc.Uri().substr(8) : inc.Uri();
    i.name = inc.LocalModelName().value_or(i.model);
    i.named = inc.LocalModelName().has_value();
    i.parent = inc.AbsoluteParentName();
    if (!builtin) i.folder = fs::path(resolved).parent_path().string();
    i.has_pose = inc.IncludeRawPose().has_value();
    i.at = place_of(inc.IncludeElement(), "");
    const std::size_t index = includes_->size();
    includes_->push_back(i);
    auto model = std::make_shared<sdf::InterfaceModel>(
        i.name,
        [this, index](const sdf::InterfaceModelPoseGraph& graph) {
            ignition::math::Pose3d pose;
            if (graph.ResolveNestedModelFramePoseInWorldFrame(pose).empty()) {
                (*includes_)[index].frame = to_iso(pose);
                (*includes_)[index].posed = true;
            }
        },
        inc.IsStatic().value_or(true), "__bvc3d_link__");
    model->AddLink(sdf::InterfaceLink("__bvc3d_link__", {}));
    return model;
}

// SDFormat's complaints that do not concern geometry: the world name "world" (reserved since SDF
// 1.7, used by every Gazebo-classic world), inertia (physics), deprecations. Missing models are ours
// to report (or skip).
bool harmless(const sdf::Error& e) {
    switch (e.Code()) {
        case sdf::ErrorCode::LINK_INERTIA_INVALID:
        case sdf::ErrorCode::MODEL_WITHOUT_LINK:  // no link, no geometry (a wrapper of a skipped model)
        case sdf::ErrorCode::ELEMENT_DEPRECATED:
        case sdf::ErrorCode::ATTRIBUTE_DEPRECATED:
        case sdf::ErrorCode::VERSION_DEPRECATED:
            return true;
        case sdf::ErrorCode::RESERVED_NAME:
            return e.Message().find("world name [world]") != std::string::npos;
        default:
            return false;
    }
}

void Loader::check_errors(const sdf::Errors& errors, const std::vector<std::string>& messages) {
    std::vector<const sdf::Error*> fatal;
    for (const auto& e : errors) {
        if (harmless(e)) continue;
        if (e.Code() == sdf::ErrorCode::URI_LOOKUP) {
            const std::string uri = bracketed(e.Message());  // "Unable to find uri[model://NAME]"
            Place at{e.FilePath().value_or(""), e.LineNumber().value_or(0), element_path(e.XmlPath().value_or(""))};
            if (at.path.size() > 4 && at.path.substr(at.path.size() - 4) == "/uri") at.path.resize(at.path.size() - 4);
            if (uri.rfind("model://", 0) == 0 && options_.skip_missing_models) {
                scene_.missing_models.push_back(uri.substr(8) + " at " + at.path);
                continue;
            }
            fail(at, "model '" + uri + "' was not found on the model path (" + join(resolver_.model_path(), ", ") +
                         "): add its folder to model_path or GAZEBO_MODEL_PATH, or leave missing models out "
                         "(missing_models: skip; on the command line --missing-models skip)");
        }
        fatal.push_back(&e);
    }
    // "Failed to load a world" sums up the others: alone, it is about harmless ones.
    const auto summary = [](const sdf::Error* e) { return e->Message().find("Failed to load a world") == 0; };
    if (std::all_of(fatal.begin(), fatal.end(), summary)) return;
    const sdf::Error& e = **std::find_if(fatal.begin(), fatal.end(), [&](const sdf::Error* x) { return !summary(x); });
    Place at{e.FilePath().value_or(""), e.LineNumber().value_or(0), element_path(e.XmlPath().value_or(""))};
    if (at.file.empty()) at.file = file_;
    std::string reason = e.Message();
    if (!messages.empty()) reason += " (SDFormat: " + join(messages, "; ") + ")";
    fail(at, reason);
}

void Loader::parse(sdf::Root& root, const std::function<sdf::Errors(sdf::Root&)>& load) {
    sdf::Errors errors;
    std::vector<std::string> messages;
    {
        ConsoleCapture capture;
        GlobalConfig global(&find_, &parser_);
        errors = load(root);
        messages = capture.messages();
    }
    check_errors(errors, messages);
}

void Loader::read_geometry(const sdf::Geometry& g, const sdf::ElementPtr& e, const std::string& path, const Iso& pose,
                           std::vector<Piece>& out) const {
    Piece p;
    p.path = path;
    p.at = place_of(e, path);
    p.pose = pose;
    switch (g.Type()) {
        case sdf::GeometryType::EMPTY:
            return;
        case sdf::GeometryType::BOX: {
            const auto s = g.BoxShape()->Size();
            p.shape = Shape::box;
            p.size = Vec3(size_value(s.X(), p.at, "box size x"), size_value(s.Y(), p.at, "box size y"),
                          size_value(s.Z(), p.at, "box size z"));
            break;
        }
        case sdf::GeometryType::CYLINDER: {
            p.shape = Shape::cylinder;
            const double r = size_value(g.CylinderShape()->Radius(), p.at, "cylinder radius");
            p.size = Vec3(r, r, size_value(g.CylinderShape()->Length(), p.at, "cylinder length"));
            break;
        }
        case sdf::GeometryType::SPHERE:
            p.shape = Shape::sphere;
            p.size = Vec3::Constant(size_value(g.SphereShape()->Radius(), p.at, "sphere radius"));
            break;
        case sdf::GeometryType::PLANE: {
            p.shape = Shape::plane;
            const auto n = g.PlaneShape()->Normal();
            const auto s = g.PlaneShape()->Size();
            p.normal = Vec3(n.X(), n.Y(), n.Z());
            if (!p.normal.allFinite() || p.normal.norm() < 1e-12) fail(p.at, "plane normal must be a non-zero vector");
            p.normal.normalize();
            p.size = Vec3(size_value(s.X(), p.at, "plane size x"), size_value(s.Y(), p.at, "plane size y"), 0.0);
            break;
        }
        case sdf::GeometryType::MESH: {
            p.shape = Shape::mesh;
            const sdf::Mesh& m = *g.MeshShape();
            const auto s = m.Scale();
            p.scale = Vec3(s.X(), s.Y(), s.Z());
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite(p.scale[k]) || std::abs(p.scale[k]) < min_mesh_scale ||
                    std::abs(p.scale[k]) > 1.0 / min_mesh_scale)
                    fail(p.at, "mesh scale (" + format_number(p.scale.x()) + ", " + format_number(p.scale.y()) + ", " +
                                   format_number(p.scale.z()) + ") is absurd: each factor must be finite, with " +
                                   format_number(min_mesh_scale) +
                                   " <= |factor| <= " + format_number(1.0 / min_mesh_scale));
            const GazeboResolver::Found found = resolver_.mesh_file(m.Uri(), m.FilePath());
            if (found.file.empty()) fail(p.at, found.error);
            p.mesh_file = found.file;
            break;
        }
        case sdf::GeometryType::HEIGHTMAP:
            fail(p.at, "a heightmap cannot be built (bvc3d reads box, cylinder, sphere, plane and mesh geometry)");
        default:
            fail(p.at, "this geometry cannot be built (bvc3d reads box, cylinder, sphere, plane and mesh geometry)");
    }
    check_pose(pose, p.at, "its pose");
    out.push_back(std::move(p));
}

// A model's links' geometry and its nested models', posed in the frame `frame` of the model.
void Loader::walk_model(const sdf::Model& m, const Iso& frame, const std::string& path, std::vector<Piece>& out) const {
    const bool visual = options_.geometry == GazeboOptions::Geometry::visual;
    for (uint64_t l = 0; l < m.LinkCount(); ++l) {
        const sdf::Link& link = *m.LinkByIndex(l);
        const uint64_t n = visual ? link.VisualCount() : link.CollisionCount();
        for (uint64_t i = 0; i < n; ++i) {
            ignition::math::Pose3d pose;
            std::string name;
            const sdf::Geometry* geom;
            sdf::ElementPtr element;
            if (visual) {
                const sdf::Visual& v = *link.VisualByIndex(i);
                v.SemanticPose().Resolve(pose, "__model__");
                name = v.Name();
                geom = v.Geom();
                element = v.Element();
            } else {
                const sdf::Collision& c = *link.CollisionByIndex(i);
                c.SemanticPose().Resolve(pose, "__model__");
                name = c.Name();
                geom = c.Geom();
                element = c.Element();
            }
            if (geom) read_geometry(*geom, element, path + "/" + link.Name() + "/" + name, frame * to_iso(pose), out);
        }
    }
    for (uint64_t k = 0; k < m.ModelCount(); ++k) {
        const sdf::Model& nested = *m.ModelByIndex(k);
        ignition::math::Pose3d pose;
        nested.SemanticPose().Resolve(pose, "__model__");
        const Iso f = frame * to_iso(pose);
        check_pose(f, place_of(nested.Element(), path + "/" + nested.Name()), "its pose");
        walk_model(nested, f, path + "/" + nested.Name(), out);
    }
}

int Loader::template_of(const Include& inc, const std::string& where) {
    const std::string key = inc.folder.empty() ? builtin_marker + inc.model : inc.folder;
    if (const auto it = template_by_folder_.find(key); it != template_by_folder_.end()) return it->second;
    Template t;
    t.where = where;
    t.model = inc.model;
    t.folder = inc.folder;
    t.name = inc.model;
    if (inc.folder.empty()) {
        t.builtin = true;
        if (inc.model == "ground_plane") {
            Piece p;
            p.path = "link/visual";
            p.at = inc.at;
            p.shape = Shape::plane;
            p.size = Vec3(ground_plane_size, ground_plane_size, 0.0);
            p.ground_plane = true;
            t.pieces.push_back(p);
        }
    } else {
        t.file = sdf::getModelFilePath(inc.folder);
        if (t.file.empty())
            fail(inc.at, "model '" + inc.model + "': its model.config in '" + inc.folder + "' names no SDF file");
        std::error_code ec;
        if (!fs::exists(t.file, ec))
            fail(inc.at, "model '" + inc.model + "': its file '" + t.file + "' (named by model.config) does not exist");
        files_.insert((fs::path(inc.folder) / "model.config").string());
        files_.insert(t.file);
    }
    templates_.push_back(std::move(t));
    template_by_folder_[key] = static_cast<int>(templates_.size() - 1);
    return static_cast<int>(templates_.size() - 1);
}

// Reads every model file not read yet, all in one SDFormat document (each <include>d once, under
// its own name), then the model files those include, until none is new.
void Loader::load_templates() {
    for (std::size_t next = 0; next < templates_.size();) {
        const std::size_t end = templates_.size();
        std::vector<std::size_t> todo;
        for (std::size_t t = next; t < end; ++t)
            if (!templates_[t].builtin) todo.push_back(t);
        if (!todo.empty()) read_templates(todo);
        for (std::size_t t = next; t < end; ++t)
            for (std::size_t k = 0; k < templates_[t].includes.size(); ++k) {
                const Include inc = templates_[t].includes[k];  // template_of may add templates
                template_of(inc, templates_[t].where + "/" +
                                     slashed(inc.parent.empty() ? inc.name : inc.parent + "::" + inc.name));
            }
        next = end;
    }
}

// Each model file is read into one SDF document whose element descriptions are made once:
// Root::Load and SDFormat's own <include> make them anew each time (tens of milliseconds a file).
sdf::Errors Loader::read_into(sdf::Root& root, const std::string& file) {
    if (!blank_) {
        blank_ = std::make_shared<sdf::SDF>();
        sdf::init(blank_);
    }
    blank_->Root()->ClearElements();
    sdf::Errors errors;
    sdf::readFile(file, config_, blank_, errors);
    if (!errors.empty()) return errors;
    return root.Load(blank_, config_);
}

void Loader::read_templates(const std::vector<std::size_t>& todo) {
    for (std::size_t t : todo) {
        Template& tp = templates_[t];
        std::vector<Include> nested;
        includes_ = &nested;
        sdf::Root root;
        parse(root, [&](sdf::Root& r) { return read_into(r, tp.file); });
        includes_ = nullptr;
        const sdf::Model* m = root.Model();
        if (!m) fail(Place{tp.file, 0, ""}, "holds no <model> (a model's file must)");
        tp.name = m->Name();
        // Its own <pose> (a file's top model has no frame to resolve it against: it is the raw pose);
        // its geometry is kept in its own frame.
        tp.own_pose = to_iso(m->RawPose());
        check_pose(tp.own_pose, place_of(m->Element(), tp.where), "the model's pose");
        walk_model(*m, Iso::Identity(), tp.where, tp.pieces);
        for (auto& p : tp.pieces)
            p.path = p.path.substr(tp.where.size() + 1);  // "w/crate/link/visual" -> "link/visual"
        const Iso to_model = tp.own_pose.inverse();
        for (Include inc : nested) {
            // The enclosing model's scoped name starts with the file's model: keep what is inside it.
            if (inc.parent == tp.name) inc.parent.clear();
            else if (inc.parent.rfind(tp.name + "::", 0) == 0) inc.parent = inc.parent.substr(tp.name.size() + 2);
            inc.frame = to_model * inc.frame;
            tp.includes.push_back(inc);
        }
    }
}

const TriangleMesh& Loader::mesh(const Piece& piece) {
    auto it = meshes_.find(piece.mesh_file);
    if (it != meshes_.end()) return it->second;
    TriangleMesh m;
    try {
        m = load_mesh_file(piece.mesh_file, MeshFileOptions{options_.collada_up_axis});
    } catch (const InputError& e) {
        fail(piece.at, e.what());
    }
    files_.insert(piece.mesh_file);
    return meshes_.emplace(piece.mesh_file, std::move(m)).first->second;
}

TriangleMesh cylinder_prism(double r, double length) {
    // Corners on the circle; the chord's midpoint is r·cos(π/n) from the axis.
    int n = 16;
    while (n < 4096 && r * (1 - std::cos(pi / n)) > cylinder_tolerance) n *= 2;
    TriangleMesh m;
    const double h = length / 2;
    const Vec3 top(0, 0, h), bottom(0, 0, -h);
    for (int i = 0; i < n; ++i) {
        const double a0 = 2 * pi * i / n, a1 = 2 * pi * (i + 1) / n;
        const Vec3 p0(r * std::cos(a0), r * std::sin(a0), 0), p1(r * std::cos(a1), r * std::sin(a1), 0);
        m.add_quad(p0 + bottom, p1 + bottom, p1 + top, p0 + top);
        m.add_triangle(top, p0 + top, p1 + top);
        m.add_triangle(bottom, p1 + bottom, p0 + bottom);
    }
    return m;
}

void Loader::emit(const Piece& piece, const Iso& pose, const std::string& path) {
    const Place at{piece.at.file, piece.at.line, path};
    check_pose(pose, at, "its pose in the world");
    GazeboPart part;
    part.path = path;
    part.file = piece.at.file;
    part.line = piece.at.line;
    part.shape = shape_name(piece.shape);
    part.mesh_file = piece.mesh_file;
    part.ground_plane = piece.ground_plane;
    part.first_triangle = scene_.mesh.size();
    if (piece.shape == Shape::sphere) {
        const double radius = piece.size.x();
        auto [it, added] = sphere_set_.emplace(radius, static_cast<int>(scene_.spheres.size()));
        if (added) scene_.spheres.push_back(SphereSet{{}, radius});
        part.sphere_set = it->second;
        part.sphere_index = scene_.spheres[it->second].centers.size();
        scene_.spheres[it->second].centers.push_back(pose.translation());
        scene_.parts.push_back(part);
        return;
    }
    TriangleMesh local;
    switch (piece.shape) {
        case Shape::box:
            local = box_mesh(piece.size);
            break;
        case Shape::cylinder:
            local = cylinder_prism(piece.size.x(), piece.size.z());
            break;
        case Shape::plane: {
            const Eigen::Matrix3d R =
                Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), piece.normal).toRotationMatrix();
            const double hx = piece.size.x() / 2, hy = piece.size.y() / 2;
            local.add_quad(R * Vec3(-hx, -hy, 0), R * Vec3(hx, -hy, 0), R * Vec3(hx, hy, 0), R * Vec3(-hx, hy, 0));
            break;
        }
        case Shape::mesh: {
            local = mesh(piece);
            for (auto& v : local.vertices) v = v.cwiseProduct(piece.scale);
            break;
        }
        case Shape::sphere:
            break;
    }
    const std::size_t first_vertex = scene_.mesh.vertices.size();
    scene_.mesh.append(local, pose);
    for (std::size_t v = first_vertex; v < scene_.mesh.vertices.size(); ++v) {
        const Vec3& p = scene_.mesh.vertices[v];
        if (!p.allFinite() || p.cwiseAbs().maxCoeff() > max_coordinate)
            fail(at, "reaches (" + format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
                         "): coordinates must lie within ±" + format_number(max_coordinate) + " m");
    }
    // A mesh scaled flat (or a plane seen edge-on) leaves degenerate triangles: drop them.
    std::size_t kept = part.first_triangle;
    for (std::size_t t = part.first_triangle; t < scene_.mesh.size(); ++t) {
        const auto c = scene_.mesh.corners(t);
        if (triangle_double_area(c[0], c[1], c[2]) > 1e-12) scene_.mesh.triangles[kept++] = scene_.mesh.triangles[t];
    }
    scene_.mesh.triangles.resize(kept);
    if (static_cast<double>(scene_.mesh.size()) > max_mesh_triangles)
        fail(at, "the world holds more than " + format_number(max_mesh_triangles) + " triangles, the limit");
    part.triangle_count = scene_.mesh.size() - part.first_triangle;
    scene_.parts.push_back(part);
}

// Places `pieces` and the models of `includes` (their frames relative to `frame`), depth first.
void Loader::expand(const std::vector<Piece>& pieces, const std::vector<Include>& includes, const Iso& frame,
                    const std::string& prefix, std::vector<int>& stack) {
    for (const auto& p : pieces) emit(p, frame * p.pose, prefix + "/" + p.path);
    for (const auto& inc : includes) {
        const int t = template_of(inc, prefix + "/" + inc.name);
        // Without a <name>, an included model keeps the name in its file (as SDFormat names it).
        const std::string name = inc.named || templates_[t].builtin ? inc.name : templates_[t].name;
        const std::string path = prefix + "/" + slashed(inc.parent.empty() ? name : inc.parent + "::" + name);
        if (std::find(stack.begin(), stack.end(), t) != stack.end()) {
            std::string chain;
            for (int s : stack) chain += templates_[s].model + " -> ";
            fail(Place{inc.at.file, inc.at.line, path},
                 "models include each other in a cycle: " + chain + templates_[t].model);
        }
        if (!inc.posed) fail(inc.at, "SDFormat gave no pose for the included model '" + inc.name + "'");
        const Template& tp = templates_[t];
        const Iso f = frame * inc.frame * (inc.has_pose ? Iso::Identity() : tp.own_pose);
        check_pose(f, Place{inc.at.file, inc.at.line, path}, "the included model's pose");
        stack.push_back(t);
        expand(tp.pieces, tp.includes, f, path, stack);
        stack.pop_back();
    }
}

GazeboScene Loader::load() {
    std::error_code ec;
    if (!fs::exists(file_, ec)) throw InputError("Gazebo world '" + file_ + "': file does not exist");
    if (fs::is_directory(file_, ec)) throw InputError("Gazebo world '" + file_ + "': is a folder, not a file");
    files_.insert(file_);
    std::lock_guard<std::mutex> lock(sdformat_mutex());
    std::vector<Include> top;
    std::vector<Piece> pieces;
    {
        includes_ = &top;
        sdf::Root root;
        // Root::Load of the file keeps the world when SDFormat complains about its name (a loaded
        // SDF document does not): read_into is for model files.
        parse(root, [&](sdf::Root& r) { return r.Load(file_, config_); });
        includes_ = nullptr;
        if (const sdf::World* world = root.WorldByIndex(0)) {
            scene_.name = world->Name();
            for (uint64_t i = 0; i < world->ModelCount(); ++i) {
                const sdf::Model& m = *world->ModelByIndex(i);
                ignition::math::Pose3d pose;
                m.SemanticPose().Resolve(pose, "world");
                const Iso f = to_iso(pose);
                check_pose(f, place_of(m.Element(), scene_.name + "/" + m.Name()), "its pose");
                walk_model(m, f, scene_.name + "/" + m.Name(), pieces);
            }
        } else if (const sdf::Model* model = root.Model()) {  // a model file: the model is the world
            scene_.name = model->Name();
            ignition::math::Pose3d pose;
            model->SemanticPose().Resolve(pose, "world");
            walk_model(*model, to_iso(pose), scene_.name, pieces);
        } else {
            throw InputError("Gazebo world '" + file_ + "': holds neither a <world> nor a <model>");
        }
    }
    for (const auto& inc : top)
        template_of(inc, scene_.name + "/" + slashed(inc.parent.empty() ? inc.name : inc.parent + "::" + inc.name));
    load_templates();
    std::vector<int> stack;
    // Pieces of models written in the world file itself, then every include.
    for (const auto& p : pieces) emit(p, p.pose, p.path);
    expand({}, top, Iso::Identity(), scene_.name, stack);
    if (scene_.parts.empty())
        throw InputError("Gazebo world '" + file_ + "': has no " +
                         (options_.geometry == GazeboOptions::Geometry::visual ? "visual" : "collision") +
                         " geometry to build a world from");
    scene_.files.assign(files_.begin(), files_.end());
    return std::move(scene_);
}

}  // namespace

namespace {

// The folders of a colon-separated environment variable, in order.
std::vector<std::string> env_folders(const char* name) {
    std::vector<std::string> out;
    if (const char* env = std::getenv(name)) {
        std::istringstream in(env);
        for (std::string dir; std::getline(in, dir, ':');)
            if (!dir.empty()) out.push_back(dir);
    }
    return out;
}

bool is_file(const fs::path& p) {
    std::error_code ec;
    return fs::is_regular_file(p, ec);
}

}  // namespace

std::vector<std::string> gazebo_model_path(const std::string& world_file, const GazeboOptions& options) {
    std::vector<std::string> path = options.model_path;
    const fs::path beside = fs::absolute(world_file).parent_path().parent_path() / "models";
    path.push_back(beside.lexically_normal().string());
    for (auto& dir : env_folders("GAZEBO_MODEL_PATH")) path.push_back(std::move(dir));
    return path;
}

std::vector<std::string> gazebo_resource_path(const GazeboOptions& options) {
    std::vector<std::string> path = options.resource_path;
    for (auto& dir : env_folders("GAZEBO_RESOURCE_PATH")) path.push_back(std::move(dir));
    return path;
}

GazeboResolver::GazeboResolver(const std::string& world_file, const GazeboOptions& options)
    : model_path_(gazebo_model_path(world_file, options)), resource_path_(gazebo_resource_path(options)) {}

std::string GazeboResolver::model_folder(const std::string& name) const {
    if (name.empty() || name.find('/') != std::string::npos) return "";
    for (const auto& dir : model_path_)
        if (is_file(fs::path(dir) / name / "model.config")) return (fs::path(dir) / name).string();
    return "";
}

GazeboResolver::Found GazeboResolver::mesh_file(const std::string& uri, const std::string& sdf_file) const {
    const auto missing = [&](const std::string& why) { return Found{"", "mesh '" + uri + "': " + why}; };
    if (uri.empty()) return Found{"", "mesh has no <uri>"};
    const std::string model = "model://", file = "file://";
    if (uri.rfind(model, 0) == 0) {
        const std::string rest = uri.substr(model.size());
        const auto slash = rest.find('/');
        const std::string folder = model_folder(rest.substr(0, slash));
        if (folder.empty() || slash == std::string::npos)
            return missing("model '" + rest.substr(0, slash) + "' was not found on the model path (" +
                           join(model_path_, ", ") + ")");
        const fs::path path = fs::path(folder) / rest.substr(slash + 1);
        if (!is_file(path)) return missing("file '" + path.string() + "' does not exist");
        return Found{path.string(), ""};
    }
    const bool file_uri = uri.rfind(file, 0) == 0;
    if (!file_uri && uri.find("://") != std::string::npos)
        return missing("only model://, file:// and file paths can be read");
    const fs::path named = file_uri ? uri.substr(file.size()) : uri;
    if (named.is_absolute()) {
        if (!is_file(named)) return missing("file '" + named.string() + "' does not exist");
        return Found{named.string(), ""};
    }
    // Relative: beside the SDF file (a plain path only), then on the resource path.
    std::vector<std::string> places;
    if (!file_uri)
        places.push_back(fs::path(sdf_file).has_parent_path() ? fs::path(sdf_file).parent_path().string() : ".");
    places.insert(places.end(), resource_path_.begin(), resource_path_.end());
    for (const auto& dir : places)
        if (is_file(fs::path(dir) / named)) return Found{(fs::path(dir) / named).string(), ""};
    const std::string how =
        "relative file:// URIs are searched on the resource path: a world YAML's resource_path, then the folders "
        "of GAZEBO_RESOURCE_PATH";
    if (places.empty())
        return missing("'" + named.string() + "' is relative and the resource path is empty (" + how + ")");
    return missing("'" + named.string() + "' was not found in '" + join(places, "', '") + "' (" +
                   (file_uri ? "" : "a plain path is looked for beside its SDF file first; ") + how + ")");
}

GazeboScene load_gazebo_world(const std::string& file, const GazeboOptions& options) {
    try {
        return Loader(file, options).load();
    } catch (const InputError& e) {  // an error in a model's file: say which world included it
        const std::string what = e.what();
        if (what.find("'" + file + "'") != std::string::npos) throw;
        throw InputError("Gazebo world '" + file + "': " + what);
    }
}

namespace {

// The texts of every <mesh>'s <uri> in an SDF file's text (comments included: a superset does no harm).
std::vector<std::string> mesh_uris(const std::string& text) {
    std::vector<std::string> uris;
    for (std::size_t at = text.find("<mesh"); at != std::string::npos; at = text.find("<mesh", at + 5)) {
        if (at + 5 < text.size() && !std::strchr(" \t\r\n>", text[at + 5])) continue;  // <meshes>, <mesh_x>
        const std::size_t end = text.find("</mesh>", at), open = text.find("<uri>", at);
        if (end == std::string::npos || open == std::string::npos || open > end) continue;
        const std::size_t close = text.find("</uri>", open);
        if (close == std::string::npos || close > end) continue;
        std::string uri = text.substr(open + 5, close - open - 5);
        const auto first = uri.find_first_not_of(" \t\r\n"), last = uri.find_last_not_of(" \t\r\n");
        if (first != std::string::npos) uris.push_back(uri.substr(first, last - first + 1));
    }
    return uris;
}

}  // namespace

std::vector<std::string> gazebo_world_files(const std::string& file, const GazeboOptions& options) {
    const GazeboResolver resolver(file, options);
    std::set<std::string> files{file}, folders;
    std::vector<std::string> to_scan{file}, scanned;
    while (!to_scan.empty()) {
        scanned.push_back(to_scan.back());
        to_scan.pop_back();
        std::ifstream in(scanned.back(), std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        for (std::size_t at = text.find("model://"); at != std::string::npos; at = text.find("model://", at + 8)) {
            std::size_t end = at + 8;
            while (end < text.size() && !std::strchr("/<\"' \t\r\n", text[end])) ++end;
            const std::string folder = resolver.model_folder(text.substr(at + 8, end - at - 8));
            if (folder.empty() || !folders.insert(folder).second) continue;
            std::error_code ec;
            for (const auto& e : fs::recursive_directory_iterator(folder, ec)) {
                if (!e.is_regular_file(ec)) continue;
                files.insert(e.path().string());
                const auto ext = e.path().extension().string();
                if (ext == ".sdf" || ext == ".world") to_scan.push_back(e.path().string());
            }
        }
    }
    // Then the meshes found as the loader finds them (file:// URIs, paths), those not listed yet (by
    // another spelling of their path) added.
    const auto canonical = [](const std::string& f) {
        std::error_code ec;
        const fs::path c = fs::weakly_canonical(f, ec);
        return ec ? f : c.string();
    };
    std::set<std::string> listed;
    for (const auto& f : files) listed.insert(canonical(f));
    for (const auto& sdf_file : scanned) {
        std::ifstream in(sdf_file, std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        for (const auto& uri : mesh_uris(text)) {
            const auto found = resolver.mesh_file(uri, sdf_file);
            if (!found.file.empty() && listed.insert(canonical(found.file)).second) files.insert(found.file);
        }
    }
    return {files.begin(), files.end()};
}

bool is_gazebo_file(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".world" || ext == ".sdf";
}

}  // namespace bvc3d
