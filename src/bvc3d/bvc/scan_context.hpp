#pragma once
// Scan Context (Kim & Kim, IROS 2018; docs/place-recognition.md#scan-context): the LiDAR
// place-recognition field's baseline descriptor of a scan, beside the BVC population as another
// description of the same returns. Egocentric: it reads points in a level frame that turns with the
// sensor (x forward, z up), so it needs no heading.
// Takes: a scan's points (N × 3, metres) in that frame. Gives: the rings × sectors matrix of bin
// heights, its ring key (what a k-d tree indexes), and the distance between two descriptors
// minimised over column shifts (a rotation of the sensor about z).
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"

namespace bvc3d {

// The reference implementation's defaults (the paper's 20 × 60 bins out to 80 m).
struct ScanContextParams {
    int rings = 20;
    int sectors = 60;
    double max_radius = 80.0;   // m: farther points (horizontal distance) are left out
    double lidar_height = 2.0;  // m added to every z, so that the ground is above 0 (LIDAR_HEIGHT)
    int candidates = 10;        // nearest ring keys whose descriptors are compared in a search

    static const params::Table<ScanContextParams>& table();
    void validate() const { table().check(*this); }
};

struct ScanContext {
    int rings = 0, sectors = 0;
    std::vector<double> bins;      // rings × sectors, row-major: bins[ring·sectors + sector]
    std::vector<double> ring_key;  // per ring, the mean over its sectors
    // Each sector's column (its rings' bins) scaled to unit length, sector-major; all-zero columns stay 0
    // and are marked in `filled` (what the distance compares).
    std::vector<double> unit_columns;
    std::vector<char> filled;

    double bin(int ring, int sector) const { return bins[static_cast<std::size_t>(ring * sectors + sector)]; }
};

// The descriptor of `xyz` (N × 3 row-major). A point at horizontal distance ρ ≤ max_radius and
// azimuth α (degrees counter-clockwise from +x in [0, 360)) falls in ring ⌈ρ/Δρ⌉ and sector ⌈α/Δα⌉,
// both counted from 1 and clamped to [1, rings] and [1, sectors] (so ρ = 0 is ring 1, α = 0 sector 1),
// Δρ = max_radius / rings, Δα = 360° / sectors. A bin holds the largest z + lidar_height of its
// points, 0 when it has none. Non-finite points are an InputError naming the point.
ScanContext scan_context(std::span<const double> xyz, const ScanContextParams& params = {});

// The descriptor of given bins (rings × sectors, row-major): its ring key and unit columns.
ScanContext scan_context_from_bins(int rings, int sectors, std::vector<double> bins);

struct ScanContextMatch {
    double distance = 1.0;  // in [0, 2] (in [0, 1] when no bin is negative)
    int shift = 0;          // sectors: b's sector c compared with a's sector (c + shift) mod sectors
};

// The paper's distance: for a shift s, the mean over the sectors c whose columns are non-zero in both
// of 1 − cos(a's column c + s, b's column c); a shift with no such sector counts as 1 (cos = 0, as for
// an all-zero rate vector). Minimised over every shift (the reference implementation searches 10 %
// of them around a rough alignment; SPEC fixes the exhaustive search); ties go to the smallest shift.
// A scan turned by +s·Δα about z has its sectors moved by +s: the shift is the rotation from b to a.
ScanContextMatch scan_context_distance(const ScanContext& a, const ScanContext& b);

}  // namespace bvc3d
