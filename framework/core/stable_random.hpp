#pragma once
/// \file
/// Random streams that are the same on every machine and standard library: a seeded mt19937
/// keyed by a name (FNV-1a and std::seed_seq, both specified exactly), and uniform and normal
/// draws from its raw 32-bit output (std:: distributions differ between standard libraries).
/// The deformation error's poses (eval/deformation_error.hpp), random_pose
/// (geometry/lbs.hpp) and the training-data augmentation (data/augment.hpp) draw from them.

#include <cstdint>
#include <random>
#include <string>

namespace skinlab {

/// 64-bit FNV-1a hash of `text`: its value is fixed by its definition (std::hash's is not).
std::uint64_t stable_hash(const std::string& text);

/// mt19937 seeded by std::seed_seq{seed low, seed high, hash low, hash high} with
/// hash = stable_hash(key): one stream per (seed, key), e.g. per character name, independent of
/// the order in which keys are visited (and of thread scheduling).
std::mt19937 keyed_engine(std::int64_t seed, const std::string& key);

/// Uniform on the open interval (0, 1) from one 32-bit draw.
double uniform_open(std::mt19937& rng);

/// Standard normal by Box–Muller (the cosine branch only), from two draws.
double standard_normal(std::mt19937& rng);

}  // namespace skinlab
