// Worlds from YAML and mesh files, and the errors bad ones give (file, key, reason).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "../support/temp_dir.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/recording/ply.hpp"
#include "bvc3d/world/mesh_import.hpp"
#include "bvc3d/world/ray_caster.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;

namespace {

const fs::path data_dir = fs::path(BVC3D_SOURCE_DIR) / "test" / "data";

using bvc3d::test::TempDir;

// Loading `yaml` fails, and the message names the file, the key and the reason.
void expect_config_error(const std::string& yaml, const std::string& key, const std::string& reason) {
    TempDir dir;
    const auto file = dir.write("world.yaml", yaml);
    try {
        config::load_world_file(file.string());
        ADD_FAILURE() << "no error for:\n" << yaml;
    } catch (const ConfigError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
        EXPECT_NE(msg.find(key), std::string::npos) << "expected key '" << key << "' in: " << msg;
        EXPECT_NE(msg.find(reason), std::string::npos) << "expected reason '" << reason << "' in: " << msg;
    }
}

const char* walls = R"(
walkable: {rect: [-4, -4, 4, 4]}
)";

}  // namespace

TEST(WorldYaml, PrimitivesBuildTheExpectedGeometry) {
    TempDir dir;
    const auto file = dir.write("w.yaml", std::string(R"(
name: primitives
objects:
  - box: {center: [0, 0, 0.5], size: [1, 2, 1], yaw_deg: 90}
  - quad: [[4, -4, 0], [4, 4, 0], [4, 4, 3], [4, -4, 3]]
  - tilted_wall: {center: [-2, 0], length: 4, thickness: 0.2, height: 2, yaw_deg: 90, tilt_deg: 30}
)") + walls);
    const World w(config::load_world_file(file.string()));
    EXPECT_EQ(w.name(), "primitives");
    EXPECT_EQ(w.mesh().size(), 12u + 2u + 12u);
    // The yawed box is 2 m long along x: from the origin's side at x = -3 ... ray along +x at y = 0.
    EXPECT_NEAR(w.rays().cast(Vec3(-1.5, 0, 0.5), Vec3::UnitX(), 20), 0.5, 1e-9);
    EXPECT_NEAR(w.rays().cast(Vec3(2, 2, 1), Vec3::UnitX(), 20), 2.0, 1e-9);  // the quad at x = 4
    // Walkable region defaults the start region.
    EXPECT_EQ(w.description().start.region.points.size(), 4u);
}

TEST(WorldYaml, CrossArenaObjectBringsItsRegions) {
    TempDir dir;
    const auto file = dir.write("w.yaml", "objects:\n  - cross_arena: {tilt_deg: 45, lean: -x+y}\n");
    const auto d = config::load_world_file(file.string());
    EXPECT_EQ(d.start.points.size(), 4u);
    EXPECT_NEAR(d.walkable.area(), 100.0, 1e-12);
    const auto preset = config::resolve_world("cross", 45.0, "-x+y");
    ASSERT_EQ(d.mesh.vertices.size(), preset.mesh.vertices.size());
    for (std::size_t i = 0; i < d.mesh.vertices.size(); ++i) EXPECT_EQ(d.mesh.vertices[i], preset.mesh.vertices[i]);
}

TEST(WorldYaml, PresetsAndShippedPaperWorldsAgree) {
    for (int tilt : {0, 30, 45, 60}) {
        const auto named = config::resolve_world("cross-" + std::to_string(tilt));
        const auto flag = config::resolve_world("cross", tilt);
        const auto file = config::load_world_file(std::string(BVC3D_SOURCE_DIR) + "/configs/worlds/cross-" +
                                                  std::to_string(tilt) + ".yaml");
        ASSERT_EQ(named.mesh.vertices, flag.mesh.vertices);
        ASSERT_EQ(named.mesh.vertices, file.mesh.vertices);
    }
    EXPECT_THROW(config::resolve_world("cross-30", 45.0), InputError);
    EXPECT_THROW(config::resolve_world("atlantis"), InputError);
}

// The authors' Webots arena: inner faces of the 0.3 m outer walls (centered on ±5 m) at ±4.85 m, the
// ceiling's underside at 2.25 m (a 0.3 m slab on 2.4 m walls), the central cross as the paper's.
TEST(WorldYaml, WebotsCrossHasTheAuthorsGeometry) {
    const World w(config::resolve_world("cross-webots", 45.0));
    EXPECT_EQ(w.name(), "cross-webots-45");
    EXPECT_EQ(w.description().tilt_deg, 45.0);
    for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0)})
        EXPECT_NEAR(w.rays().cast(Vec3(4.2 * dir.x() + 0.1 * dir.y(), 4.2 * dir.y() + 0.1 * dir.x(), 1.0), dir, 20),
                    0.65, 1e-9);
    EXPECT_NEAR(w.rays().cast(Vec3(-4.5, 4.5, 0.2), Vec3::UnitZ(), 20), 2.05, 1e-9);
    EXPECT_NEAR(w.description().walkable.area(), 9.7 * 9.7, 1e-9);
    // The central walls as the paper's arena has them, tops displaced by 2.25·tan 45° toward +x,+y:
    // wall A (along x) at height z spans |y - z| <= 0.15·√2, so a ray along +y at x = 2, z = 1 from
    // y = -2 meets it at y = 1 - 0.15·√2, 7 m long (|x| <= 3.5) with 1.35 m gaps to the outer walls.
    EXPECT_NEAR(w.rays().cast(Vec3(2, -2, 1), Vec3::UnitY(), 20), 3 - 0.15 * std::sqrt(2.0), 1e-9);
    EXPECT_NEAR(w.rays().cast(Vec3(3.6, -2, 1), Vec3::UnitY(), 20), 6.85, 1e-9);
    EXPECT_EQ(config::world_preset_takes_tilt("cross-webots"), true);
    EXPECT_EQ(config::world_preset_takes_tilt("cross-30"), false);
    // The paper's arena is unchanged.
    EXPECT_NEAR(World(config::resolve_world("cross", 0.0)).rays().cast(Vec3(4, 1, 1), Vec3::UnitX(), 20), 1.0, 1e-9);
}

