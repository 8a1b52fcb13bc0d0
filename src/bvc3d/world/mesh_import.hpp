#pragma once
// Triangle meshes from files (OBJ, STL, PLY, glTF, ... anything assimp reads).
#include <string>

#include "bvc3d/world/mesh.hpp"

namespace bvc3d {

// The largest mesh file and mesh: beyond them a world is a mistake (or would not fit in memory).
inline constexpr double max_mesh_file_bytes = 1e9;
inline constexpr double max_mesh_triangles = 2e7;

// How a Collada file's <up_axis> is read (the other formats declare no axis).
enum class ColladaUpAxis {
    assimp,   // assimp's convention: turned so that the declared up axis is +y (meshes of world YAML)
    ignored,  // the coordinates as written, +z up, whatever the file declares: as Gazebo reads meshes
    to_z_up,  // turned so that the declared up axis is +z
};

struct MeshFileOptions {
    ColladaUpAxis collada_up_axis = ColladaUpAxis::assimp;
};

// Loads every triangle of every mesh in the file, with node transforms applied, in the file's
// units (Collada's <unit> applied). Degenerate triangles are dropped. Throws InputError naming the
// file and the reason when the file is missing, unreadable, not a mesh, truncated or inconsistent
// (mesh_check.hpp), too large, has coordinates beyond ±max_coordinate, or holds no usable triangle.
TriangleMesh load_mesh_file(const std::string& path, const MeshFileOptions& options = {});

}  // namespace bvc3d
