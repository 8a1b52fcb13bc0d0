#pragma once
// PCD v0.7 scans (the Point Cloud Library's format). Takes: a .pcd file. Gives: its x, y, z as a
// PointCloud, without NaN/inf points (an organized cloud's "no return"), counted in
// dropped_nonfinite. And writes clouds as PCD.
//
// Read: DATA ascii, binary and binary_compressed (LZF, the field-major block). x, y, z must be
// TYPE F, SIZE 4 or 8, COUNT 1; any other field (any TYPE I/U/F, SIZE 1/2/4/8, any COUNT) is
// skipped. Binary data is little-endian (as every PCL writer on x86/ARM writes it). WIDTH × HEIGHT
// must equal POINTS (POINTS may be left out). VIEWPOINT is ignored: points stay in the frame they
// were written in. VERSION, when present, must be 0.7 (or .7); COUNT defaults to 1. Fields named
// "_" (PCL's padding) take bytes in binary data but no values in ascii lines, as PCL writes them.
// Anything else malformed throws InputError naming the file, the line or point, and the reason.
#include <filesystem>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

enum class PcdEncoding { ascii, binary, binary_compressed };
enum class PcdPrecision { f4, f8 };  // x, y, z as TYPE F SIZE 4 (float) or SIZE 8 (double)

PointCloud read_pcd(const std::filesystem::path& file);

// Writes an unorganized cloud (HEIGHT 1) with fields x y z; all-or-nothing (temporary + rename).
void write_pcd(const std::filesystem::path& file, const PointCloud& cloud, PcdEncoding encoding = PcdEncoding::binary,
               PcdPrecision precision = PcdPrecision::f4);

}  // namespace bvc3d::recording
