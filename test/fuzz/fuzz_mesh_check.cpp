// The structure checks of mesh files (world::check_mesh_file): the first byte picks the format
// (.ply, .obj, .stl), the rest is the file.
#include "bvc3d/world/mesh_check.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* const extensions[] = {"x.ply", "x.obj", "x.stl"};
    const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
    return bvc3d::fuzz::expect_input_errors([&] { bvc3d::check_mesh_file(extensions[data[0] % 3], bytes); });
}
