#pragma once
// PLY scans (the Stanford polygon format, 1.0). Takes: a .ply file. Gives: the x, y, z of its
// vertex element as a PointCloud, without NaN/inf points (counted in dropped_nonfinite). And
// writes clouds as PLY.
//
// Read: format ascii, binary_little_endian and binary_big_endian. The vertex element must have
// scalar properties x, y, z of type float/float32 or double/float64. Every other property
// (scalar or list, any type) and every other element (faces, edges, ...) is skipped, before or
// after the vertices. In ascii each element instance is one line (as all writers do it; blank
// lines are ignored). Data beyond the last element, or short of it, is an error.
// Anything malformed throws InputError naming the file, the line or element, and the reason.
#include <filesystem>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

enum class PlyEncoding { ascii, binary_little_endian, binary_big_endian };
enum class PlyPrecision { float32, float64 };  // vertex x, y, z as "float" or "double"

PointCloud read_ply(const std::filesystem::path& file);

// Writes one vertex element with properties x y z; all-or-nothing (temporary + rename).
void write_ply(const std::filesystem::path& file, const PointCloud& cloud,
               PlyEncoding encoding = PlyEncoding::binary_little_endian,
               PlyPrecision precision = PlyPrecision::float32);

}  // namespace bvc3d::recording
