#include "bvc3d/analysis/modality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

namespace {

constexpr int max_dims = 16;

// Points of up to max_dims dimensions, row-major.
struct PointSet {
    int dims = 2;
    std::vector<double> coords;
    std::size_t size() const { return dims ? coords.size() / static_cast<std::size_t>(dims) : 0; }
    const double* operator[](std::size_t i) const { return coords.data() + i * static_cast<std::size_t>(dims); }
};

// scikit-learn's KDTree (sklearn/neighbors/_binary_tree.pxi, _kd_tree.pyx) restricted to what
// query_radius(X, r) needs with the Euclidean metric. The tree has 2^levels − 1 nodes; a node is
// split at its median along the dimension of largest spread, the points ordered by (value,
// index) as sklearn's partition_node_indices orders them, so each node holds the same points as
// sklearn's (the order inside a node differs, which no result depends on).
class SklearnKdTree {
public:
    explicit SklearnKdTree(const PointSet& pts, int leaf_size = 30) : pts_(pts), idx_(pts.size()) {
        const auto n = static_cast<double>(pts.size());
        const int levels = static_cast<int>(std::log2(std::fmax(1.0, (n - 1) / leaf_size)) + 1);
        nodes_.resize((std::size_t{1} << levels) - 1);
        for (std::size_t i = 0; i < idx_.size(); ++i) idx_[i] = static_cast<int>(i);
        build(0, 0, static_cast<int>(pts.size()));
    }

    // Appends the indices of the points within r of pt, as _query_radius_single selects them.
    void query_radius(const double* pt, double r, std::vector<int>& out) const {
        Query q{pt, r, r * r, exponent_, 1. / exponent_, out};
        visit(0, q);
    }

private:
    struct Node {
        int start = 0, end = 0;
        bool leaf = true;
        std::vector<double> lo, hi;  // bounding box
    };
    struct Query {
        const double* pt;
        double r, reduced_r, p, inv_p;
        std::vector<int>& out;
    };

    void build(std::size_t i, int start, int end) {
        const int D = pts_.dims;
        Node& nd = nodes_[i];
        nd.start = start;
        nd.end = end;
        nd.lo.assign(D, INFINITY);
        nd.hi.assign(D, -INFINITY);
        for (int k = start; k < end; ++k)
            for (int j = 0; j < D; ++j) {
                nd.lo[j] = std::fmin(nd.lo[j], pts_[static_cast<std::size_t>(idx_[k])][j]);
                nd.hi[j] = std::fmax(nd.hi[j], pts_[static_cast<std::size_t>(idx_[k])][j]);
            }
        nd.leaf = 2 * i + 1 >= nodes_.size() || end - start < 2;
        if (nd.leaf) return;
        // find_node_split_dim: first dimension with the strictly largest spread.
        int dim = 0;
        double max_spread = 0;
        for (int j = 0; j < D; ++j)
            if (nd.hi[j] - nd.lo[j] > max_spread) {
                max_spread = nd.hi[j] - nd.lo[j];
                dim = j;
            }
        const int mid = start + (end - start) / 2;
        std::nth_element(idx_.begin() + start, idx_.begin() + mid, idx_.begin() + end, [&](int a, int b) {
            const double va = pts_[static_cast<std::size_t>(a)][dim], vb = pts_[static_cast<std::size_t>(b)][dim];
            return va == vb ? a < b : va < vb;
        });
        build(2 * i + 1, start, mid);
        build(2 * i + 2, mid, end);
    }

    // min_max_dist of _kd_tree.pyx for p = 2 through libm's pow (not x*x, not sqrt: they round
    // differently in about 1 case in 1000, and sklearn's decisions follow pow). Most nodes are
    // decided by the cheap bounds; pow runs only within a relative 1e-9 of the radius.
    bool node_beyond(const Node& nd, const Query& q, bool upper) const {
        const int D = pts_.dims;
        double fast = 0, exact = 0;
        double tv[max_dims];
        for (int j = 0; j < D; ++j) {
            const double d_lo = nd.lo[j] - q.pt[j], d_hi = q.pt[j] - nd.hi[j];
            tv[j] = upper ? std::fmax(std::fabs(d_lo), std::fabs(d_hi))
                          : 0.5 * ((d_lo + std::fabs(d_lo)) + (d_hi + std::fabs(d_hi)));
            fast += tv[j] * tv[j];
        }
        fast = std::sqrt(fast);
        if (fast > q.r * (1 + 1e-9)) return true;
        if (fast < q.r * (1 - 1e-9)) return false;
        for (int j = 0; j < D; ++j) exact += std::pow(tv[j], q.p);
        return std::pow(exact, q.inv_p) > q.r;
    }

