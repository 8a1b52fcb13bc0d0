#pragma once
// Cubic voxels: the 3-D Grid, for flying agents (docs/flying.md#analysis).
// Takes: positions (N × 3). Gives: bins as every Grid does (binning.hpp), so rate maps, decoding and
// cell statistics run on voxels unchanged, and modality and aliasing on their centers.
#include <optional>

#include "bvc3d/analysis/binning.hpp"

namespace bvc3d::analysis {

// The box a voxel grid covers (m).
struct Box3 {
    double xmin = 0, xmax = 1, ymin = 0, ymax = 1, zmin = 0, zmax = 1;
    void validate() const;  // finite, min < max on each axis; throws InputError
};

// Cubes of side `side` from a lower corner: voxel (i, j, k) spans [x0 + i·side, x0 + (i+1)·side) and
// likewise in y and z; flat index (i·ny + j)·nz + k, so z varies fastest.
struct VoxelGrid : Grid {
    double side = 0.5;
    double x0 = 0, y0 = 0, z0 = 0;
    int nx = 1, ny = 1, nz = 1;

    // Over `box` (from its lower corner, ceil(size / side) voxels per axis, so the last may stick
    // out; positions outside the box fall in no voxel), or without one over the positions' own
    // bounds (from their minimum). InputError for side <= 0, non-finite positions or more than 5e7 voxels.
    static VoxelGrid fit(const Eigen::Ref<const Points>& positions, double side, const std::optional<Box3>& box = {});

    int dims() const override { return 3; }
    int size() const override { return nx * ny * nz; }
    int bin_of(const double* p) const override;
    void center(int bin, double* out) const override;
    double bin_measure() const override { return side * side * side; }
};

}  // namespace bvc3d::analysis
