#pragma once
// The best match by cosine similarity among many population vectors (place recognition's search,
// docs/place-recognition.md#the-search): an exact search, blocked so that a block of templates is
// read from memory once for a block of queries, on unit-length float rows.
// Takes: template rows (e.g. BVC rates, one scan each) and query rows, each query with the range of
// templates it may match. Gives: per query the most similar template in its range and the cosine.
#include <cstddef>
#include <span>
#include <vector>

#include "bvc3d/analysis/types.hpp"
#include "bvc3d/core/aligned.hpp"

namespace bvc3d::analysis {

// A query's variants: its values turned by s = 0 … turns − 1 steps along a cyclic axis, the value
// at (outer, k, inner) moving to (outer, (k + s) mod turns, inner) for `inner` values per step
// (a BVC population's azimuths: turns = n_dir, inner = n_per_axis). turns = 1: the query itself.
struct QueryTurns {
    int turns = 1;
    std::size_t inner = 1;
};

class CosineIndex {
public:
    // The rows scaled to unit length (all-zero rows stay zero: cos = 0 with everything). Non-finite
    // values are an InputError naming the row.
    explicit CosineIndex(const Eigen::Ref<const RowMatrixXf>& rows);

    std::size_t size() const { return n_; }
    std::size_t dim() const { return dim_; }

    struct Range {
        std::size_t first = 0, end = 0;  // the templates [first, end) a query may match
    };
    struct Best {
        long index = -1;          // the template, -1 when the range is empty
        double similarity = 0.0;  // its cosine with the query (the best variant's)
        int variant = 0;          // which of the query's variants matched
    };
    // Row q of `queries` matches the template of ranges[q] most similar to any of its variants. Ties
    // go to the lowest template, then the lowest variant. Queries are scaled to unit length like the
    // templates. The answer does not depend on `threads` (0: every core).
    std::vector<Best> best(const Eigen::Ref<const RowMatrixXf>& queries, std::span<const Range> ranges,
                           QueryTurns turns = {}, int threads = 0) const;
    // The same with the index's own rows as the queries (no copy): row rows[q] matches in ranges[q].
    std::vector<Best> best_of_rows(std::span<const std::size_t> rows, std::span<const Range> ranges,
                                   QueryTurns turns = {}, int threads = 0) const;

private:
    // Query q's unit row is at unit[q·stride_] (or at rows_ + rows[q]·stride_).
    std::vector<Best> search(const float* unit, const std::size_t* rows, std::span<const Range> ranges,
                             QueryTurns turns, int threads) const;
    std::size_t n_ = 0, dim_ = 0, stride_ = 0;  // stride_: dim_ rounded up to the kernel's 16 floats
    std::vector<float, CacheAligned<float>> rows_;
};

// `rows` scaled to unit length into `out` (n × stride floats, zero-padded): the layout the search reads.
void unit_rows(const Eigen::Ref<const RowMatrixXf>& rows, std::size_t stride, float* out);

}  // namespace bvc3d::analysis
