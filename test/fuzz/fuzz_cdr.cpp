// CDR messages (recording::cdr): the first byte picks the message type (PointCloud2, whose points are
// then gathered, Odometry, PoseStamped, TFMessage), the rest is the message with its encapsulation header.
#include "bvc3d/recording/cdr.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace bvc3d::recording;
    if (size == 0) return 0;
    const std::span<const std::uint8_t> rest(data + 1, size - 1);
    return bvc3d::fuzz::expect_input_errors([&] {
        switch (data[0] % 4) {
            case 0:
                cloud_points(cdr::decode_cloud(rest));
                break;
            case 1:
                cdr::decode_odometry(rest);
                break;
            case 2:
                cdr::decode_pose_stamped(rest);
                break;
            default:
                cdr::decode_tf(rest);
        }
    });
}
