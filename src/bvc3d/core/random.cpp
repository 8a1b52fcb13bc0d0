#include "bvc3d/core/random.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

Rng::Rng(std::uint64_t seed, Stream stream) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                      static_cast<std::uint32_t>(stream), 0x62766333u /* "bvc3" */};
    engine_.seed(seq);
}

double Rng::uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double Rng::uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

double Rng::normal(double mean, double sd) {
    const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
    const double u2 = uniform();
    return mean + sd * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

std::string Rng::state() const {
    std::ostringstream os;
    os << engine_;
    return os.str();
}

void Rng::set_state(const std::string& s) {
    std::istringstream is(s);
    auto engine = engine_;
    is >> engine;
    if (!is) throw InputError("random generator state is corrupt");
    engine_ = engine;
}

namespace {
std::uint64_t splitmix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}
}  // namespace

std::uint64_t hash_u64(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
    return splitmix(splitmix(splitmix(a) ^ b) ^ c);
}

double hash_uniform(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
    return static_cast<double>(hash_u64(a, b, c) >> 11) * 0x1.0p-53;
}

}  // namespace bvc3d
