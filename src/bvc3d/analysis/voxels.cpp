#include "bvc3d/analysis/voxels.hpp"

#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

void Box3::validate() const {
    const double v[6] = {xmin, xmax, ymin, ymax, zmin, zmax};
    for (double x : v)
        if (!std::isfinite(x)) throw InputError("voxel box: bounds must be finite");
    if (!(xmin < xmax) || !(ymin < ymax) || !(zmin < zmax))
        throw InputError("voxel box: need xmin < xmax, ymin < ymax and zmin < zmax");
}

VoxelGrid VoxelGrid::fit(const Eigen::Ref<const Points>& positions, double side, const std::optional<Box3>& box) {
    if (!(side > 0) || !std::isfinite(side))
        throw InputError("voxel side must be a positive length, got " + std::to_string(side));
    check_positions(positions, 3);
    VoxelGrid g;
    g.side = side;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    if (box) {
        box->validate();
        lo[0] = box->xmin, lo[1] = box->ymin, lo[2] = box->zmin;
        hi[0] = box->xmax, hi[1] = box->ymax, hi[2] = box->zmax;
    } else if (positions.rows() > 0) {
        for (int d = 0; d < 3; ++d) lo[d] = positions.col(d).minCoeff(), hi[d] = positions.col(d).maxCoeff();
    }
    int n[3];
    double total = 1;
    for (int d = 0; d < 3; ++d) {
        const double cells = (hi[d] - lo[d]) / side;
        // A box is covered by whole voxels; data bounds put the maximum inside the last voxel.
        const double count = box ? std::max(1.0, std::ceil(cells)) : std::floor(cells) + 1;
        total *= count;
        if (total > 5e7)
            throw InputError("a voxel grid of side " + std::to_string(side) +
                             " m over these positions would "
                             "have more than 5e7 voxels");
        n[d] = static_cast<int>(count);
    }
    g.x0 = lo[0], g.y0 = lo[1], g.z0 = lo[2];
    g.nx = n[0], g.ny = n[1], g.nz = n[2];
    return g;
}

int VoxelGrid::bin_of(const double* p) const {
    const double origin[3] = {x0, y0, z0};
    const int n[3] = {nx, ny, nz};
    int idx[3];
    for (int d = 0; d < 3; ++d) {
        const double u = (p[d] - origin[d]) / side;
        if (!(u >= 0)) return -1;
        int i = static_cast<int>(std::floor(u));
        if (i == n[d] && u <= n[d]) i = n[d] - 1;  // on the far face of the last voxel
        if (i >= n[d]) return -1;
        idx[d] = i;
    }
    return (idx[0] * ny + idx[1]) * nz + idx[2];
}

void VoxelGrid::center(int bin, double* out) const {
    const int k = bin % nz, j = (bin / nz) % ny, i = bin / (nz * ny);
    out[0] = x0 + (i + 0.5) * side;
    out[1] = y0 + (j + 0.5) * side;
    out[2] = z0 + (k + 0.5) * side;
}

}  // namespace bvc3d::analysis