    void visit(std::size_t i, Query& q) const {
        const Node& nd = nodes_[i];
        if (node_beyond(nd, q, false)) return;  // case 1: dist_LB > r, the whole node is out
        if (!node_beyond(nd, q, true)) {        // case 2: dist_UB <= r, the whole node is in
            q.out.insert(q.out.end(), idx_.begin() + nd.start, idx_.begin() + nd.end);
            return;
        }
        if (nd.leaf) {  // case 3: euclidean_rdist(pt, x) <= r*r, point by point
            for (int k = nd.start; k < nd.end; ++k) {
                const double* x = pts_[static_cast<std::size_t>(idx_[k])];
                double rdist = 0;
                for (int j = 0; j < pts_.dims; ++j) {
                    const double t = q.pt[j] - x[j];
                    rdist += t * t;
                }
                if (rdist <= q.reduced_r) q.out.push_back(idx_[k]);
            }
            return;
        }
        visit(2 * i + 1, q);
        visit(2 * i + 2, q);
    }

    const PointSet& pts_;
    std::vector<int> idx_;
    std::vector<Node> nodes_;
    // The Minkowski exponent, read at run time so that the compiler cannot turn pow(x, 2) into x*x.
    static inline volatile double exponent_ = 2.0;
};

// scikit-learn's brute-force radius neighbors for float64 Euclidean data (EuclideanRadiusNeighbors64
// with reference BLAS): |x_i|² + (−2·x_i·x_j) + |x_j|², clipped at 0, compared with eps².
Neighborhoods brute_neighbors(const PointSet& pts, double eps) {
    Neighborhoods nb;
    const double rr = eps * eps;
    const int D = pts.dims;
    auto dot = [&](const double* a, const double* b) {
        double s = 0;
        for (int j = 0; j < D; ++j) s += a[j] * b[j];
        return s;
    };
    std::vector<double> norm(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) norm[i] = dot(pts[i], pts[i]);
    for (std::size_t i = 0; i < pts.size(); ++i) {
        if (i % 1024 == 0) poll_cancel();
        for (std::size_t j = 0; j < pts.size(); ++j) {
            const double middle = -2.0 * dot(pts[i], pts[j]);
            if (std::max(norm[i] + middle + norm[j], 0.0) <= rr) nb.indices.push_back(static_cast<int>(j));
        }
        nb.offsets.push_back(static_cast<int>(nb.indices.size()));
    }
    return nb;
}

Neighborhoods neighbors(const PointSet& pts, double eps) {
    // NearestNeighbors' default n_neighbors = 5 makes 'auto' choose brute force when 5 >= n // 2.
    if (pts.size() / 2 <= 5) return brute_neighbors(pts, eps);
    Neighborhoods nb;
    const SklearnKdTree tree(pts);
    for (std::size_t i = 0; i < pts.size(); ++i) {
        if (i % 4096 == 0) poll_cancel();
        tree.query_radius(pts[i], eps, nb.indices);
        nb.offsets.push_back(static_cast<int>(nb.indices.size()));
    }
    return nb;
}

// DBSCAN labels as scikit-learn's labels_: -1 for noise, clusters numbered in order of discovery.
std::vector<int> cluster_labels(const PointSet& pts, const DbscanParams& params) {
    const std::size_t n = pts.size();
    std::vector<int> label(n, -1);
    // A core point needs min_samples neighbors (itself included): none with fewer points.
    if (n < static_cast<std::size_t>(params.min_samples) || n == 0) return label;
    const Neighborhoods nb = neighbors(pts, params.eps);
    std::vector<char> core(n);
    for (std::size_t i = 0; i < n; ++i) core[i] = nb.offsets[i + 1] - nb.offsets[i] >= params.min_samples;
    // sklearn's dbscan_inner. Its neighborhoods need not be symmetric (see the KD-tree), so the
    // clusters follow the same expansion: a new cluster at each unlabeled core point in index order,
    // grown through the neighborhoods of core points only.
    std::vector<int> stack;
    int clusters = 0;
    for (std::size_t start = 0; start < n; ++start) {
        if (label[start] != -1 || !core[start]) continue;
        stack.push_back(static_cast<int>(start));
        while (!stack.empty()) {
            const auto i = static_cast<std::size_t>(stack.back());
            stack.pop_back();
            if (label[i] != -1) continue;
            label[i] = clusters;
            if (!core[i]) continue;
            for (int k = nb.offsets[i]; k < nb.offsets[i + 1]; ++k)
                if (label[static_cast<std::size_t>(nb.indices[static_cast<std::size_t>(k)])] == -1)
                    stack.push_back(nb.indices[static_cast<std::size_t>(k)]);
        }
        ++clusters;
    }
    return label;
}

int cluster_count(const PointSet& pts, const DbscanParams& params) {
    int clusters = 0;
    for (const int l : cluster_labels(pts, params)) clusters = std::max(clusters, l + 1);
    return clusters;
}

void check_points(const Eigen::Ref<const Points>& points) {
    if (points.cols() < 1 || points.cols() > max_dims)
        throw InputError("points need 1 to " + std::to_string(max_dims) + " coordinates, got " +
                         std::to_string(points.cols()));
    for (Eigen::Index i = 0; i < points.rows(); ++i)
        if (!points.row(i).allFinite()) throw InputError("points must be finite: row " + std::to_string(i) + " is not");
}

PointSet to_points(const Eigen::Ref<const Points>& points) {
    PointSet pts;
    pts.dims = static_cast<int>(points.cols());
    pts.coords.reserve(static_cast<std::size_t>(points.size()));
    for (Eigen::Index i = 0; i < points.rows(); ++i)
        for (Eigen::Index d = 0; d < points.cols(); ++d) pts.coords.push_back(points(i, d));
    return pts;
}

}  // namespace

