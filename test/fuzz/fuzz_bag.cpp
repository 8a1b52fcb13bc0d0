// ROS 1 bags (recording::open_ros1_bag, Debian's rosbag storage library under it) and ROS 1 messages
// (the message packages' deserializers): the first byte picks which, the rest is the file or the
// message. Every message is decoded as its topic's type says and every cloud's points are gathered.
#include "bvc3d/recording/bag.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace bvc3d::recording;
    if (size == 0) return 0;
    const std::vector<std::uint8_t> rest(data + 1, data + size);
    return bvc3d::fuzz::expect_input_errors([&] {
        switch (data[0] % 5) {
            case 0: {
                const auto bag = open_ros1_bag(bvc3d::fuzz::as_file(rest.data(), rest.size(), ".bag"));
                bvc3d::fuzz::read_every_message(*bag);
                break;
            }
            case 1:
                cloud_points(ros1::decode_cloud(rest));
                break;
            case 2:
                ros1::decode_odometry(rest);
                break;
            case 3:
                ros1::decode_pose_stamped(rest);
                break;
            default:
                ros1::decode_tf(rest);
        }
    });
}
