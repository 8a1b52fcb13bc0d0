#pragma once
// Population stage: head-direction (HD) cells (docs/model-reference.md#head-direction-cells; the authors' follow-up
// to the paper, Dukenbaev et al. 2026). Takes: the agent's heading (on the floor) or its 3-D direction of motion
// (flying). Gives: one signed rate per cell, reading no other population.
//
//   2-D:  v_k = cos(θ − θ_k),      θ_k = 2πk/n (k = 0…n−1; 0 = east), θ the heading
//   3-D:  v_k = u_k · w/|w|,       u_k the 20 unit face normals of an icosahedron, w the direction of motion
//
// The flying agent's pose keeps its sensor level, so w is taken as the displacement since the previous model step
// (what the agent flew); at the first step, or when it did not move, the pose's own yaw and pitch.
#include <array>
#include <span>
#include <vector>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

enum class HdSpace { planar, spherical };

struct HeadDirectionParams {
    int n = 8;                        // cells (planar only)
    HdSpace space = HdSpace::planar;  // planar: n cells around the heading; spherical: the icosahedron's 20
    static const params::Table<HeadDirectionParams>& table();
    void validate() const { table().check(*this); }
};

// The equations above, written once.
namespace hd {
// θ_k of the planar cells.
double preferred_heading(int k, int n);
// The 20 unit face normals of an icosahedron (the centroids of its faces, normalised), in a fixed order.
const std::array<Vec3, 20>& icosahedron_faces();
// Rates of the planar cells for heading θ into out (n values).
void planar_rates(double heading, std::span<double> out);
// Rates of the spherical cells for direction w (any length > 0) into out (20 values).
void spherical_rates(const Vec3& w, std::span<double> out);
// The unit direction of yaw and pitch.
Vec3 direction(double yaw, double pitch);
}  // namespace hd

class HeadDirectionCells : public Population {
public:
    explicit HeadDirectionCells(const HeadDirectionParams& p);
    const HeadDirectionParams& params() const { return p_; }

    std::size_t size() const override;
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override;
    void restore(const std::vector<StateArray>& state) override;

private:
    HeadDirectionParams p_;
    // Spherical: the previous step's position (the direction of motion is the displacement since), once there is one.
    bool has_previous_ = false;
    Vec3 previous_{0, 0, 0};
};

}  // namespace bvc3d
