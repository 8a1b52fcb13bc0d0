// The shortest path through the C++ API: a world, one scan, the BVC rates, one place-cell step.
//   build/example/minimal
#include <algorithm>
#include <cstdio>

#include "bvc3d/config/model_spec.hpp"

int main() {
    using namespace bvc3d;
    const World world = World::cross({.tilt_deg = 45});  // the paper's arena, walls leaning 45°
    const ModelSpec model = model_preset("3d-0.2");      // Table I: spherical scanner, layers 0 and 0.2 rad
    const Scan scan = Lidar(model.sensor).scan(world, Pose::on_floor(1.0, 2.0, 0.5));
    const BoundaryVectorLayer layer(model.bvc);
    std::vector<double> bvc(layer.n_cells());
    layer.rates(scan, bvc);
    PlaceCellNetwork net(model.bvc.n_cells(), model.place, /*seed=*/0);
    const auto place = net.step(bvc, /*learn=*/true);
    int active = 0;
    for (float v : place) active += v > 0;
    std::printf("%zu returns; first: range %.3f m, azimuth %.3f rad, elevation %.3f rad\n", scan.size(), scan[0].range,
                scan[0].azimuth, scan[0].elevation);
    std::printf("%zu BVCs, max rate %.1f; %d of %d place cells active after one step\n", bvc.size(),
                *std::max_element(bvc.begin(), bvc.end()), active, net.n_place());
}
