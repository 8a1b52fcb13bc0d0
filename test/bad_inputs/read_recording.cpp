// bvc3d_read_recording: the recording stage's readers from the command line, for the bad-input
// corpus (test/bad_inputs) until the program has recording commands of its own. Reads one input and
// prints what it holds; bad input ends like the program's: one "bvc3d: error:" line, status 2.
//   bvc3d_read_recording scan FILE            a .pcd, .ply or .bin scan
//   bvc3d_read_recording poses FORMAT FILE    kitti, tum, matrix or auto
//   bvc3d_read_recording list PATH            a folder, a list file or a scan
//   bvc3d_read_recording extrinsics FILE      12 or 16 numbers
#include <cstdio>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/pose_file.hpp"
#include "bvc3d/recording/scan_file.hpp"
#include "bvc3d/recording/scan_list.hpp"

int main(int argc, char** argv) {
    using namespace bvc3d::recording;
    const std::string what = argc > 1 ? argv[1] : "";
    try {
        if (what == "scan" && argc == 3) {
            const auto cloud = read_scan(argv[2]);
            std::printf("%zu points (%zu dropped)\n", cloud.size(), cloud.dropped_nonfinite);
        } else if (what == "poses" && argc == 4) {
            std::printf("%zu poses\n", read_poses(argv[3], parse_pose_format(argv[2])).size());
        } else if (what == "list" && argc == 3) {
            std::printf("%zu scans\n", list_scans(argv[2]).size());
        } else if (what == "extrinsics" && argc == 3) {
            read_extrinsics(argv[2]);
            std::printf("extrinsics read\n");
        } else {
            std::fprintf(stderr,
                         "bvc3d: usage error: bvc3d_read_recording scan FILE | poses FORMAT FILE | list PATH | "
                         "extrinsics FILE\n");
            return 2;
        }
    } catch (const bvc3d::InputError& e) {
        std::fprintf(stderr, "bvc3d: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bvc3d: internal error: %s\n", e.what());
        return 3;
    }
    return 0;
}
