#pragma once
// Seeded random streams (docs/model-reference.md#conventions: one generator per trial; same seed => bit-identical
// outputs).
//
// A trial's seed is split into independent named streams, so that e.g. drawing the initial
// weights never changes the robot's trajectory. Distributions are written out here rather than
// taken from <random>, whose distribution algorithms are implementation-defined; the engine
// itself (mt19937_64 seeded through seed_seq) is fully specified by the standard.
#include <cstdint>
#include <random>
#include <string>

namespace bvc3d {

enum class Stream : std::uint64_t { walk = 1, weights = 2, sensor_noise = 3, heading_drift = 4, grid_mask = 5 };

class Rng {
public:
    Rng(std::uint64_t seed, Stream stream);

    double uniform();                       // [0, 1), 53 random bits
    double uniform(double lo, double hi);   // [lo, hi)
    double normal(double mean, double sd);  // Box-Muller, no cached second value
    bool bernoulli(double p) { return uniform() < p; }
    std::uint64_t next_u64() { return engine_(); }

    // Text form of the engine state, for checkpoints.
    std::string state() const;
    void set_state(const std::string& s);

private:
    std::mt19937_64 engine_;
};

// A counter-based draw: a well-mixed 64-bit value that depends only on its arguments. Used for
// sensor noise, so that the noise of one beam does not depend on which other beams were cast.
std::uint64_t hash_u64(std::uint64_t a, std::uint64_t b, std::uint64_t c);
double hash_uniform(std::uint64_t a, std::uint64_t b, std::uint64_t c);  // [0, 1)

}  // namespace bvc3d
