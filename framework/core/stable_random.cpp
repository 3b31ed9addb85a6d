#include "framework/core/stable_random.hpp"

#include <cmath>

namespace skinlab {

std::uint64_t stable_hash(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV offset basis
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;  // FNV prime
  }
  return h;
}

std::mt19937 keyed_engine(std::int64_t seed, const std::string& key) {
  const std::uint64_t h = stable_hash(key);
  const auto s = static_cast<std::uint64_t>(seed);
  // seed_seq's mixing and mt19937 are specified exactly by the standard.
  std::seed_seq sequence{static_cast<std::uint32_t>(s), static_cast<std::uint32_t>(s >> 32),
                         static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(h >> 32)};
  return std::mt19937(sequence);
}

double uniform_open(std::mt19937& rng) { return (static_cast<double>(rng()) + 0.5) * 0x1p-32; }

double standard_normal(std::mt19937& rng) {
  const double u1 = uniform_open(rng), u2 = uniform_open(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace skinlab
