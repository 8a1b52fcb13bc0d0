#pragma once
// Structure checks of mesh files, before assimp reads them. assimp accepts truncated or
// inconsistent files (a PLY header promising 100 vertices over 3 lines of data became junk
// triangles; a truncated binary PLY crashed it), so PLY, OBJ and STL files are walked first: the
// data must hold exactly what the header declares, numbers must be numbers, and every face must
// refer to vertices that exist. (glTF is checked by assimp's own validation.)
// Takes: a file's name and its bytes. Gives: nothing, or an InputError with the reason (the caller
// adds the file's name).
#include <filesystem>
#include <string_view>

namespace bvc3d {

// Checks the formats above by the file's extension (any letter case); other formats pass.
void check_mesh_file(const std::filesystem::path& path, std::string_view bytes);

}  // namespace bvc3d
