#pragma once
// Core: the 20 unit face normals of a regular icosahedron, the directions of the flying agent's HD cells (SPEC §16)
// and of its moves (agent/goal_seeking_flight.hpp). Takes: nothing. Gives: the normals, in a fixed order.
#include <array>

#include "bvc3d/core/geometry.hpp"

namespace bvc3d {

const std::array<Vec3, 20>& icosahedron_faces();

}  // namespace bvc3d
