#include "bvc3d/analysis/localization.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::analysis {

namespace {

// Rows scaled to unit length (all-zero rows stay zero), in double.
RowMatrixXd unit_rows(const Eigen::Ref<const RowMatrixXf>& m) {
    RowMatrixXd u = m.cast<double>();
    for (Eigen::Index i = 0; i < u.rows(); ++i) {
        const double n = u.row(i).norm();
        if (n > 0) u.row(i) /= n;
    }
    return u;
}

double median_of(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t n = v.size(), h = n / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
    const double hi = v[h];
    if (n % 2) return hi;
    const double lo = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h));
    return 0.5 * (lo + hi);  // numpy's median
}

ErrorSummary summarize(const std::vector<double>& errors) {
    ErrorSummary s;
    if (errors.empty()) return s;
    double sum = 0;
    std::size_t in1 = 0, in2 = 0;
    for (const double e : errors) {
        sum += e;
        in1 += e <= 1.0;
        in2 += e <= 2.0;
    }
    const auto n = static_cast<double>(errors.size());
    s.mean = sum / n;
    s.median = median_of(errors);
    s.within_1m = static_cast<double>(in1) / n;
    s.within_2m = static_cast<double>(in2) / n;
    return s;
}

double horizontal(const Eigen::Ref<const Points>& a, Eigen::Index i, const Eigen::Ref<const Points>& b,
                  Eigen::Index j) {
    return std::hypot(a(i, 0) - b(j, 0), a(i, 1) - b(j, 1));
}

}  // namespace

LocalizationResult localize(const Eigen::Ref<const RowMatrixXf>& templates,
                            const Eigen::Ref<const Points>& template_xyz, const Eigen::Ref<const RowMatrixXf>& queries,
                            const Eigen::Ref<const Points>& query_xyz) {
    const Eigen::Index T = templates.rows(), Q = queries.rows();
    if (T == 0) throw InputError("localization needs at least one template");
    if (templates.cols() != queries.cols())
        throw InputError("templates have " + std::to_string(templates.cols()) + " cells and queries " +
                         std::to_string(queries.cols()) + ": they must come from the same model");
    if (template_xyz.rows() != T || query_xyz.rows() != Q || template_xyz.cols() != 3 || query_xyz.cols() != 3)
        throw InputError("localization: one x, y, z row per template and per query");
    // A position that is not a number has no error to measure: refused, naming the row, not carried into the means.
    for (const auto& [xyz, what] : {std::pair{&template_xyz, "template"}, std::pair{&query_xyz, "query"}})
        for (Eigen::Index i = 0; i < xyz->rows(); ++i)
            if (!xyz->row(i).allFinite())
                throw InputError(std::string("localization: ") + what + " " + std::to_string(i) +
                                 "'s position is not finite (" + format_number((*xyz)(i, 0)) + ", " +
                                 format_number((*xyz)(i, 1)) + ", " + format_number((*xyz)(i, 2)) + ")");
    for (const auto& [rates, what] : {std::pair{&templates, "templates"}, std::pair{&queries, "queries"}})
        if (!rates->allFinite())
            throw InputError(std::string("localization: the ") + what + " hold values that are not finite");

    const RowMatrixXd t = unit_rows(templates), q = unit_rows(queries);
    LocalizationResult r;
    r.decoded.assign(static_cast<std::size_t>(Q), -1);
    r.similarity.assign(static_cast<std::size_t>(Q), 0.0);
    r.error.assign(static_cast<std::size_t>(Q), std::numeric_limits<double>::quiet_NaN());
    r.vertical_error = r.error;
    r.nearest_error.assign(static_cast<std::size_t>(Q), 0.0);
    std::vector<double> errors, vertical, nearest, chance;
    for (Eigen::Index i = 0; i < Q; ++i) {
        const auto k = static_cast<std::size_t>(i);
        double best = -INFINITY;
        Eigen::Index arg = 0;
        for (Eigen::Index j = 0; j < T; ++j) {
            const double c = q.row(i).dot(t.row(j));
            if (c > best) best = c, arg = j;
        }
        double near = INFINITY;
        for (Eigen::Index j = 0; j < T; ++j) near = std::min(near, horizontal(query_xyz, i, template_xyz, j));
        r.nearest_error[k] = near;
        r.similarity[k] = best;
        if (!(best > 0)) {
            ++r.n_undecoded;
            continue;
        }
        r.decoded[k] = static_cast<long>(arg);
        r.error[k] = horizontal(query_xyz, i, template_xyz, arg);
        r.vertical_error[k] = std::abs(query_xyz(i, 2) - template_xyz(arg, 2));
        errors.push_back(r.error[k]);
        vertical.push_back(r.vertical_error[k]);
        nearest.push_back(near);
        for (Eigen::Index j = 0; j < T; ++j) chance.push_back(horizontal(query_xyz, i, template_xyz, j));
    }
    r.decoded_summary = summarize(errors);
    r.nearest = summarize(nearest);
    r.chance = summarize(chance);
    if (!vertical.empty()) {
        r.vertical_median = median_of(vertical);
        double s = 0;
        for (const double v : vertical) s += v;
        r.vertical_mean = s / static_cast<double>(vertical.size());
    }
    return r;
}

}  // namespace bvc3d::analysis
