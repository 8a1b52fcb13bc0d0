#pragma once
// World stage: the static 3-D geometry the robot moves through and its sensors see.
// Takes: a WorldDescription (triangles, points drawn as small spheres, floor regions), built in
// code, from YAML, meshes or point clouds.
// Gives: ray casts (RayCaster, through Embree) and the geometry for body collision.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/world/mesh.hpp"

namespace bvc3d {

class RayCaster;

// Where a walk may start: one of `points` (uniformly), or else a uniform point of `region`.
struct StartRegion {
    std::vector<Vec2> points;
    Polygon2 region;
};

// Where a flying agent's body may be (docs/flying.md): a floor region × [z_min, z_max]. The whole
// body stays inside it.
struct FlightVolume {
    Polygon2 region;
    double z_min = 0.0, z_max = 0.0;  // m
    Eigen::AlignedBox3d bounds() const;
};

// Points drawn as spheres of one radius: a registered point map of a building (docs/worlds.md).
struct SphereSet {
    std::vector<Vec3> centers;
    double radius = 0.05;  // m
};

// A named piece of a world's geometry (an SDF visual or collision: docs/buildings.md), for messages,
// tests and the viewer: a range of triangles, or one sphere.
struct WorldPart {
    std::string name;   // its element path: world/model/link/visual
    std::string shape;  // box, cylinder, sphere, plane or mesh
    std::string file;   // the file that declares it
    std::size_t first_triangle = 0, triangle_count = 0;
    int sphere_set = -1;  // a sphere: its set in `spheres` and its index there
    std::size_t sphere_index = 0;
};

struct WorldDescription {
    std::string name;
    std::string file;                // the YAML file it came from (errors about its keys name it); empty for presets
    std::optional<double> tilt_deg;  // the tilt of the cross arena, when the world is (or holds) one
    TriangleMesh mesh;
    std::vector<SphereSet> spheres;
    Polygon2 walkable;  // the robot's body stays inside this floor polygon (none in a flight-only world)
    StartRegion start;
    std::optional<FlightVolume> flight;  // where a flying agent may fly; none in a ground-only world
    // Where the floor the ground agent stands on ends (a stairwell, the edge of a slab): its body may
    // not cross them. They are no geometry: the sensors do not see them.
    std::vector<std::array<Vec2, 2>> drop_edges;
    // A building read from a file whose floors are not at z = 0 (docs/buildings.md#floors) was moved
    // down by the chosen floor's height, so that its floor is at z = 0: file z = world z + floor_z.
    double floor_z = 0.0;
    // The ground robot's body passes over geometry lower than this above the floor (a carpet, a
    // door sill); 0: everything above the floor blocks it.
    double step_height = 0.0;
    std::vector<WorldPart> parts;  // named pieces of `mesh` and `spheres` (empty: none named)
    // Models a building's file includes but that were not found and were left out on request
    // (docs/buildings.md: missing_models: skip), as "NAME at world/...".
    std::vector<std::string> left_out;

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
    double start_offset = 4.0;      // start corners at (±offset, ±offset)
    double flight_clearance = 0.2;  // the flight volume: the floor × [clearance, height - clearance]

    // The arena as the authors built it in Webots (docs/worlds.md#presets): outer walls 0.3 m thick
    // centered on ±5 m, so their inner faces stand at ±4.85 m, and 2.4 m high under a 0.3 m
    // ceiling slab whose underside is at 2.25 m; the central cross as the paper's (7 × 0.3 m,
    // floor to ceiling). Only the inner faces and the ceiling's underside can be reached or seen.
    static CrossArenaParams webots(double tilt_deg = 0.0);
};

// The corners the central walls may lean toward (CrossArenaParams::lean): "+x+y", "+x-y", "-x+y", "-x-y".
const std::vector<std::string>& cross_arena_leans();

// Checks the parameters (throws InputError naming the parameter) and builds the arena.
WorldDescription cross_arena(const CrossArenaParams& p);

// Flight-only worlds (docs/flying.md#worlds): no walkable region, a flight volume with 0.2 m
// clearance from floor and ceiling. `flight-room`: an empty 5.8 × 4.6 × 2.7 m room (the size of the
// bats' room of Yartsev & Ulanovsky 2013). `atrium`: 10 × 10 × 6 m with a 1.5 m wide mezzanine ring
// (z 2.8-3.0 m) along the walls and two 0.6 m square pillars from floor to ceiling.
WorldDescription flight_room();
WorldDescription atrium();

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