TEST(MeshImport, EveryFormatLoadsThePanel) {
    for (const char* name : {"panel.obj", "panel.stl", "panel.ply", "panel.gltf"}) {
        const TriangleMesh m = load_mesh_file((data_dir / name).string());
        EXPECT_EQ(m.size(), 2u) << name;
        const RayCaster rc(m);
        EXPECT_NEAR(rc.cast(Vec3(0, 0.3, 0.5), Vec3::UnitX(), 20), 3.0, 1e-6) << name;
    }
}

TEST(MeshImport, MeshObjectIsPlacedScaledAndRelativeToTheYaml) {
    TempDir dir;
    fs::copy_file(data_dir / "panel.obj", dir.path() / "panel.obj");
    const auto file = dir.write("w.yaml", std::string(R"(
objects:
  - mesh: {file: panel.obj, position: [1, 0, 0], scale: 0.5}
)") + walls);
    const World w(config::load_world_file(file.string()));
    // Scaled to x = 1.5, then moved by +1: the panel is at x = 2.5.
    EXPECT_NEAR(w.rays().cast(Vec3(0, 0.1, 0.2), Vec3::UnitX(), 20), 2.5, 1e-9);
}

TEST(WorldYamlErrors, NameFileKeyAndReason) {
    expect_config_error("objects: [ {box: {center: [0,0,0], size: [1,1,1]} ]\n", "", "malformed YAML");
    expect_config_error("objects:\n  - box: {center: [0,0,0], size: [1,1,1], colour: red}\n" + std::string(walls),
                        "objects[0].box.colour", "unknown key");
    expect_config_error("objects:\n  - box: {center: [0,0,0], size: [1,1]}\n" + std::string(walls),
                        "objects[0].box.size", "expected a list of 3 numbers, got 2");
    expect_config_error("objects:\n  - box: {center: [0,0,zero], size: [1,1,1]}\n" + std::string(walls),
                        "objects[0].box.center[2]", "expected a number");
    expect_config_error("objects:\n  - box: {center: [0,0,0], size: [1,-1,1]}\n" + std::string(walls),
                        "objects[0].box.size", "must be > 0");
    expect_config_error("objects:\n  - quad: [[0,0,0],[1,1,1],[2,2,2],[3,3,3]]\n" + std::string(walls),
                        "objects[0].quad", "degenerate");
    expect_config_error("objects:\n  - sphere: {radius: 1}\n" + std::string(walls), "objects[0]",
                        "unknown object kind 'sphere'");
    expect_config_error("objects: []\n" + std::string(walls), "objects", "no objects");
    expect_config_error("objects:\n  - quad: [[4,-4,0],[4,4,0],[4,4,3],[4,-4,3]]\n", "walkable", "is required");
    expect_config_error("objects:\n  - mesh: {file: missing.obj}\n" + std::string(walls), "objects[0].mesh.file",
                        "does not exist");
    expect_config_error("objects:\n  - cross_arena: {tilt_deg: 75}\n", "objects[0].cross_arena",
                        "pass through the outer walls");
    expect_config_error("objects:\n  - cross_arena: {tilt: 30}\n", "objects[0].cross_arena.tilt", "unknown key");
    expect_config_error("wurld: 1\nobjects: []\n", "wurld", "unknown key");
    expect_config_error("objects:\n  - cross_arena: {}\nwalkable: {rect: [1, 1, 0, 0]}\n", "walkable.rect",
                        "xmin < xmax");
    expect_config_error("objects:\n  - cross_arena: {}\nstart: {points: [[9, 9]]}\n", "start.points[0]",
                        "outside the walkable region");
    expect_config_error("", "", "empty");
    expect_config_error("objects:\n  - box: {center: [0,0,0], size: [1,1,1], size: [2,2,2]}\n" + std::string(walls),
                        "objects[0].box.size", "appears twice");
}

TEST(WorldYamlErrors, BrokenAndDegenerateMeshFiles) {
    TempDir dir;
    fs::copy_file(data_dir / "broken.obj", dir.path() / "broken.obj");
    fs::copy_file(data_dir / "degenerate.obj", dir.path() / "degenerate.obj");
    for (const auto& [name, reason] : {std::pair<std::string, std::string>{"broken.obj", "no non-degenerate triangles"},
                                       {"degenerate.obj", "no non-degenerate triangles"}}) {
        const auto file = dir.write("w.yaml", "objects:\n  - mesh: {file: " + name + "}\n" + walls);
        try {
            config::load_world_file(file.string());
            ADD_FAILURE() << name;
        } catch (const ConfigError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find("objects[0].mesh.file"), std::string::npos) << msg;
            EXPECT_NE(msg.find(name), std::string::npos) << msg;
            EXPECT_TRUE(msg.find(reason) != std::string::npos || msg.find("cannot be read") != std::string::npos)
                << msg;
        }
    }
    EXPECT_THROW(load_mesh_file(dir.path().string()), InputError);  // a directory
}

