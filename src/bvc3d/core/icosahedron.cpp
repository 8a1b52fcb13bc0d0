#include "bvc3d/core/icosahedron.hpp"

#include <cmath>
#include <cstdlib>
#include <vector>

namespace bvc3d {

const std::array<Vec3, 20>& icosahedron_faces() {
    static const std::array<Vec3, 20> faces = [] {
        // Vertices (0, ±1, ±φ) and their cyclic permutations; a face is three vertices pairwise at edge length 2.
        const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
        std::vector<Vec3> v;
        for (double a : {-1.0, 1.0})
            for (double b : {-phi, phi}) {
                v.emplace_back(0, a, b);
                v.emplace_back(a, b, 0);
                v.emplace_back(b, 0, a);
            }
        std::array<Vec3, 20> out;
        std::size_t n = 0;
        const auto edge = [&](std::size_t i, std::size_t j) { return std::abs((v[i] - v[j]).norm() - 2.0) < 1e-9; };
        for (std::size_t i = 0; i < v.size(); ++i)
            for (std::size_t j = i + 1; j < v.size(); ++j)
                for (std::size_t k = j + 1; k < v.size(); ++k)
                    if (edge(i, j) && edge(j, k) && edge(i, k)) out[n++] = (v[i] + v[j] + v[k]).normalized();
        return out;
    }();
    return faces;
}

}  // namespace bvc3d
