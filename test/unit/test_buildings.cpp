// Buildings (docs/buildings.md): hand-made Gazebo worlds of primitives, nested models, includes,
// poses and scales, checked against geometry computed here from the SDF numbers (not through the
// library's pose code); the real LiDAR models; routes, tours and the free-space grid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <optional>

#include "../support/temp_dir.hpp"
#include "bvc3d/agent/grid_path.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/tour.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/building.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/sensor/lidar_models.hpp"
#include "bvc3d/world/gazebo_world.hpp"
#include "bvc3d/world/ray_caster.hpp"

namespace bvc3d {
namespace {

using test::TempDir;
using M4 = Eigen::Matrix4d;
constexpr double kPi = std::numbers::pi;

// SDF's pose: x y z, then roll, pitch, yaw about the fixed x, y, z axes (R = Rz·Ry·Rx), written
// out here from the definition.
M4 sdf_pose(double x, double y, double z, double roll, double pitch, double yaw) {
    const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch),
                 cy = std::cos(yaw), sy = std::sin(yaw);
    M4 m = M4::Identity();
    m(0, 0) = cy * cp;
    m(0, 1) = cy * sp * sr - sy * cr;
    m(0, 2) = cy * sp * cr + sy * sr;
    m(1, 0) = sy * cp;
    m(1, 1) = sy * sp * sr + cy * cr;
    m(1, 2) = sy * sp * cr - cy * sr;
    m(2, 0) = -sp;
    m(2, 1) = cp * sr;
    m(2, 2) = cp * cr;
    m(0, 3) = x;
    m(1, 3) = y;
    m(2, 3) = z;
    return m;
}

Vec3 apply(const M4& m, const Vec3& p) { return (m * Eigen::Vector4d(p.x(), p.y(), p.z(), 1)).head<3>(); }
Vec3 rotate(const M4& m, const Vec3& d) { return m.topLeftCorner<3, 3>() * d; }

// Distance along a unit ray to a box of full size `size` posed by `m` (slab method in the box's frame).
double ray_box(const M4& m, const Vec3& size, const Vec3& origin, const Vec3& dir) {
    const M4 inv = m.inverse();
    const Vec3 o = apply(inv, origin), d = rotate(inv, dir);
    double t0 = -1e300, t1 = 1e300;
    for (int k = 0; k < 3; ++k) {
        const double h = size[k] / 2;
        if (std::abs(d[k]) < 1e-300) {
            if (std::abs(o[k]) > h) return INFINITY;
            continue;
        }
        double a = (-h - o[k]) / d[k], b = (h - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return t0 <= t1 && t0 >= 0 ? t0 : INFINITY;
}

double ray_sphere(const Vec3& c, double r, const Vec3& o, const Vec3& d) {
    const Vec3 w = o - c;
    const double b = w.dot(d), disc = b * b - (w.squaredNorm() - r * r);
    if (disc < 0) return INFINITY;
    const double t = -b - std::sqrt(disc);
    return t >= 0 ? t : INFINITY;
}

// The OBJ of a unit cube centered on the origin.
const char* kCubeObj = R"(v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 0.5
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
)";

std::string model_config(const std::string& name) {
    return "<?xml version=\"1.0\"?>\n<model><name>" + name +
           "</name><version>1.0</version><sdf version=\"1.6\">model.sdf</sdf>"
           "<description>a test model & its parts</description></model>\n";
}

// The test world: a model file `crate` (its own pose; a box on a link with a pose; a nested model
// `lid` holding a sphere; an include of model `bolt`), included twice (with a pose, which replaces
// the crate's own, and without); an inline model with a nested model, a box wall and a cylinder;
// a model placed relative to a frame; a scaled, rolled, pitched and yawed mesh; the ground plane
// and the sun.
struct TestWorld {
    TempDir dir{"gazebo"};
    std::filesystem::path world;
    TestWorld() {
        dir.write("models/crate/model.config", model_config("crate"));
        dir.write("models/crate/model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.6"><model name="crate"><static>true</static>
  <pose>0 0 5 0 0 0.3</pose>
  <link name="body"><pose>0.5 0 0 0 0 0</pose>
    <visual name="box"><pose>0 0 0.25 0 0 0</pose><geometry><box><size>1 2 0.5</size></box></geometry></visual>
    <collision name="box"><pose>0 0 0.25 0 0 0</pose>
      <geometry><box><size>1.2 2.2 0.5</size></box></geometry></collision>
  </link>
  <model name="lid"><pose>0 0 1 0 0 0</pose>
    <link name="top"><visual name="ball"><pose>0.2 0 0 0 0 0</pose>
      <geometry><sphere><radius>0.3</radius></sphere></geometry></visual></link>
  </model>
  <include><uri>model://bolt</uri><pose>0 0.5 2 0 0 0</pose></include>
</model></sdf>
)");
        dir.write("models/bolt/model.config", model_config("bolt"));
        dir.write("models/bolt/model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.6"><model name="bolt"><static>true</static>
  <link name="head"><visual name="ball"><geometry><sphere><radius>0.1</radius></sphere></geometry></visual></link>
</model></sdf>
)");
        dir.write("models/cube/model.config", model_config("cube"));
        dir.write("models/cube/meshes/cube.obj", kCubeObj);
        dir.write("models/cube/model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.6"><model name="cube"><static>true</static>
  <link name="l"><visual name="v"><pose>0 0 0 0.2 -0.3 0.4</pose>
    <geometry><mesh><uri>model://cube/meshes/cube.obj</uri><scale>2 1 0.5</scale></mesh></geometry></visual></link>
</model></sdf>
)");
        world = dir.write("worlds/test.world", R"(<?xml version="1.0"?>
<sdf version="1.6"><world name="w">
  <include><uri>model://sun</uri></include>
  <include><uri>model://ground_plane</uri><pose>0 0 -0.5 0 0 0</pose></include>
  <include><uri>model://crate</uri><pose>3 1 0 0 0 0.7</pose></include>
  <include><uri>model://crate</uri><name>crate2</name></include>
  <model name="outer"><static>true</static><pose>-4 0 0 0 0 0.5</pose>
    <model name="inner"><pose>1 0 0 0 0 0</pose>
      <link name="L"><pose>0 1 0 0 0 0.2</pose>
        <visual name="wall"><pose>0 0 1 0 0 0</pose><geometry><box><size>0.2 3 2</size></box></geometry></visual>
        <visual name="post"><pose>1 0 1 0 0 0</pose>
          <geometry><cylinder><radius>0.3</radius><length>2</length></cylinder></geometry></visual>
      </link>
    </model>
  </model>
  <frame name="F"><pose>0 -6 0 0 0 0</pose></frame>
  <model name="rel"><static>true</static><pose relative_to="F">1 0 0 0 0 0</pose>
    <link name="L"><visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link>
  </model>
  <model name="shape"><static>true</static><pose>0 8 1 0 0 0</pose>
    <include><uri>model://cube</uri><pose>1 2 3 0.1 0.2 0.3</pose></include>
  </model>
</world></sdf>
)");
    }
};

// The poses the SDF numbers give, composed here.
const M4 crate1 = sdf_pose(3, 1, 0, 0, 0, 0.7);  // the include's pose replaces the crate's own
const M4 crate2 = sdf_pose(0, 0, 5, 0, 0, 0.3);  // no include pose: the crate's own
const M4 crate_box = sdf_pose(0.5, 0, 0, 0, 0, 0) * sdf_pose(0, 0, 0.25, 0, 0, 0);
const M4 crate_ball = sdf_pose(0, 0, 1, 0, 0, 0) * sdf_pose(0.2, 0, 0, 0, 0, 0);
const M4 crate_bolt = sdf_pose(0, 0.5, 2, 0, 0, 0);
const M4 link_L = sdf_pose(-4, 0, 0, 0, 0, 0.5) * sdf_pose(1, 0, 0, 0, 0, 0) * sdf_pose(0, 1, 0, 0, 0, 0.2);
const M4 wall = link_L * sdf_pose(0, 0, 1, 0, 0, 0);
const M4 post = link_L * sdf_pose(1, 0, 1, 0, 0, 0);
const M4 rel = sdf_pose(0, -6, 0, 0, 0, 0) * sdf_pose(1, 0, 0, 0, 0, 0);
const M4 cube = sdf_pose(0, 8, 1, 0, 0, 0) * sdf_pose(1, 2, 3, 0.1, 0.2, 0.3) * sdf_pose(0, 0, 0, 0.2, -0.3, 0.4);

TEST(GazeboWorld, NamesEveryPartByItsElementPath) {
    TestWorld t;
    const GazeboScene s = load_gazebo_world(t.world.string());
    std::vector<std::string> names;
    for (const auto& p : s.parts) names.push_back(p.path);
    for (const char* name :
         {"w/ground_plane/link/visual", "w/crate/body/box", "w/crate/lid/top/ball", "w/crate/bolt/head/ball",
          "w/crate2/body/box", "w/outer/inner/L/wall", "w/outer/inner/L/post", "w/rel/L/v", "w/shape/cube/l/v"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    EXPECT_EQ(s.parts.size(), 11u);  // the sun has no geometry
    for (const auto& p : s.parts) EXPECT_EQ(p.ground_plane, p.path == "w/ground_plane/link/visual");
    EXPECT_TRUE(s.missing_models.empty());
}

TEST(GazeboWorld, SpheresSitWhereTheirComposedPosesPutThem) {
    TestWorld t;
    const GazeboScene s = load_gazebo_world(t.world.string());
    const auto center = [&](const std::string& name) {
        for (const auto& p : s.parts)
            if (p.path == name) return s.spheres[static_cast<std::size_t>(p.sphere_set)].centers[p.sphere_index];
        ADD_FAILURE() << name;
        return Vec3(0, 0, 0);
    };
    const auto expect_near = [](const Vec3& a, const Vec3& b) { EXPECT_LT((a - b).norm(), 1e-9) << a.transpose(); };
    expect_near(center("w/crate/lid/top/ball"), apply(crate1 * crate_ball, Vec3::Zero()));
    expect_near(center("w/crate2/lid/top/ball"), apply(crate2 * crate_ball, Vec3::Zero()));
    expect_near(center("w/crate/bolt/head/ball"), apply(crate1 * crate_bolt, Vec3::Zero()));
    expect_near(center("w/crate2/bolt/head/ball"), apply(crate2 * crate_bolt, Vec3::Zero()));
}

// Rays from many places at each primitive's surface: the range equals the analytic one to 1e-6 m.
TEST(GazeboWorld, RaysHitTheBoxesSpheresAndMeshAtTheirAnalyticDistances) {
    TestWorld t;
    const GazeboScene s = load_gazebo_world(t.world.string());
    const RayCaster caster(s.mesh, s.spheres);
    struct Target {
        const char* name;
        M4 pose;
        Vec3 size;      // a box (or the mesh: the unit cube scaled)
        double radius;  // > 0: a sphere at the pose's origin
    };
    const std::vector<Target> targets{
        {"crate box", crate1 * crate_box, Vec3(1, 2, 0.5), 0},
        {"crate2 box", crate2 * crate_box, Vec3(1, 2, 0.5), 0},
        {"wall", wall, Vec3(0.2, 3, 2), 0},
        {"rel", rel, Vec3(1, 1, 1), 0},
        {"cube mesh", cube, Vec3(2, 1, 0.5), 0},
        {"lid ball", crate1 * crate_ball, Vec3::Zero(), 0.3},
        {"bolt", crate2 * crate_bolt, Vec3::Zero(), 0.1},
    };
    int checked = 0;
    for (const auto& tg : targets)
        for (int k = 0; k < 24; ++k) {
            // From 1.5 m away, aimed at a point inside the target (its center offset a little).
            const double a = 2 * kPi * k / 24, e = 0.6 * std::sin(3.0 * k);
            const Vec3 center = apply(tg.pose, Vec3(0.05 * std::cos(k), 0.05 * std::sin(k), 0.02 * k / 24));
            const Vec3 dir = -Vec3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
            const Vec3 origin = center - 2.5 * dir;
            const double expected = tg.radius > 0 ? ray_sphere(apply(tg.pose, Vec3::Zero()), tg.radius, origin, dir)
                                                  : ray_box(tg.pose, tg.size, origin, dir);
            const double got = caster.cast(origin, dir, 2.5);
            if (!std::isfinite(expected) || expected > got + 1e-6) continue;  // something else is in front
            EXPECT_NEAR(got, expected, 1e-6) << tg.name << " ray " << k;
            ++checked;
        }
    EXPECT_GT(checked, 100);
}

TEST(GazeboWorld, CylindersArePrismsWithinTheirTolerance) {
    TestWorld t;
    const GazeboScene s = load_gazebo_world(t.world.string());
    const RayCaster caster(s.mesh, s.spheres);
    // The top cap is flat: exact.
    const Vec3 top = apply(post, Vec3(0.1, -0.05, 1.0));
    EXPECT_NEAR(caster.cast(top + Vec3(0, 0, 2), Vec3(0, 0, -1), 5), 2.0, 1e-6);
    // The side: between the true circle and at most cylinder_tolerance inside it.
    for (int k = 0; k < 36; ++k) {
        const double a = 2 * kPi * k / 36 + 0.01;
        const Vec3 axis_point = apply(post, Vec3(0, 0, 0.3));
        const Vec3 out = rotate(post, Vec3(std::cos(a), std::sin(a), 0));
        const double got = caster.cast(axis_point + 0.5 * out, -out, 3);  // the wall is 0.6 m from the side
        EXPECT_GE(got, 0.5 - 0.3 - 1e-9);
        EXPECT_LE(got, 0.5 - 0.3 + cylinder_tolerance + 1e-9);
    }
}

TEST(GazeboWorld, GroundPlaneIsAHundredMeterSquareAtTheIncludesPose) {
    TestWorld t;
    const GazeboScene s = load_gazebo_world(t.world.string());
    const RayCaster caster(s.mesh, s.spheres);
    EXPECT_NEAR(caster.cast(Vec3(20, -30, 1), Vec3(0, 0, -1), 10), 1.5, 1e-9);        // z = -0.5
    EXPECT_EQ(caster.cast(Vec3(50.5, 0, 1), Vec3(0, 0, -1), 10), RayCaster::no_hit);  // beyond its 50 m half side
    EXPECT_NEAR(caster.cast(Vec3(49.5, 49.5, 1), Vec3(0, 0, -1), 10), 1.5, 1e-9);
}

TEST(GazeboWorld, CollisionGeometryIsReadWhenAsked) {
    TestWorld t;
    GazeboOptions o;
    o.geometry = GazeboOptions::Geometry::collision;
    const GazeboScene s = load_gazebo_world(t.world.string(), o);
    ASSERT_EQ(s.parts.size(), 3u);  // the ground plane (built in) and the two crates' collision boxes
    const RayCaster caster(s.mesh, s.spheres);
    const M4 box = crate1 * crate_box;
    const Vec3 c = apply(box, Vec3::Zero());
    const Vec3 d = rotate(box, Vec3(-1, 0, 0));
    EXPECT_NEAR(caster.cast(c - 3 * d, d, 5), ray_box(box, Vec3(1.2, 2.2, 0.5), c - 3 * d, d), 1e-6);
}

// The ground robot's body against the wall, the crate and the relative box: its clearance is the
// distance to their footprints (rectangles standing on the floor), computed here.
TEST(GazeboWorld, BodyCollidesWithTheFootprintsOfTheGeometry) {
    TestWorld t;
    GazeboScene s = load_gazebo_world(t.world.string());
    WorldDescription w;  // the scene as it is: its boxes stand on z = 0
    w.mesh = std::move(s.mesh);
    w.spheres = std::move(s.spheres);
    w.walkable = Polygon2::rectangle(-10, -10, 10, 10);
    const BodyCollider body(w, 0.25, 0.1);
    // Footprints, in the file's frame (z does not matter for standing boxes).
    struct Rect {
        M4 pose;
        Vec2 half;
    };
    const std::vector<Rect> rects{{crate1 * crate_box, {0.5, 1.0}}, {wall, {0.1, 1.5}}, {rel, {0.5, 0.5}}};
    const auto distance = [&](const Vec2& p) {
        double best = 1e9;
        for (const auto& r : rects) {
            const Vec3 q = apply(r.pose.inverse(), Vec3(p.x(), p.y(), apply(r.pose, Vec3::Zero()).z()));
            const Vec2 outside((std::max(std::abs(q.x()) - r.half.x(), 0.0)),
                               std::max(std::abs(q.y()) - r.half.y(), 0.0));
            best = std::min(best, outside.norm());
        }
        return best;
    };
    int checked = 0;
    for (double x = -5; x <= 5; x += 0.37)
        for (double y = -8; y <= 4; y += 0.41) {
            const Vec2 p(x, y);
            const double d = distance(p);
            if (d > 1.0 || d < 1e-3) continue;  // near these three only (the post and crate2 are elsewhere)
            if ((p - apply(post, Vec3::Zero()).head<2>()).norm() < 1.5) continue;
            EXPECT_NEAR(body.clearance(p), d - 0.25, 1e-6) << x << ", " << y;
            ++checked;
        }
    EXPECT_GT(checked, 30);
}

TEST(GazeboWorld, RefusesBrokenWorldsNamingTheFileAndElement) {
    TestWorld t;
    const auto error = [&](const std::string& name, const std::string& body) {
        const auto file =
            t.dir.write("worlds/" + name, "<?xml version=\"1.0\"?>\n<sdf version=\"1.6\"><world name=\"w\">\n" + body +
                                              "\n</world></sdf>\n");
        try {
            load_gazebo_world(file.string());
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    auto m = error("missing.world", "<include><uri>model://nothere</uri></include>");
    EXPECT_NE(m.find("missing.world"), std::string::npos) << m;
    EXPECT_NE(m.find("nothere"), std::string::npos) << m;
    EXPECT_NE(m.find("line 3"), std::string::npos) << m;
    m = error("heightmap.world",
              "<model name='hill'><static>true</static><link name='l'><visual name='v'><geometry><heightmap>"
              "<uri>h.png</uri><size>1 1 1</size></heightmap></geometry></visual></link></model>");
    EXPECT_NE(m.find("w/hill/l/v"), std::string::npos) << m;
    EXPECT_NE(m.find("heightmap"), std::string::npos) << m;
    m = error("nomesh.world",
              "<model name='m'><static>true</static><link name='l'><visual name='v'><geometry><mesh>"
              "<uri>meshes/absent.dae</uri></mesh></geometry></visual></link></model>");
    EXPECT_NE(m.find("w/m/l/v"), std::string::npos) << m;
    EXPECT_NE(m.find("absent.dae"), std::string::npos) << m;
    m = error("scale.world",
              "<model name='m'><static>true</static><link name='l'><visual name='v'><geometry><mesh>"
              "<uri>model://cube/meshes/cube.obj</uri><scale>1 0 1</scale></mesh></geometry></visual></link></model>");
    EXPECT_NE(m.find("w/m/l/v"), std::string::npos) << m;
    EXPECT_NE(m.find("scale"), std::string::npos) << m;
    m = error("far.world",
              "<model name='m'><static>true</static><pose>3e7 0 0 0 0 0</pose><link name='l'><visual name='v'>"
              "<geometry><box><size>1 1 1</size></box></geometry></visual></link></model>");
    EXPECT_NE(m.find("w/m"), std::string::npos) << m;
    EXPECT_NE(m.find("1e+06"), std::string::npos) << m;
    m = error("nan.world",
              "<model name='m'><static>true</static><pose>nan 0 0 0 0 0</pose><link name='l'><visual "
              "name='v'><geometry><box><size>1 1 1</size></box></geometry></visual></link></model>");
    EXPECT_NE(m.find("nan.world"), std::string::npos) << m;
    EXPECT_NE(m.find("w/m/pose"), std::string::npos) << m;
    m = error("empty.world", "<include><uri>model://sun</uri></include>");
    EXPECT_NE(m.find("no visual geometry"), std::string::npos) << m;
    // Models that include each other.
    t.dir.write("models/a/model.config", model_config("a"));
    t.dir.write("models/a/model.sdf",
                "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"a\"><link name=\"l\"/>"
                "<include><uri>model://b</uri></include></model></sdf>");
    t.dir.write("models/b/model.config", model_config("b"));
    t.dir.write("models/b/model.sdf",
                "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\"b\"><link name=\"l\"/>"
                "<include><uri>model://a</uri></include></model></sdf>");
    m = error("cycle.world", "<include><uri>model://a</uri></include>");
    EXPECT_NE(m.find("cycle"), std::string::npos) << m;
    EXPECT_NE(m.find("a -> b -> a"), std::string::npos) << m;
}

TEST(GazeboWorld, SkipsMissingModelsWhenAskedAndListsThem) {
    TestWorld t;
    const auto file = t.dir.write("worlds/partial.world", R"(<?xml version="1.0"?>
<sdf version="1.6"><world name="world">
  <include><uri>model://crate</uri></include>
  <model name="wrap"><include><uri>model://nothere</uri><pose>1e9 0 0 0 0 0</pose></include></model>
</world></sdf>)");
    EXPECT_THROW(load_gazebo_world(file.string()), InputError);
    GazeboOptions o;
    o.skip_missing_models = true;
    const GazeboScene s = load_gazebo_world(file.string(), o);
    ASSERT_EQ(s.missing_models.size(), 1u);
    EXPECT_NE(s.missing_models[0].find("nothere"), std::string::npos);
    EXPECT_EQ(s.parts.size(), 3u);  // the crate's box, lid ball and bolt
}

// An environment variable set (or unset) for one test; restored after.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value) ::setenv(name, value->c_str(), 1);
        else ::unsetenv(name);
    }
    ~ScopedEnv() {
        if (old_) ::setenv(name_, old_->c_str(), 1);
        else ::unsetenv(name_);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* name_;
    std::optional<std::string> old_;
};

// A world published as a ROS package (AWS's bookstore): worlds/store.world includes model://desk,
// whose mesh is named relative to the package's folder, file://models/desk/meshes/desk.obj.
struct PackagedWorld {
    TempDir dir{"package"};
    std::filesystem::path world, mesh;
    PackagedWorld() {
        dir.write("models/desk/model.config", model_config("desk"));
        dir.write("models/desk/model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.6"><model name="desk"><static>true</static>
  <link name="l"><visual name="v">
    <geometry><mesh><uri>file://models/desk/meshes/desk.obj</uri></mesh></geometry></visual></link>
</model></sdf>
)");
        mesh = dir.write("models/desk/meshes/desk.obj", kCubeObj);
        world = dir.write("worlds/store.world", R"(<?xml version="1.0"?>
<sdf version="1.6"><world name="store"><include><uri>model://desk</uri></include></world></sdf>
)");
    }
};

bool lists(const std::vector<std::string>& files, const std::filesystem::path& file) {
    for (const auto& f : files)
        if (std::filesystem::equivalent(f, file)) return true;
    return false;
}

std::string load_error(const std::string& world, const GazeboOptions& options = {}) {
    try {
        load_gazebo_world(world, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

TEST(GazeboWorld, RelativeFileUrisAreFoundOnTheResourcePath) {
    const PackagedWorld p;
    const ScopedEnv no_env("GAZEBO_RESOURCE_PATH", std::nullopt);
    // Not beside the model's file, not in the current folder: nowhere without a resource path.
    std::string m = load_error(p.world.string());
    EXPECT_NE(m.find("mesh 'file://models/desk/meshes/desk.obj'"), std::string::npos) << m;
    EXPECT_NE(m.find("resource path is empty"), std::string::npos) << m;
    EXPECT_NE(m.find("GAZEBO_RESOURCE_PATH"), std::string::npos) << m;
    EXPECT_NE(m.find("store/desk/l/v"), std::string::npos) << m;
    EXPECT_NE(m.find("model.sdf"), std::string::npos) << m;
    // Through GAZEBO_RESOURCE_PATH (its first folder holds nothing), as gazebo_ros sets it from the
    // package's gazebo_media_path.
    {
        const ScopedEnv env("GAZEBO_RESOURCE_PATH", "/nonexistent-bvc3d:" + p.dir.path().string());
        const GazeboScene s = load_gazebo_world(p.world.string());
        ASSERT_EQ(s.parts.size(), 1u);
        EXPECT_TRUE(std::filesystem::equivalent(s.parts[0].mesh_file, p.mesh));
        EXPECT_EQ(s.parts[0].triangle_count, 12u);
        EXPECT_TRUE(lists(s.files, p.mesh));
        EXPECT_TRUE(lists(gazebo_world_files(p.world.string()), p.mesh));
    }
    // Through the option (a world YAML's resource_path).
    GazeboOptions o;
    o.resource_path = {p.dir.path().string()};
    EXPECT_EQ(load_gazebo_world(p.world.string(), o).parts.at(0).triangle_count, 12u);
    // Folders that do not hold it are named in the message.
    o.resource_path = {(p.dir / "worlds").string(), (p.dir / "models").string()};
    m = load_error(p.world.string(), o);
    EXPECT_NE(m.find("'models/desk/meshes/desk.obj' was not found in '" + (p.dir / "worlds").string() + "', '" +
                     (p.dir / "models").string() + "'"),
              std::string::npos)
        << m;
}

TEST(Building, WorldYamlResourcePathFindsFileUris) {
    const PackagedWorld p;
    const ScopedEnv no_env("GAZEBO_RESOURCE_PATH", std::nullopt);
    const auto yaml = p.dir.write("store.yaml", "sdf: worlds/store.world\nresource_path: [.]\n");
    const WorldDescription w = config::load_world_file(yaml.string());
    EXPECT_EQ(w.mesh.size(), 12u);
    EXPECT_TRUE(lists(config::world_file_meshes(yaml.string()), p.mesh));
    // Without the key the YAML's world is an error naming its key, the URI and where to say where it is.
    const auto bare = p.dir.write("bare.yaml", "sdf: worlds/store.world\n");
    try {
        config::load_world_file(bare.string());
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("bare.yaml"), std::string::npos) << m;
        EXPECT_NE(m.find("file://models/desk/meshes/desk.obj"), std::string::npos) << m;
        EXPECT_NE(m.find("resource_path"), std::string::npos) << m;
    }
}

TEST(Building, FingerprintChangesWhenAnyMeshTheWorldReadsIsEdited) {
    // One mesh of each kind of URI: an absolute file://, a relative file:// on the resource path, a plain
    // path beside the world file, and model://.
    const TempDir dir("fingerprint");
    const auto abs = dir.write("elsewhere/a.obj", kCubeObj);
    const auto on_path = dir.write("media/meshes/b.obj", kCubeObj);
    const auto plain = dir.write("worlds/meshes/c.obj", kCubeObj);
    dir.write("models/cube/model.config", model_config("cube"));
    const auto in_model = dir.write("models/cube/meshes/cube.obj", kCubeObj);
    dir.write("models/cube/model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.6"><model name="cube"><static>true</static><link name="l"><visual name="v">
  <geometry><mesh><uri>model://cube/meshes/cube.obj</uri></mesh></geometry></visual></link></model></sdf>
)");
    const auto mesh_model = [](const std::string& name, const std::string& uri, double x) {
        return "<model name='" + name + "'><static>true</static><pose>" + std::to_string(x) +
               " 0 0 0 0 0</pose><link name='l'><visual name='v'><geometry><mesh><uri>" + uri +
               "</uri></mesh></geometry></visual></link></model>\n";
    };
    const auto world =
        dir.write("worlds/w.world", "<?xml version=\"1.0\"?>\n<sdf version=\"1.6\"><world name=\"w\">\n" +
                                        mesh_model("a", "file://" + abs.string(), 0) +
                                        mesh_model("b", "file://meshes/b.obj", 2) + mesh_model("c", "meshes/c.obj", 4) +
                                        "<include><uri>model://cube</uri></include>\n" + "</world></sdf>\n");
    const ScopedEnv env("GAZEBO_RESOURCE_PATH", (dir / "media").string());
    const WorldSpec spec{world.string(), std::nullopt, "+x+y"};
    // The files it reads are all listed (never fewer than the loader reads).
    const GazeboScene scene = load_gazebo_world(world.string());
    const auto listed = gazebo_world_files(world.string());
    for (const auto& f : scene.files) EXPECT_TRUE(lists(listed, f)) << f;
    for (const auto& mesh : {abs, on_path, plain, in_model}) EXPECT_TRUE(lists(scene.files, mesh)) << mesh;
    // Editing any of them makes a new world; the same bytes again, the same one.
    std::string before = spec.fingerprint();
    EXPECT_EQ(spec.fingerprint(), before);
    for (const auto& mesh : {abs, on_path, plain, in_model}) {
        std::ofstream(mesh, std::ios::app) << "v 9 9 9\n";
        const std::string after = spec.fingerprint();
        EXPECT_NE(after, before) << mesh;
        before = after;
    }
}

// A two-storey building: slabs at z = 0 and z = 3 with a stairwell hole in the upper one.
struct TwoStoreys {
    TempDir dir{"storeys"};
    std::filesystem::path world;
    TwoStoreys() {
        std::string models;
        const auto box = [&](const std::string& name, double x, double y, double z, double sx, double sy, double sz) {
            models += "<model name='" + name + "'><static>true</static><pose>" + std::to_string(x) + " " +
                      std::to_string(y) + " " + std::to_string(z) +
                      " 0 0 0</pose><link name='l'><visual name='v'><geometry><box><size>" + std::to_string(sx) + " " +
                      std::to_string(sy) + " " + std::to_string(sz) +
                      "</size></box></geometry></visual></link></model>\n";
        };
        box("floor0", 0, 0, -0.1, 10, 10, 0.2);  // top at z = 0
        // The upper floor (top at z = 3) around a 2 × 2 m hole at x, y in [1, 3].
        box("floor1a", -2, 0, 2.9, 6, 10, 0.2);  // x in [-5, 1]
        box("floor1b", 4, 0, 2.9, 2, 10, 0.2);   // x in [3, 5]
        box("floor1c", 2, -2, 2.9, 2, 6, 0.2);   // x in [1, 3], y in [-5, 1]
        box("floor1d", 2, 4, 2.9, 2, 2, 0.2);    // x in [1, 3], y in [3, 5]
        for (double z : {1.5, 4.5}) {            // walls of both storeys
            box("wn" + std::to_string(z), 0, 5.05, z, 10.2, 0.1, 3);
            box("ws" + std::to_string(z), 0, -5.05, z, 10.2, 0.1, 3);
            box("we" + std::to_string(z), 5.05, 0, z, 0.1, 10, 3);
            box("ww" + std::to_string(z), -5.05, 0, z, 0.1, 10, 3);
        }
        box("pillar", -2, -2, 4.5, 1, 1, 3);  // on the upper floor
        world = dir.write("worlds/storeys.world", "<?xml version=\"1.0\"?>\n<sdf version=\"1.6\"><world name=\"w\">\n" +
                                                      models + "</world></sdf>\n");
    }
};

TEST(Building, WalksTheFloorChosenByFloorZWithDropEdgesAroundTheHole) {
    TwoStoreys b;
    config::BuildingSpec spec;
    spec.file = b.world.string();
    EXPECT_NEAR(config::building_world(spec).floor_z, 0.0, 1e-12);  // the lowest floor
    spec.floor_z = 3.2;
    const WorldDescription w = config::building_world(spec);
    EXPECT_NEAR(w.floor_z, 3.0, 1e-12);
    const World world(w);
    // The upper floor is at z = 0 now: a ray down in the hole falls to the lower floor, 3 m below.
    EXPECT_NEAR(world.rays().cast(Vec3(2, 2, 1), Vec3(0, 0, -1), 10), 4.0, 1e-9);
    EXPECT_NEAR(world.rays().cast(Vec3(0, 0, 1), Vec3(0, 0, -1), 10), 1.0, 1e-9);
    const BodyCollider body(w, 0.25, 0.1);
    EXPECT_FALSE(body.can_start_at(Vec2(2, 2)));  // over the hole: a pocket walled off by the drop edges
    EXPECT_TRUE(body.can_start_at(Vec2(-3, 3)));
    EXPECT_FALSE(body.is_free(Vec2(1.1, 2)));                     // its body would overhang the hole's edge
    EXPECT_NEAR(body.clearance(Vec2(0.5, 2)), 0.5 - 0.25, 1e-9);  // 0.5 m from the edge at x = 1
    EXPECT_NEAR(body.clearance(Vec2(-2, -3)), 0.5 - 0.25, 1e-9);  // 0.5 m from the pillar
    // A long walk never enters the hole's neighborhood nor leaves the storey.
    const auto steps = random_walk(world, 0.5, 7);
    for (const auto& s : steps) {
        const Vec2 outside(std::max(std::abs(s.pose.x - 2) - 1, 0.0), std::max(std::abs(s.pose.y - 2) - 1, 0.0));
        EXPECT_GE(outside.norm(), 0.25 - 1e-6);  // the body stays off the hole [1, 3]²
        EXPECT_LE(std::max(std::abs(s.pose.x), std::abs(s.pose.y)), 5 - 0.25 + 1e-9);
    }
    spec.floor_z = 1.5;
    EXPECT_THROW(config::building_world(spec), InputError);  // no floor there
}

TEST(Building, StoreyFlightVolumeFillsTheStorey) {
    TwoStoreys b;
    config::BuildingSpec spec;
    spec.file = b.world.string();
    spec.flight = config::StoreyFlight{};
    const WorldDescription w = config::building_world(spec);
    ASSERT_TRUE(w.flight);
    EXPECT_NEAR(w.flight->z_min, 0.2, 1e-12);
    EXPECT_NEAR(w.flight->z_max, 2.8 - 0.2, 1e-9);  // the ceiling is the upper floor's underside at 2.8
}

TEST(Building, WorldYamlAndWorldFileNameTheSameWorld) {
    TwoStoreys b;
    const auto yaml =
        b.dir.write("storeys.yaml", "sdf: worlds/storeys.world\nfloor_z: 3\nstart: {points: [[-3, 3]]}\n");
    const WorldDescription from_yaml = config::resolve_world(yaml.string());
    EXPECT_NEAR(from_yaml.floor_z, 3.0, 1e-12);
    ASSERT_EQ(from_yaml.start.points.size(), 1u);
    const WorldDescription from_file = config::resolve_world(b.world.string());
    EXPECT_NEAR(from_file.floor_z, 0.0, 1e-12);
    EXPECT_EQ(from_file.mesh.size(), from_yaml.mesh.size());
    const auto bad = b.dir.write("bad.yaml", "sdf: worlds/storeys.world\nfloor_z: 7\n");
    try {
        config::resolve_world(bad.string());
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("floor_z 7"), std::string::npos) << e.what();
    }
}

// -------------------------------------------------------------------------------------------------
// Real LiDAR models

TEST(LidarModels, TablesMatchTheDatasheetNumbers) {
    struct Expect {
        const char* name;
        int beams, columns;
        double top, bottom, min, max, sd;
    };
    for (const Expect& e : std::vector<Expect>{{"vlp16", 16, 1800, 15, -15, 0.5, 100, 0.03},
                                               {"hdl32", 32, 2170, 10.67, -30.67, 1, 100, 0.02},
                                               {"hdl64", 64, 4500, 2.0, -24.9, 0.9, 120, 0.02},
                                               {"os1-64", 64, 1024, 22.5, -22.5, 0.3, 100, 0.03},
                                               {"os1-128", 128, 1024, 22.5, -22.5, 0.3, 100, 0.03}}) {
        const LidarSpec s = config::resolve_sensor(e.name);
        ASSERT_EQ(static_cast<int>(s.elevations.size()), e.beams) << e.name;
        EXPECT_EQ(s.azimuth_count, e.columns);
        for (int i = 0; i < e.beams; ++i)  // evenly spaced, top first
            EXPECT_NEAR(s.elevations[static_cast<std::size_t>(i)] * 180 / kPi,
                        e.top + (e.bottom - e.top) * i / (e.beams - 1), 1e-9);
        EXPECT_EQ(s.min_range, e.min);
        EXPECT_EQ(s.max_range, e.max);
        EXPECT_EQ(s.range_noise_sd, e.sd);
    }
    EXPECT_NEAR(config::resolve_sensor("vlp16").elevations[1] * 180 / kPi, 13.0, 1e-9);  // 2° apart
}

TEST(LidarModels, ScansCarryTheTablesElevationsAndDropNearReturns) {
    // Inside a closed 8 m box: every beam hits; a level scan's returns carry their row's elevation.
    WorldDescription d;
    d.mesh.append(box_mesh(Vec3(8, 8, 8)));
    const World world(d);
    for (const auto& m : lidar_models()) {
        LidarSpec s = lidar_model_spec(m);
        s.range_noise_sd = 0;
        const Scan scan = Lidar(s).scan(world, Pose::on_floor(0.3, -0.2, 0.4));
        ASSERT_EQ(scan.size(), s.beam_count()) << m.name;
        for (std::size_t k = 0; k < scan.size(); ++k)
            ASSERT_EQ(scan[k].elevation, s.elevations[k / static_cast<std::size_t>(s.azimuth_count)]) << m.name;
    }
    LidarSpec s = lidar_model_spec(*find_lidar_model("vlp16"));
    s.range_noise_sd = 0;
    s.min_range = 4.05;  // the walls 4 m away along the axes, farther elsewhere
    const Scan scan = Lidar(s).scan(world, Pose::on_floor(0, 0, 0));
    ASSERT_FALSE(scan.empty());
    for (const auto& r : scan) EXPECT_GE(r.range, 4.05);
    EXPECT_LT(scan.size(), s.beam_count());
}

TEST(LidarModels, UpperRowsForTheThreeDimensionalModels) {
    const auto v = config::YamlView::load_string("preset: os1-64\nkeep_rows: upper\n", "sensor.yaml");
    const LidarSpec s = config::sensor_from_yaml(v);
    EXPECT_EQ(s.elevations.size(), 32u);
    for (double e : s.elevations) EXPECT_GE(e, 0);
}

// -------------------------------------------------------------------------------------------------
// Routes, tours and the grid under them

WorldDescription room(double hx, double hy) {
    WorldDescription w;
    w.name = "room";
    w.mesh.add_quad(Vec3(-hx, -hy, 0), Vec3(hx, -hy, 0), Vec3(hx, hy, 0), Vec3(-hx, hy, 0));
    w.walkable = Polygon2::rectangle(-hx, -hy, hx, hy);
    w.start.region = w.walkable;
    return w;
}

TEST(Route, SmoothWithinTheLateralAccelerationAndHeadingAlongTheMotion) {
    WorldDescription w = room(10, 10);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Vec3(0, 0, 1);
    w.mesh.append(box_mesh(Vec3(2, 2, 2)), pose);  // a block in the middle
    const BodyCollider body(w, 0.25, 0.1);
    const RouteParams p;
    const auto steps = route_through({{-6, -6}, {6, -6}, {6, 6}, {-6, 6}, {-6, -3}}, body, p);
    ASSERT_GT(steps.size(), 100u);
    EXPECT_EQ(steps.front().pose.x, -6);
    EXPECT_NEAR(steps.back().pose.x, -6, 1e-12);
    EXPECT_NEAR(steps.back().pose.y, -3, 1e-12);
    double top = 0;
    for (std::size_t i = 1; i + 1 < steps.size(); ++i) {
        const auto& a = steps[i - 1].pose;
        const auto& b = steps[i].pose;
        const auto& c = steps[i + 1].pose;
        const double dt = steps[i].t - steps[i - 1].t;
        EXPECT_NEAR(dt, p.model_dt, 1e-9);
        const Vec2 v1 = Vec2(b.x - a.x, b.y - a.y), v2 = Vec2(c.x - b.x, c.y - b.y);
        top = std::max(top, v1.norm() / dt);
        // The heading points along the motion (the chord's direction, to its curvature's order).
        if (v1.norm() > 0.05) {
            EXPECT_LT(std::abs(wrap_pi(std::atan2(v1.y(), v1.x()) - a.heading)), 0.15);
        }
        // Lateral acceleration from three positions: |v × Δv| / |v|, at most 0.5 m/s² (+ finite differences).
        if (v1.norm() > 0.05 && v2.norm() > 0.05 && i + 2 < steps.size()) {
            const Vec2 vel = (v1 + v2) / (2 * dt), acc = (v2 - v1) / (dt * dt);
            EXPECT_LE(std::abs(vel.x() * acc.y() - vel.y() * acc.x()) / vel.norm(), p.lateral_acceleration * 1.08);
        }
    }
    EXPECT_NEAR(top, p.speed, 1e-6);
    // Into the block, or through it: refused, naming the waypoint or the segment.
    try {
        route_through({{-6, -6}, {0.5, 0.2}}, body, p);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("waypoint 1 (0.5, 0.2)"), std::string::npos) << e.what();
    }
    try {
        route_through({{-6, -6}, {-6, 0}, {6, 0}}, body, p);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("segment 1"), std::string::npos) << e.what();
    }
}

// Corners too close together for an arc taken at full speed: the robot slows to √(a·R) on them.
TEST(Route, SlowsDownInTightCorners) {
    const BodyCollider body(room(10, 10), 0.25, 0.1);
    const RouteParams p;
    const auto steps = route_through({{-6, 0}, {-5, 1}, {-4, 0}, {-3, 1}, {-2, 0}, {-1, 1}, {0, 0}}, body, p);
    double top_lateral = 0, slowest = 1e9;
    for (std::size_t i = 2; i + 2 < steps.size(); ++i) {
        const auto& a = steps[i - 1].pose;
        const auto& b = steps[i].pose;
        const auto& c = steps[i + 1].pose;
        const double dt = p.model_dt;
        const Vec2 v1(b.x - a.x, b.y - a.y), v2(c.x - b.x, c.y - b.y);
        const Vec2 vel = (v1 + v2) / (2 * dt), acc = (v2 - v1) / (dt * dt);
        if (vel.norm() < 0.05) continue;
        top_lateral = std::max(top_lateral, std::abs(vel.x() * acc.y() - vel.y() * acc.x()) / vel.norm());
        slowest = std::min(slowest, vel.norm());
    }
    EXPECT_LE(top_lateral, p.lateral_acceleration * 1.08);
    EXPECT_GT(top_lateral, p.lateral_acceleration * 0.5);  // the corners are taken near the limit
    EXPECT_LT(slowest, 0.7 * p.speed);
}

TEST(Route, TrajectoryFilesReadBackBitForBit) {
    const BodyCollider body(room(5, 5), 0.25, 0.1);
    const auto steps = route_through({{-3, -3}, {3, -2}, {0, 3}}, body);
    TempDir dir("route");
    write_trajectory_file(dir / "route.csv", steps);
    const auto back = read_trajectory_file(dir / "route.csv");
    ASSERT_EQ(back.size(), steps.size());
    for (std::size_t i = 0; i < steps.size(); ++i) {
        EXPECT_EQ(back[i].t, steps[i].t);
        EXPECT_EQ(back[i].pose.x, steps[i].pose.x);
        EXPECT_EQ(back[i].pose.y, steps[i].pose.y);
        EXPECT_EQ(back[i].pose.heading, steps[i].pose.heading);
    }
}

TEST(GridPath, ShortestPathsGoAroundInflatedObstacles) {
    WorldDescription w = room(5, 5);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Vec3(0, -1, 1);
    w.mesh.append(box_mesh(Vec3(0.2, 8, 2)), pose);  // a wall from y = -5 to 3 at x = 0
    const BodyCollider body(w, 0.25, 0.1);
    const FreeSpaceGrid grid(body, 0.1);
    const GridPathFinder finder(grid, 0.35);
    const auto from = grid.cell_of({-3, -3}), to = grid.cell_of({3, -3});
    ASSERT_TRUE(from && to);
    const auto path = finder.shortest_path(*from, *to);
    ASSERT_FALSE(path.empty());
    double length = 0, top = -10;
    for (std::size_t i = 0; i < path.size(); ++i) {
        EXPECT_GE(grid.room(path[i]), 0.35);
        top = std::max(top, grid.center(path[i]).y());
        if (i) length += (grid.center(path[i]) - grid.center(path[i - 1])).norm();
    }
    EXPECT_GT(top, 3.0 + 0.1 + 0.35 - 0.1);  // around the wall's end at y = 3
    // Not much longer than the taut string around the inflated wall's end.
    const Vec2 corner(0, 3 + 0.1 + 0.35);
    const double taut = (corner - Vec2(-3, -3)).norm() + (Vec2(3, -3) - corner).norm();
    EXPECT_GT(length, taut - 0.2);
    EXPECT_LT(length, taut * 1.1);  // octile moves: at most 8 % longer, and the grid's steps
    // A wall across the whole room: no path.
    w.mesh.append(box_mesh(Vec3(0.2, 2.2, 2)), Eigen::Isometry3d(Eigen::Translation3d(0, 4, 1)));
    const BodyCollider closed(w, 0.25, 0.1);
    const FreeSpaceGrid closed_grid(closed, 0.1);
    EXPECT_TRUE(GridPathFinder(closed_grid, 0.35).shortest_path(*from, *to).empty());
}

// A ring corridor a tour drives around once: it begins with an out-and-back to drive part of the
// building the other way.
TEST(Tour, DrivesBackWhereItWouldNotOtherwise) {
    WorldDescription w = room(5, 5);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Vec3(0, 0, 1);
    w.mesh.append(box_mesh(Vec3(6.6, 6.6, 2)), pose);  // the ring is 1.7 m wide
    TourParams tp;
    const Tour t = make_tour(w, 0.25, 0.1, Vec2(-4.1, -4.1), tp);
    EXPECT_GE(t.stats.reverse_length, tp.min_reverse);
    EXPECT_GE(t.stats.coverage, tp.min_coverage);
    EXPECT_EQ(t.waypoints.front(), t.waypoints.back());
}

TEST(Tour, CoversTheFloorClosesAndDrivesPartOfItBothWays) {
    // Two rooms joined by a door, a corridor-like block in one.
    WorldDescription w = room(8, 4);
    const auto add = [&](Vec3 c, Vec3 s) {
        Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
        pose.translation() = c;
        w.mesh.append(box_mesh(s), pose);
    };
    add(Vec3(0, -1.5, 1), Vec3(0.2, 5, 2));  // a wall from y = -4 to 1, leaving a door at the top
    add(Vec3(4, 0, 1), Vec3(2, 2, 2));
    const Tour t = make_tour(w, 0.25, 0.1);
    EXPECT_GE(t.stats.coverage, 0.9);
    EXPECT_GE(t.stats.reverse_length, TourParams{}.min_reverse);
    EXPECT_EQ(t.stats.closing_gap, 0.0);
    EXPECT_EQ(t.waypoints.front(), t.waypoints.back());
    const BodyCollider body(w, 0.25, 0.1);
    for (std::size_t i = 1; i < t.steps.size(); ++i)
        EXPECT_GE(body.clearance(Vec2(t.steps[i - 1].pose.x, t.steps[i - 1].pose.y),
                                 Vec2(t.steps[i].pose.x, t.steps[i].pose.y)),
                  -1e-3)  // chords of arcs: the arcs themselves are clear
            << i;
    // The same world gives the same tour.
    const Tour again = make_tour(w, 0.25, 0.1);
    ASSERT_EQ(again.steps.size(), t.steps.size());
    for (std::size_t i = 0; i < t.steps.size(); ++i) EXPECT_EQ(again.steps[i].pose.x, t.steps[i].pose.x);
}

}  // namespace
}  // namespace bvc3d
