#include "bvc3d/analysis/decoding.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bvc3d/analysis/rate_maps.hpp"
#include "bvc3d/core/cancel.hpp"
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

RowMatrixXd unit_rows(const RowMatrixXd& m) {
    RowMatrixXd unit = m;
    for (Eigen::Index b = 0; b < unit.rows(); ++b)
        if (const double norm = unit.row(b).norm(); norm > 0) unit.row(b) /= norm;
    return unit;
}

// The decoded bin of a score row: the first bin with the largest positive score, or -1.
template <class Scores>
int best_bin(const Scores& score) {
    int best = -1;
    double best_score = 0;
    for (Eigen::Index b = 0; b < score.size(); ++b)
        if (score(b) > best_score) best = static_cast<int>(b), best_score = score(b);
    return best;
}

// Sparse path: the unit templates stored per cell (compressed columns), so that a sample only
// touches the bins where its active cells have a non-zero template entry.
template <class T>
std::vector<int> decode_sparse(const RowMatrixXd& unit, const Eigen::Ref<const RowMatrixX<T>>& rates) {
    std::vector<int> start{0}, bin;
    std::vector<double> value;
    for (Eigen::Index c = 0; c < unit.cols(); ++c) {
        for (Eigen::Index b = 0; b < unit.rows(); ++b)
            if (unit(b, c) != 0) bin.push_back(static_cast<int>(b)), value.push_back(unit(b, c));
        start.push_back(static_cast<int>(bin.size()));
    }
    std::vector<int> best(static_cast<std::size_t>(rates.rows()), -1);
    Eigen::VectorXd score = Eigen::VectorXd::Zero(unit.rows());
    for (Eigen::Index s = 0; s < rates.rows(); ++s) {
        if (s % 512 == 0) poll_cancel();
        for (Eigen::Index c = 0; c < rates.cols(); ++c) {
            const double rc = static_cast<double>(rates(s, c));
            if (rc == 0) continue;
            for (int k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1]; ++k)
                score(bin[static_cast<std::size_t>(k)]) += value[static_cast<std::size_t>(k)] * rc;
        }
        // A scan of all bins is cheaper than tracking the touched ones (a branch per entry).
        best[static_cast<std::size_t>(s)] = best_bin(score);
        score.setZero();
    }
    return best;
}

// Dense path for dense rates: blocks of samples times all templates with Eigen's matrix product.
template <class T>
std::vector<int> decode_dense(const RowMatrixXd& unit, const Eigen::Ref<const RowMatrixX<T>>& rates) {
    std::vector<int> best(static_cast<std::size_t>(rates.rows()), -1);
    constexpr Eigen::Index block = 512;
    RowMatrixXd scores;
    for (Eigen::Index s0 = 0; s0 < rates.rows(); s0 += block) {
        poll_cancel();
        const Eigen::Index m = std::min(block, rates.rows() - s0);
        scores.noalias() = rates.middleRows(s0, m).template cast<double>() * unit.transpose();
        for (Eigen::Index i = 0; i < m; ++i) best[static_cast<std::size_t>(s0 + i)] = best_bin(scores.row(i));
    }
    return best;
}

// Multiply-adds of the sparse path, estimated on every 8th sample.
template <class T>
double sparse_cost(const RowMatrixXd& unit, const Eigen::Ref<const RowMatrixX<T>>& rates) {
    const Eigen::VectorXd nnz = (unit.array() != 0).template cast<double>().colwise().sum().transpose();
    double cost = 0;
    for (Eigen::Index s = 0; s < rates.rows(); s += 8)
        for (Eigen::Index c = 0; c < rates.cols(); ++c)
            if (rates(s, c) != 0) cost += nnz(c);
    return cost * 8;
}

// Smallest e with at least half the total weight at errors <= e.
double weighted_median(std::vector<std::pair<double, double>> v) {
    std::sort(v.begin(), v.end());
    double total = 0;
    for (const auto& [e, w] : v) total += w;
    double sum = 0;
    for (const auto& [e, w] : v)
        if ((sum += w) >= 0.5 * total) return e;
    return v.empty() ? NAN : v.back().first;
}

double mean_of(const std::vector<double>& v) {
    double sum = 0;
    for (const double e : v) sum += e;
    return sum / static_cast<double>(v.size());
}

// The vertical error of chance (decoding.hpp): bins grouped by their height first.
double vertical_chance(const Bins& first, const Eigen::Ref<const Points>& positions, std::size_t half) {
    std::vector<std::pair<double, double>> layers;  // (z of bin centers, samples)
    for (int b = 0; b < first.size(); ++b) {
        const double z = first.centers(b, 2);
        auto it = std::find_if(layers.begin(), layers.end(), [&](const auto& l) { return l.first == z; });
        if (it == layers.end()) layers.emplace_back(z, 0.0), it = layers.end() - 1;
        it->second += static_cast<double>(first.counts[static_cast<std::size_t>(b)]);
    }
    std::vector<std::pair<double, double>> pairs;
    pairs.reserve((static_cast<std::size_t>(positions.rows()) - half) * layers.size());
    for (Eigen::Index s = static_cast<Eigen::Index>(half); s < positions.rows(); ++s)
        for (const auto& [z, w] : layers) pairs.emplace_back(std::abs(positions(s, 2) - z), w);
    return weighted_median(std::move(pairs));
}

}  // namespace

std::string decoding_templates_name(DecodingTemplates t) {
    return t == DecodingTemplates::means ? "means" : "rate_maps";
}

