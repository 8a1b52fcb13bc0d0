#include "bvc3d/world/mesh_import.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/world/mesh_check.hpp"

namespace bvc3d {

namespace {

// assimp drops what it cannot use (faces with out-of-range indices, ...) and only logs a warning.
// Its logger is process-wide: one stream, installed once, hands each warning to the thread that
// is loading, so that such a file is refused instead of becoming part of a world.
class WarningCapture : public Assimp::LogStream {
public:
    static thread_local std::vector<std::string>* current;
    void write(const char* message) override {
        if (current) current->emplace_back(message);
    }
};
thread_local std::vector<std::string>* WarningCapture::current = nullptr;

void capture_assimp_warnings() {
    static std::once_flag once;
    std::call_once(once, [] {
        if (Assimp::DefaultLogger::isNullLogger()) Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
        Assimp::DefaultLogger::get()->attachStream(new WarningCapture, Assimp::Logger::Warn | Assimp::Logger::Err);
    });
}

// A warning that means the file's data was not all used.
bool data_dropped(const std::string& warning) {
    for (const char* sign : {"out-of-range", "out of range", "dropped", "truncated"})
        if (warning.find(sign) != std::string::npos) return true;
    return false;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
    Eigen::Matrix4d e;
    for (unsigned r = 0; r < 4; ++r)
        for (unsigned c = 0; c < 4; ++c) e(r, c) = m[r][c];
    return e;
}

void collect(const aiScene* scene, const aiNode* node, const Eigen::Matrix4d& parent, TriangleMesh& out,
             int depth = 0) {
    if (depth > 1000) throw InputError("its node hierarchy is more than 1000 levels deep");
    const Eigen::Matrix4d xf = parent * to_eigen(node->mTransformation);
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        if (node->mMeshes[i] >= scene->mNumMeshes) throw InputError("a node refers to a mesh that does not exist");
        const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue;  // points and lines are not surfaces
            Vec3 v[3];
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= mesh->mNumVertices)
                    throw InputError("face " + std::to_string(f) + " refers to vertex " +
                                     std::to_string(face.mIndices[k]) + " of " + std::to_string(mesh->mNumVertices));
                const aiVector3D& p = mesh->mVertices[face.mIndices[k]];
                v[k] = (xf * Eigen::Vector4d(p.x, p.y, p.z, 1.0)).head<3>();
            }
            for (const auto& c : v)
                if (!c.allFinite())
                    throw InputError(
                        "a vertex is not finite (values beyond ±3.4e38 do not fit the 32-bit floats "
                        "meshes are read in)");
            if (triangle_double_area(v[0], v[1], v[2]) > 1e-12) out.add_triangle(v[0], v[1], v[2]);
            if (static_cast<double>(out.size()) > max_mesh_triangles)
                throw InputError("it holds more than " + format_number(max_mesh_triangles) + " triangles, the limit");
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], xf, out, depth + 1);
}

bool is_collada(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".dae";
}

// assimp 5.2 cannot read a number list that starts with white space (`<color> 0.3 0.3 0.3 1</color>`,
// assimp issue #4951, fixed in 5.4): such files are read again with the white space between a tag
// and a number removed, which changes no value (XML lists of numbers ignore it).
std::string without_space_before_numbers(const std::string& xml) {
    std::string out;
    out.reserve(xml.size());
    for (std::size_t i = 0; i < xml.size(); ++i) {
        out += xml[i];
        if (xml[i] != '>') continue;
        std::size_t j = i + 1;
        while (j < xml.size() && std::isspace(static_cast<unsigned char>(xml[j]))) ++j;
        if (j < xml.size() && j > i + 1 &&
            (std::isdigit(static_cast<unsigned char>(xml[j])) || xml[j] == '-' || xml[j] == '+' || xml[j] == '.'))
            i = j - 1;
    }
    return out;
}

}  // namespace

TriangleMesh load_mesh_file(const std::string& path, const MeshFileOptions& options) {
    const std::string where = "mesh file '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(where + ": file does not exist");
    if (std::filesystem::is_directory(path, ec)) throw InputError(where + ": is a folder, not a file");
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(where + ": is not a regular file");
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(where + ": cannot be read (" + ec.message() + ")");
    if (static_cast<double>(size) > max_mesh_file_bytes)
        throw InputError(where + ": is " + std::to_string(size) + " bytes; the limit for a mesh file is " +
                         format_number(max_mesh_file_bytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where + ": cannot be opened for reading");
    std::string bytes(size, '\0');
    if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) throw InputError(where + ": cannot be read");
    try {
        check_mesh_file(path, bytes);
    } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
    }

    capture_assimp_warnings();
    std::vector<std::string> warnings;
    WarningCapture::current = &warnings;
    Assimp::Importer importer;
    const bool collada = is_collada(path);
    if (collada && options.collada_up_axis == ColladaUpAxis::ignored)
        importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
    // Validation checks what assimp built (indices in range, ...) before we read it.
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(path, flags);
    if (!scene && collada && std::string(importer.GetErrorString()).find("Cannot parse string") != std::string::npos) {
        warnings.clear();
        const std::string fixed = without_space_before_numbers(bytes);
        scene = importer.ReadFileFromMemory(fixed.data(), fixed.size(), flags, "dae");
    }
    WarningCapture::current = nullptr;
    if (!scene || !scene->mRootNode || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
        throw InputError(where + ": cannot be read as a mesh (" + importer.GetErrorString() + ")");
    for (auto w : warnings)
        if (data_dropped(w)) {
            while (!w.empty() && (w.back() == '\n' || w.back() == ' ')) w.pop_back();
            const auto colon = w.find(": ");  // "Warn,  T0: <message>"
            throw InputError(where + ": is inconsistent (" + (colon == std::string::npos ? w : w.substr(colon + 2)) +
                             ")");
        }
    TriangleMesh mesh;
    // assimp turned the declared up axis to +y; +y becomes +z: (x, y, z) -> (x, -z, y).
    Eigen::Matrix4d root = Eigen::Matrix4d::Identity();
    if (collada && options.collada_up_axis == ColladaUpAxis::to_z_up)
        root.topLeftCorner<3, 3>() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    try {
        collect(scene, scene->mRootNode, root, mesh);
    } catch (const InputError& e) {
        throw InputError(where + ": " + e.what());
    }
    if (mesh.empty()) throw InputError(where + ": contains no non-degenerate triangles");
    return mesh;
}

}  // namespace bvc3d
