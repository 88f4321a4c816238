#include "pathbench/run/film_hash.h"

#include <fmt/format.h>

#include <bit>
#include <cstdint>

namespace pb::run {

namespace {

struct Fnv1a64 {
  uint64_t h = 0xcbf29ce484222325ull;
  void add(uint64_t word) {
    h ^= word;
    h *= 0x100000001b3ull;
  }
};

}  // namespace

std::string film_hash(const Film& film) {
  Fnv1a64 f;
  f.add(film.width());
  f.add(film.height());
  f.add(std::bit_cast<uint64_t>(film.scale()));
  for (int64_t s : film.raw_sums()) f.add(uint64_t(s));
  for (uint32_t c : film.counts()) f.add(c);
  return fmt::format("fnv1a64:{:016x}", f.h);
}

}  // namespace pb::run