void DbscanParams::validate() const {
    if (!(eps > 0) || !std::isfinite(eps))
        throw InputError("eps must be a positive number, got " + std::to_string(eps));
    if (min_samples < 1) throw InputError("min_samples must be >= 1, got " + std::to_string(min_samples));
}

Neighborhoods sklearn_radius_neighbors(const Eigen::Ref<const Centers>& points, double eps) {
    DbscanParams{eps, 1}.validate();
    check_points(points);
    return neighbors(to_points(points), eps);
}

std::vector<int> dbscan_labels(const Eigen::Ref<const Centers>& points, const DbscanParams& params) {
    params.validate();
    check_points(points);
    return cluster_labels(to_points(points), params);
}

int dbscan_cluster_count(const Eigen::Ref<const Centers>& points, const DbscanParams& params) {
    params.validate();
    check_points(points);
    return cluster_count(to_points(points), params);
}

std::vector<int> modality(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                          const DbscanParams& params) {
    params.validate();
    check_points(centers);
    if (maps.rows() != centers.rows())
        throw InputError("maps must have one row per bin center: " + std::to_string(maps.rows()) + " rows for " +
                         std::to_string(centers.rows()) + " centers");
    std::vector<int> mi(static_cast<std::size_t>(maps.cols()));
    PointSet pts;
    pts.dims = static_cast<int>(centers.cols());
    for (Eigen::Index c = 0; c < maps.cols(); ++c) {
        poll_cancel();
        pts.coords.clear();
        for (Eigen::Index b = 0; b < maps.rows(); ++b) {
            if (std::isnan(maps(b, c)))
                throw InputError("maps must not contain NaN (column " + std::to_string(c) + ")");
            if (maps(b, c) > 0)
                for (Eigen::Index d = 0; d < centers.cols(); ++d) pts.coords.push_back(centers(b, d));
        }
        mi[static_cast<std::size_t>(c)] = cluster_count(pts, params);
    }
    return mi;
}

ModalitySummary summarize_modality(std::span<const int> mi) {
    ModalitySummary s;
    if (mi.empty()) return s;
    std::size_t active = 0, multi = 0;
    double sum = 0;
    for (const int m : mi) {
        if (m > 0) ++active, sum += m;
        if (m > 1) ++multi;
    }
    const auto n = static_cast<double>(mi.size());
    s.frac_active = static_cast<double>(active) / n;
    s.frac_multimodal = static_cast<double>(multi) / n;
    if (active > 0) s.mean_mi_active = sum / static_cast<double>(active);
    return s;
}

}  // namespace bvc3d::analysis
