#include "bvc3d/recording/scan_file.hpp"

#include <algorithm>
#include <cctype>
#include <string>

#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/kitti_bin.hpp"
#include "bvc3d/recording/parsing.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/ply.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;

std::optional<ScanFormat> scan_format_of(const fs::path& file) {
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension == ".pcd") return ScanFormat::pcd;
    if (extension == ".ply") return ScanFormat::ply;
    if (extension == ".bin") return ScanFormat::kitti_bin;
    return std::nullopt;
}

PointCloud read_scan(const fs::path& file) {
    const auto format = scan_format_of(file);
    if (!format)
        throw detail::input_error(file, "unknown scan file extension " +
                                            detail::quote_token(file.extension().string()) +
                                            ": expected .pcd, .ply or .bin (KITTI)");
    switch (*format) {
        case ScanFormat::pcd:
            return read_pcd(file);
        case ScanFormat::ply:
            return read_ply(file);
        case ScanFormat::kitti_bin:
            return read_kitti_bin(file);
    }
    throw detail::input_error(file, "unknown scan format");
}

}  // namespace bvc3d::recording
