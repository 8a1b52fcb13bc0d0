#include "bvc3d/world/mesh_import.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <filesystem>
#include <fstream>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
    Eigen::Matrix4d e;
    for (unsigned r = 0; r < 4; ++r)
        for (unsigned c = 0; c < 4; ++c) e(r, c) = m[r][c];
    return e;
}

void collect(const aiScene* scene, const aiNode* node, const Eigen::Matrix4d& parent, TriangleMesh& out) {
    const Eigen::Matrix4d xf = parent * to_eigen(node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue;  // points and lines are not surfaces
            Vec3 v[3];
            for (int k = 0; k < 3; ++k) {
                const aiVector3D& p = mesh->mVertices[face.mIndices[k]];
                v[k] = (xf * Eigen::Vector4d(p.x, p.y, p.z, 1.0)).head<3>();
            }
            if (!(v[0].allFinite() && v[1].allFinite() && v[2].allFinite()))
                throw InputError("mesh file has a non-finite vertex");
            if (triangle_double_area(v[0], v[1], v[2]) > 1e-12) out.add_triangle(v[0], v[1], v[2]);
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], xf, out);
}

}  // namespace

TriangleMesh load_mesh_file(const std::string& path) {
    const std::string where = "mesh file '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(where + ": file does not exist");
    if (std::filesystem::is_directory(path, ec)) throw InputError(where + ": is a directory, not a file");
    if (!std::ifstream(path).good()) throw InputError(where + ": cannot be opened for reading");

    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    if (!scene || !scene->mRootNode || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
        throw InputError(where + ": cannot be read as a mesh (" + importer.GetErrorString() + ")");
    TriangleMesh mesh;
    try {
        collect(scene, scene->mRootNode, Eigen::Matrix4d::Identity(), mesh);
    } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
    }
    if (mesh.empty()) throw InputError(where + ": contains no non-degenerate triangles");
    return mesh;
}

}  // namespace bvc3d