TEST(SensorYaml, CustomBeamTableAndErrors) {
    TempDir dir;
    const auto ok =
        dir.write("s.yaml", "elevations_deg: [15, 5, -5]\nazimuth_count: 360\nheight: 0.3\nrange_noise_sd: 0.02\n");
    const LidarSpec s = config::resolve_sensor(ok.string());
    EXPECT_EQ(s.beam_count(), 3u * 360u);
    EXPECT_NEAR(s.elevations[0], 15 * M_PI / 180, 1e-15);
    EXPECT_DOUBLE_EQ(s.range_noise_sd, 0.02);
    const auto sph = dir.write("p.yaml", "preset: spherical\nkeep_rows: all\n");
    EXPECT_EQ(config::resolve_sensor(sph.string()).beam_count(), 16200u);
    const auto bad = dir.write("b.yaml", "elevations_deg: [0]\ndropout: 1.5\n");
    try {
        config::resolve_sensor(bad.string());
        ADD_FAILURE();
    } catch (const ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("dropout"), std::string::npos) << e.what();
    }
    EXPECT_THROW(config::resolve_sensor("lidar9000"), InputError);
}

TEST(WorldYaml, PointCloudObjectIsPlacedCroppedAndHitAsSpheres) {
    TempDir dir;
    recording::PointCloud cloud;
    cloud.xyz = {2, 0, 0.5, 2, 0, -3, 2, 1, 0.5};  // the second point is cropped away below z = -1 after moving
    recording::write_ply(dir.path() / "map.ply", cloud);
    const auto file = dir.write("w.yaml", std::string(R"(
objects:
  - point_cloud: {file: map.ply, radius: 0.1, position: [1, 0, 0], crop_z: [-1, 5]}
)") + walls);
    const World w(config::load_world_file(file.string()));
    ASSERT_EQ(w.spheres().size(), 1u);
    EXPECT_EQ(w.spheres()[0].centers.size(), 2u);
    EXPECT_NEAR(w.rays().cast(Vec3(0, 0, 0.5), Vec3::UnitX(), 20), 2.9, 1e-12);
    EXPECT_EQ(w.rays().cast(Vec3(0, 0, -3), Vec3::UnitX(), 20), RayCaster::no_hit);
    const auto files = config::world_file_meshes(file.string());
    ASSERT_EQ(files.size(), 1u);
    EXPECT_NE(files[0].find("map.ply"), std::string::npos);

    expect_config_error("objects:\n  - point_cloud: {file: missing.pcd}\n" + std::string(walls),
                        "objects[0].point_cloud.file", "no such file");
    const std::string ply = (dir.path() / "map.ply").string();
    expect_config_error("objects:\n  - point_cloud: {file: " + ply + ", radius: 0}\n" + std::string(walls),
                        "objects[0].point_cloud.radius", "must be > 0");
    expect_config_error("objects:\n  - point_cloud: {file: " + ply + ", crop_z: [10, 20]}\n" + std::string(walls),
                        "objects[0].point_cloud", "keeps no points");
    expect_config_error("objects:\n  - point_cloud: {file: " + ply + ", size: 1}\n" + std::string(walls),
                        "objects[0].point_cloud.size", "unknown key");
}
