#include "bvc3d/sensor/return_source.hpp"

#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

void ArrayReturnSource::returns(std::uint64_t step, const Pose&, const std::vector<char>&, Scan& out) {
    if (step >= scans_.size())
        throw InputError("returns were given for " + std::to_string(scans_.size()) + " steps; step " +
                         std::to_string(step) + " has none");
    out = scans_[step];
}

}  // namespace bvc3d
