#include "bvc3d/sensor/lidar_models.hpp"

#include "bvc3d/core/angles.hpp"

namespace bvc3d {

const std::vector<LidarModel>& lidar_models() {
    // name, description, top°, bottom°, beams, columns, min m, max m, range noise σ m
    static const std::vector<LidarModel> models{
        // Velodyne VLP-16 (Puck) datasheet: 16 channels, ±15° in 2° steps, 0.2° azimuth at 10 Hz (1800
        // columns), up to 100 m, ±3 cm accuracy; 0.5 m nearest return.
        {"vlp16", "Velodyne VLP-16: 16 beams +15°..-15° by 2°", 15.0, -15.0, 16, 1800, 0.5, 100.0, 0.03},
        // Velodyne HDL-32E datasheet: 32 lasers +10.67°..-30.67° (≈1.33° apart), 0.16° azimuth at 10 Hz
        // (2170 columns), 1-100 m, ±2 cm.
        {"hdl32", "Velodyne HDL-32E: 32 beams +10.67°..-30.67° by 1.33°", 10.67, -30.67, 32, 2170, 1.0, 100.0, 0.02},
        // Velodyne HDL-64E S2 (KITTI's scanner). Its specification sheet gives a vertical field of view of
        // +2° up to -24.9° down "with 64 equally spaced angular subdivisions (approximately 0.4°)" (SPEC
        // §14; KITTI's setup paper, Geiger et al. 2013: "26.9° vertical"); these are those 64 design
        // angles, +2.0° - k·26.9°/63. A unit's own calibration (its db.xml; KITTI's velodyne calibration)
        // differs from them by a few tenths of a degree per laser. 0.09° azimuth at 10 Hz (4500 columns),
        // 0.9-120 m, ±2 cm.
        {"hdl64", "Velodyne HDL-64E S2 (KITTI): 64 beams +2.0°..-24.9°, equally spaced", 2.0, -24.9, 64, 4500, 0.9,
         120.0, 0.02},
        // Ouster OS1-64 and OS1-128 datasheets: 45° vertical field of view (+22.5°..-22.5°), beams evenly
        // spaced, 1024 columns per turn at 10 Hz, 0.3-100 m, ±3 cm.
        {"os1-64", "Ouster OS1-64: 64 beams +22.5°..-22.5°, evenly spaced", 22.5, -22.5, 64, 1024, 0.3, 100.0, 0.03},
        {"os1-128", "Ouster OS1-128: 128 beams +22.5°..-22.5°, evenly spaced", 22.5, -22.5, 128, 1024, 0.3, 100.0,
         0.03},
    };
    return models;
}

const LidarModel* find_lidar_model(const std::string& name) {
    for (const auto& m : lidar_models())
        if (m.name == name) return &m;
    return nullptr;
}

LidarSpec lidar_model_spec(const LidarModel& m) {
    LidarSpec s;
    s.name = m.name;
    s.elevations.resize(static_cast<std::size_t>(m.beams));
    for (int i = 0; i < m.beams; ++i) {
        const double deg = m.beams == 1 ? m.top_deg : m.top_deg + (m.bottom_deg - m.top_deg) * i / (m.beams - 1);
        s.elevations[static_cast<std::size_t>(i)] = deg_to_rad(deg);
    }
    s.azimuth_count = m.columns;
    s.height = lidar_model_height;
    s.min_range = m.min_range;
    s.max_range = m.max_range;
    s.range_noise_sd = m.range_noise_sd;
    return s;
}

}  // namespace bvc3d
