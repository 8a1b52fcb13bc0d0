#pragma once
// Takes a box and a seeded stream. Gives a point uniform in the box, its coordinates drawn last axis first
// (y, x; z, y, x): the order g++ evaluated them in when each caller drew them as a constructor's arguments, an
// order C++ leaves open (clang drew x first). Kept, so that every seed's results stay what they were and are the
// same whichever compiler builds them.
#include <Eigen/Geometry>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

inline Vec2 uniform_point(const Eigen::AlignedBox2d& box, Rng& rng) {
    const double y = rng.uniform(box.min().y(), box.max().y());
    const double x = rng.uniform(box.min().x(), box.max().x());
    return {x, y};
}

inline Vec3 uniform_point(const Eigen::AlignedBox3d& box, Rng& rng) {
    const double z = rng.uniform(box.min().z(), box.max().z());
    const double y = rng.uniform(box.min().y(), box.max().y());
    const double x = rng.uniform(box.min().x(), box.max().x());
    return {x, y, z};
}

}  // namespace bvc3d
