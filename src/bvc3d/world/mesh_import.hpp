#pragma once
// Triangle meshes from files (OBJ, STL, PLY, glTF, ... anything assimp reads).
#include <string>

#include "bvc3d/world/mesh.hpp"

namespace bvc3d {

// Loads every triangle of every mesh in the file, with node transforms applied, in the file's
// units. Degenerate triangles are dropped. Throws InputError naming the file and the reason when
// the file is missing, unreadable, not a mesh, or holds no usable triangle.
TriangleMesh load_mesh_file(const std::string& path);

}  // namespace bvc3d
