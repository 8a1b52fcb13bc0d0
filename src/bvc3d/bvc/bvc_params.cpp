#include "bvc3d/bvc/bvc_params.hpp"

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

const params::Table<BvcParams>& BvcParams::table() {
    using namespace params;
    static const Table<BvcParams> t(
        "BVC layer",
        {reals("elevations", &BvcParams::elevations, closed(-pi / 2, pi / 2),
               "rad, the layers' preferred elevations; [] is the 2-D model")
             .in_radians()
             .sizes(0, 1024),
         integer("n_dir", &BvcParams::n_dir, closed(1, 4096), "preferred azimuths, 2π/n_dir apart"),
         integer("n_per_axis", &BvcParams::n_per_axis, closed(1, 100000), "preferred distances per direction"),
         real("max_dist", &BvcParams::max_dist, above(0), "m, the largest preferred distance"),
         real("sigma_r", &BvcParams::sigma_r, above(0), "m, distance tuning width"),
         real("sigma_theta", &BvcParams::sigma_theta, above(0), "rad, azimuth tuning width"),
         real("sigma_phi", &BvcParams::sigma_phi, above(0), "rad, elevation tuning width"),
         choice("normalization", &BvcParams::normalization,
                {{BvcNormalization::per_step_max, "per_step_max"},
                 {BvcNormalization::none, "none"},
                 {BvcNormalization::fixed, "fixed"}},
                "per_step_max: raw / (2·max raw); none; fixed: raw / norm_constant"),
         real("norm_constant", &BvcParams::norm_constant, above(0), "the divisor of `fixed` normalization"),
         choice("reading", &BvcParams::reading,
                {{BvcReading::gaussian, "gaussian"}, {BvcReading::nearest_beam, "nearest_beam"}},
                "gaussian (the paper's equations) or nearest_beam (one return per direction, 2-D only)")});
    return t;
}

void BvcParams::validate() const {
    table().check(*this);
    const double cells = static_cast<double>(n_layers()) * n_dir * n_per_axis;
    if (cells > max_cells)
        table().fail("n_per_axis", "makes " + std::to_string(n_layers()) + " layers × " + std::to_string(n_dir) +
                                       " directions × " + std::to_string(n_per_axis) + " distances = " +
                                       format_number(cells) + " cells; the limit is " + format_number(max_cells));
    if (reading == BvcReading::nearest_beam && !elevations.empty())
        table().fail("reading",
                     "cannot be nearest_beam with elevation layers (the nearest_beam reading is a 2-D model)");
}

}  // namespace bvc3d
