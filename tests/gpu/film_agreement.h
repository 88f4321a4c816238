#pragma once
// How closely two films of one frame agree, as the GPU-vs-CPU checks count it: a pixel
// agrees when every channel of its mean is within `rel` of the other film's, relative to
// the larger of the two (issue 15's acceptance: >= 99.99 % of the pixels within 1e-4).
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "pathbench/common/film.h"

namespace pb::test {

struct FilmAgreement {
  size_t pixels = 0, within = 0, differ = 0;  // differ: any film sum not equal
  double worst = 0;                          // largest relative difference of a channel
  double share_within() const { return pixels ? double(within) / double(pixels) : 0.0; }
};

inline FilmAgreement film_agreement(const Film& a, const Film& b, double rel = 1e-4) {
  const auto ma = a.mean(), mb = b.mean();
  FilmAgreement r;
  r.pixels = ma.size() / 3;
  for (size_t p = 0; p < r.pixels; ++p) {
    bool ok = true, same = true;
    for (int k = 0; k < 3; ++k) {
      const double x = ma[p * 3 + k], y = mb[p * 3 + k];
      const double d = std::fabs(x - y) / std::max({std::fabs(x), std::fabs(y), 1e-30});
      if (x != y) r.worst = std::max(r.worst, d);
      if (!(d <= rel)) ok = false;
      if (a.raw_sums()[p * 3 + k] != b.raw_sums()[p * 3 + k]) same = false;
    }
    r.within += ok;
    r.differ += !same;
  }
  return r;
}

}  // namespace pb::test
