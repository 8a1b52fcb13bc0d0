#pragma once
// Gazebo (SDF) worlds (docs/buildings.md): the geometry of a world file, read with SDFormat (Debian's
// libsdformat, the reference parser) and assimp.
// Takes: a .world or .sdf file, a model path (folders holding NAME/model.config for model://NAME) and a
// resource path (folders that relative file:// URIs are relative to).
// Gives: the triangles and spheres of every visual (or collision) in the world frame, each part named
// by its element path (world/model/.../link/visual) and file, and the files that were read; the files a
// world depends on, for fingerprints. Both find files through one resolver (GazeboResolver).
//
// A geometry's pose is world ← model (an <include>'s <pose> replaces the model's own) ← nested
// models ← link ← visual, composed by SDFormat's pose graph (`relative_to` included). Shapes: box,
// cylinder (a prism whose corners lie on the true surface, at most `cylinder_tolerance` inside it),
// sphere (exact), plane, mesh (uri, <scale>; submesh ignored). `model://ground_plane` (a 100 × 100 m
// plane at z = 0) and `model://sun` (no geometry) are built in, as Gazebo provides them. A heightmap,
// capsule, ellipsoid or polyline, a missing model, mesh or included file, a cycle of includes, a
// NaN or absurd pose or size: InputError naming the file, the line and the element's path.
#include <string>
#include <vector>

#include "bvc3d/world/mesh.hpp"
#include "bvc3d/world/mesh_import.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

struct GazeboOptions {
    enum class Geometry { visual, collision };
    std::vector<std::string> model_path;     // folders searched for model://NAME before the default ones
    std::vector<std::string> resource_path;  // folders searched for relative file:// before GAZEBO_RESOURCE_PATH
    Geometry geometry = Geometry::visual;    // what the sensor sees and the body collides with
    bool skip_missing_models = false;        // leave out includes whose model is not found (listed in the result)
    ColladaUpAxis collada_up_axis = ColladaUpAxis::ignored;  // as Gazebo reads meshes
};

inline constexpr double cylinder_tolerance = 1e-3;  // m, largest gap between a cylinder's prism and its surface
inline constexpr double ground_plane_size = 100.0;  // m, the side of Gazebo's ground plane
inline constexpr double min_mesh_scale = 1e-6;      // |scale| below this (or above 1/this) is a mistake

// One geometry element and where its triangles (or its sphere) are in the scene.
struct GazeboPart {
    std::string path;       // world/model/.../link/visual
    std::string file;       // the SDF file that declares it
    int line = 0;           // its line there (0: unknown)
    std::string shape;      // box, cylinder, sphere, plane or mesh
    std::string mesh_file;  // the mesh file read (meshes only)
    std::size_t first_triangle = 0, triangle_count = 0;
    int sphere_set = -1;           // spheres: which set of `spheres` ...
    std::size_t sphere_index = 0;  // ... and which center in it
    bool ground_plane = false;     // Gazebo's own ground plane (model://ground_plane, built in)
};

struct GazeboScene {
    std::string name;  // the world's name
    TriangleMesh mesh;
    std::vector<SphereSet> spheres;  // one set per radius
    std::vector<GazeboPart> parts;
    std::vector<std::string> missing_models;  // left out (skip_missing_models): "NAME at world/..." each
    std::vector<std::string> files;           // every file read: the world, model files, meshes (sorted)
};

// The folders searched for model://NAME, in order: `options.model_path`, the `models` folder beside
// the world file's folder, then those of GAZEBO_MODEL_PATH (colon-separated).
std::vector<std::string> gazebo_model_path(const std::string& world_file, const GazeboOptions& options);

// The folders searched for relative file:// URIs (Gazebo's rule; a ROS package exports its folder there
// as `gazebo_media_path`), in order: `options.resource_path`, then those of GAZEBO_RESOURCE_PATH
// (colon-separated). Unlike Gazebo, not the current folder: a world loads the same from anywhere.
std::vector<std::string> gazebo_resource_path(const GazeboOptions& options);

// Where a world's URIs lead, for the loader and for the fingerprint's list of files alike:
// - model://NAME: NAME's folder on the model path; model://NAME/REST: REST inside it;
// - file:///ABS and /ABS: that file;
// - file://REL: the first folder of the resource path holding REL;
// - REL (a plain relative path): beside the SDF file that names it, else as file://REL.
class GazeboResolver {
public:
    GazeboResolver(const std::string& world_file, const GazeboOptions& options);

    // NAME's folder (holding model.config) on the model path; "" if none holds it.
    std::string model_folder(const std::string& name) const;
    // The mesh file `uri` names in the SDF file `sdf_file`, or why there is none (naming the URI and
    // every place searched).
    struct Found {
        std::string file;
        std::string error;  // when `file` is empty
    };
    Found mesh_file(const std::string& uri, const std::string& sdf_file) const;

    const std::vector<std::string>& model_path() const { return model_path_; }
    const std::vector<std::string>& resource_path() const { return resource_path_; }

private:
    std::vector<std::string> model_path_, resource_path_;
};

GazeboScene load_gazebo_world(const std::string& file, const GazeboOptions& options = {});

// The files a world depends on, found without SDFormat (for fingerprints, which must be cheap): the
// world file, every file in the folders of the models it names (model://NAME in its text, and in
// theirs) and every mesh file a <mesh> of these SDF files names (through GazeboResolver, wherever it
// lies). It may list more files than load_gazebo_world() reads (a model's unread files, meshes in
// comments), never fewer.
std::vector<std::string> gazebo_world_files(const std::string& file, const GazeboOptions& options = {});

// Whether `path` names a Gazebo world file by its extension (.world or .sdf).
bool is_gazebo_file(const std::string& path);

}  // namespace bvc3d
