#pragma once
// An image checksum that puts correctness beside speed in the history (tools/history):
// a hash of the film's exact integer state — size, fixed-point scale, every pixel's
// 64-bit sums and sample counts — so two runs that made the same image bit for bit have
// the same hash on any device, strategy, thread count or (later) rank split, and any
// change of a single sample changes it. Not cryptographic: a change detector.
#include <string>

#include "pathbench/common/film.h"

namespace pb::run {

// "fnv1a64:" and 16 hex digits: FNV-1a over the film's 64-bit words (width, height,
// scale's bits, sums, counts), word by word so a 2048x2048 film takes milliseconds.
std::string film_hash(const Film& film);

}  // namespace pb::run