DecodingTemplates parse_decoding_templates(std::string_view name) {
    if (name == "rate_maps") return DecodingTemplates::rate_maps;
    if (name == "means") return DecodingTemplates::means;
    throw InputError("decoding templates must be 'rate_maps' or 'means', got '" + std::string(name) + "'");
}

template <class T>
DecodingResult decoding_error(const Grid& grid, const Eigen::Ref<const Points>& positions,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, DecodingTemplates templates,
                              double quantile) {
    check_positions(positions, grid.dims());
    const std::size_t n = static_cast<std::size_t>(positions.rows());
    if (n < 2) throw InputError("decoding needs at least 2 samples, got " + std::to_string(n));
    check_values<T>(rates, n, "rates");
    if (!(quantile >= 0.0 && quantile <= 1.0))
        throw InputError("quantile must lie in [0, 1], got " + std::to_string(quantile));
    const std::size_t half = n / 2;
    const Bins first = bin_positions(grid, positions.topRows(static_cast<Eigen::Index>(half)));
    RowMatrixXd tmpl = bin_means<T>(first, rates.topRows(static_cast<Eigen::Index>(half)));
    // docs/model-reference.md#analysis: the first half's rate maps (threshold, then per-cell max-normalization).
    if (templates == DecodingTemplates::rate_maps) threshold_and_normalize(tmpl, quantile);
    const RowMatrixXd unit = unit_rows(tmpl);  // score_b = t̂_b · r: r's norm does not change the best bin
    const auto second = rates.bottomRows(static_cast<Eigen::Index>(n - half));
    // The sparse path wins while the rates are sparse; a product in blocks runs ~4x faster per
    // multiply-add, so it takes over for dense rates (e.g. BVC rates).
    const double dense_cost = static_cast<double>(second.rows()) * static_cast<double>(unit.size()) / 4;
    const std::vector<int> best =
        sparse_cost<T>(unit, second) <= dense_cost ? decode_sparse<T>(unit, second) : decode_dense<T>(unit, second);

    const auto distance = [&](Eigen::Index s, Eigen::Index b) {
        double d2 = 0;
        for (Eigen::Index d = 0; d < positions.cols(); ++d) {
            const double diff = positions(s, d) - first.centers(b, d);
            d2 += diff * diff;
        }
        return std::sqrt(d2);
    };
    // Chance: the occupancy-weighted mean distance to the template bins (NaN without any).
    double occupancy = 0;
    for (const auto c : first.counts) occupancy += static_cast<double>(c);
    const auto chance = [&](Eigen::Index s) {
        double sum = 0;
        for (Eigen::Index b = 0; b < first.centers.rows(); ++b)
            sum += static_cast<double>(first.counts[static_cast<std::size_t>(b)]) * distance(s, b);
        return occupancy > 0 ? sum / occupancy : std::numeric_limits<double>::quiet_NaN();
    };

    DecodingResult out;
    const bool split = positions.cols() == 3;  // horizontal and vertical parts of 3-D errors
    std::vector<double> errors, all, horizontal, vertical;
    errors.reserve(best.size());
    all.reserve(best.size());
    for (std::size_t i = 0; i < best.size(); ++i) {
        const auto s = static_cast<Eigen::Index>(half + i);
        if (best[i] < 0) {
            ++out.n_undecoded;
            all.push_back(chance(s));
            continue;
        }
        errors.push_back(distance(s, best[i]));
        all.push_back(errors.back());
        if (split) {
            const double dx = positions(s, 0) - first.centers(best[i], 0),
                         dy = positions(s, 1) - first.centers(best[i], 1);
            horizontal.push_back(std::sqrt(dx * dx + dy * dy));
            vertical.push_back(std::abs(positions(s, 2) - first.centers(best[i], 2)));
        }
    }
    if (split && first.size() > 0) out.median_vertical_chance_m = vertical_chance(first, positions, half);
    if (!horizontal.empty()) {
        out.mean_horizontal_m = mean_of(horizontal);
        out.median_horizontal_m = median(std::move(horizontal));
        out.mean_vertical_m = mean_of(vertical);
        out.median_vertical_m = median(std::move(vertical));
    }
    out.n_decoded = errors.size();
    const auto summarize = [](std::vector<double> v, double& mean, double& med) {
        if (v.empty()) return;
        double sum = 0;
        for (const double e : v) sum += e;
        mean = sum / static_cast<double>(v.size());
        med = median(std::move(v));
    };
    summarize(std::move(errors), out.mean_m, out.median_m);
    if (occupancy > 0) summarize(std::move(all), out.mean_all_m, out.median_all_m);
    return out;
}

template <class T>
DecodingResult decoding_error(std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, const DecodingParams& params) {
    return decoding_error<T>(HexGrid::fit(x, y, params.gridsize, params.extent), positions_2d(x, y), rates,
                             params.templates, params.quantile);
}

template DecodingResult decoding_error<float>(const Grid&, const Eigen::Ref<const Points>&,
                                              const Eigen::Ref<const RowMatrixXf>&, DecodingTemplates, double);
template DecodingResult decoding_error<double>(const Grid&, const Eigen::Ref<const Points>&,
                                               const Eigen::Ref<const RowMatrixXd>&, DecodingTemplates, double);
template DecodingResult decoding_error<float>(std::span<const double>, std::span<const double>,
                                              const Eigen::Ref<const RowMatrixXf>&, const DecodingParams&);
template DecodingResult decoding_error<double>(std::span<const double>, std::span<const double>,
                                               const Eigen::Ref<const RowMatrixXd>&, const DecodingParams&);

}  // namespace bvc3d::analysis
