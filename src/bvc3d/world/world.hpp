#pragma once
// World stage: the static 3-D geometry the robot moves through and its sensors see.
// Takes: a WorldDescription (triangles, points drawn as small spheres, floor regions), built in
// code, from YAML, meshes or point clouds.
// Gives: ray casts (RayCaster, through Embree) and the geometry for body collision.
#include <memory>
#include <optional>
#include <string>

#include "bvc3d/world/mesh.hpp"

namespace bvc3d {

class RayCaster;

// Where a walk may start: one of `points` (uniformly), or else a uniform point of `region`.
struct StartRegion {
    std::vector<Vec2> points;
    Polygon2 region;
};

// Points drawn as spheres of one radius: a registered point map of a building (docs/worlds.md).
struct SphereSet {
    std::vector<Vec3> centers;
    double radius = 0.05;  // m
};

struct WorldDescription {
    std::string name;
    std::string file;  // the YAML file it came from (errors about its keys name it); empty for presets
    std::optional<double> tilt_deg;  // the tilt of the cross arena, when the world is (or holds) one
    TriangleMesh mesh;
    std::vector<SphereSet> spheres;
    Polygon2 walkable;  // the robot's body stays inside this floor polygon
    StartRegion start;

    bool has_geometry() const;
    // The box holding every triangle and sphere (empty for a world without geometry).
    Eigen::AlignedBox3d bounds() const;
};

// The paper's arena (docs/model-reference.md#the-cross-arena).
struct CrossArenaParams {
    double tilt_deg = 0.0;
    std::string lean = "+x+y";  // the corner the central walls lean toward
    double half_width = 5.0;
    double height = 2.5;
    double wall_length = 7.0;
    double wall_thickness = 0.3;
    double start_offset = 4.0;  // start corners at (±offset, ±offset)
};

// Checks the parameters (throws InputError naming the parameter) and builds the arena.
WorldDescription cross_arena(const CrossArenaParams& p);

class World {
public:
    explicit World(WorldDescription description);
    static World cross(const CrossArenaParams& p = {}) { return World(cross_arena(p)); }

    const WorldDescription& description() const { return desc_; }
    const std::string& name() const { return desc_.name; }
    const TriangleMesh& mesh() const { return desc_.mesh; }
    const std::vector<SphereSet>& spheres() const { return desc_.spheres; }
    const RayCaster& rays() const { return *caster_; }

private:
    WorldDescription desc_;
    std::shared_ptr<const RayCaster> caster_;  // immutable after construction: shared by copies
};

}  // namespace bvc3d
