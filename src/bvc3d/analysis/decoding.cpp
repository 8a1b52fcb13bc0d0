#include "bvc3d/analysis/decoding.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

namespace {

double median(std::vector<double> v) {  // numpy.median: the mean of the two middle values
    const std::size_t k = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    const double hi = v[k];
    if (v.size() % 2) return hi;
    const double lo = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k));
    return (lo + hi) / 2;
}

// Unit templates stored per cell (compressed columns): the bins where the cell's template entry is
// non-zero and its value there. A sample only touches the columns of its active cells.
struct SparseTemplates {
    std::vector<int> start;  // per cell, into bin/value
    std::vector<int> bin;
    std::vector<double> value;
};

SparseTemplates sparse_unit_templates(const RowMatrixXd& mean) {
    RowMatrixXd unit = mean;
    for (Eigen::Index b = 0; b < unit.rows(); ++b)
        if (const double norm = unit.row(b).norm(); norm > 0) unit.row(b) /= norm;
    SparseTemplates t;
    t.start.push_back(0);
    for (Eigen::Index c = 0; c < unit.cols(); ++c) {
        for (Eigen::Index b = 0; b < unit.rows(); ++b)
            if (unit(b, c) != 0) {
                t.bin.push_back(static_cast<int>(b));
                t.value.push_back(unit(b, c));
            }
        t.start.push_back(static_cast<int>(t.bin.size()));
    }
    return t;
}

}  // namespace

template <class T>
DecodingResult decoding_error(const HexGrid& grid, std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates) {
    check_positions(x, y);
    const std::size_t n = x.size();
    if (n < 2) throw InputError("decoding needs at least 2 samples, got " + std::to_string(n));
    check_values<T>(rates, n, "rates");
    const std::size_t half = n / 2;
    const HexBins first = bin_samples(grid, x.first(half), y.first(half));
    const RowMatrixXd mean = bin_means<T>(first, rates.topRows(static_cast<Eigen::Index>(half)));
    const SparseTemplates tpl = sparse_unit_templates(mean);

    DecodingResult out;
    std::vector<double> errors, score(static_cast<std::size_t>(first.size()), 0.0);
    std::vector<int> touched;
    std::vector<char> is_touched(score.size(), 0);
    errors.reserve(n - half);
    for (std::size_t s = half; s < n; ++s) {
        const auto r = rates.row(static_cast<Eigen::Index>(s));
        // score_b = t̂_b · r; dividing by |r| would not change the best bin.
        for (Eigen::Index c = 0; c < r.size(); ++c) {
            const double rc = static_cast<double>(r(c));
            if (rc == 0) continue;
            for (int k = tpl.start[static_cast<std::size_t>(c)]; k < tpl.start[static_cast<std::size_t>(c) + 1]; ++k) {
                const auto b = static_cast<std::size_t>(tpl.bin[static_cast<std::size_t>(k)]);
                if (!is_touched[b]) is_touched[b] = 1, touched.push_back(static_cast<int>(b));
                score[b] += tpl.value[static_cast<std::size_t>(k)] * rc;
            }
        }
        int best = -1;
        double best_score = 0;
        for (const int b : touched) {
            const double v = score[static_cast<std::size_t>(b)];
            if (v > best_score || (v == best_score && best >= 0 && b < best)) best = b, best_score = v;
            score[static_cast<std::size_t>(b)] = 0;
            is_touched[static_cast<std::size_t>(b)] = 0;
        }
        touched.clear();
        if (best < 0) {
            ++out.n_undecoded;
            continue;
        }
        const double dx = x[s] - first.centers(best, 0), dy = y[s] - first.centers(best, 1);
        errors.push_back(std::sqrt(dx * dx + dy * dy));
    }
    out.n_decoded = errors.size();
    if (!errors.empty()) {
        double sum = 0;
        for (const double e : errors) sum += e;
        out.mean_m = sum / static_cast<double>(errors.size());
        out.median_m = median(std::move(errors));
    }
    return out;
}

template <class T>
DecodingResult decoding_error(std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, const DecodingParams& params) {
    return decoding_error<T>(HexGrid::fit(x, y, params.gridsize, params.extent), x, y, rates);
}

template DecodingResult decoding_error<float>(const HexGrid&, std::span<const double>, std::span<const double>,
                                              const Eigen::Ref<const RowMatrixXf>&);
template DecodingResult decoding_error<double>(const HexGrid&, std::span<const double>, std::span<const double>,
                                               const Eigen::Ref<const RowMatrixXd>&);
template DecodingResult decoding_error<float>(std::span<const double>, std::span<const double>,
                                              const Eigen::Ref<const RowMatrixXf>&, const DecodingParams&);
template DecodingResult decoding_error<double>(std::span<const double>, std::span<const double>,
                                               const Eigen::Ref<const RowMatrixXd>&, const DecodingParams&);

}  // namespace bvc3d::analysis
