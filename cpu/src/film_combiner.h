#pragma once
// One wavefront slice's additions to the shared film, combined while they hit one pixel.
// Film::add_atomic costs four locked read-modify-writes a path (three sums and the
// count), which at ~10 cycles each are a large part of the wavefront's own time on the
// CPU (docs/notes/cpu-log.md, "SoA hand-over"); the wavefront hands out the samples of one
// pixel together (SampleSource), so its paths mostly end next to others of the same
// pixel. Their quantised values are summed here in plain integers and added to the film
// once per run of one pixel. The sums are integers, so the film holds the same bits
// whatever the grouping. With a variance film (double sums of squares, whose rounding
// depends on the order) every sample goes to add_atomic as before.
#include <atomic>
#include <cstdint>

#include "pathbench/common/film.h"

namespace pb::cpu {

class FilmCombiner {
 public:
  explicit FilmCombiner(Film& film) : film_(film), direct_(film.has_variance()) {}
  FilmCombiner(const FilmCombiner&) = delete;
  FilmCombiner& operator=(const FilmCombiner&) = delete;
  ~FilmCombiner() { flush(); }

  // Film::add_atomic's contract: false (nothing added) for a sample the film refuses.
  bool add(uint32_t pixel, Vec3f L) {
    if (direct_) return film_.add_atomic(pixel, L);
    if (!sample_acceptable(L, film_.sample_limit())) return false;
    if (pixel != pixel_) {
      flush();
      pixel_ = pixel;
    }
    const double scale = film_.scale();
    sum_[0] += quantize_radiance(L.x, scale);
    sum_[1] += quantize_radiance(L.y, scale);
    sum_[2] += quantize_radiance(L.z, scale);
    ++count_;
    return true;
  }

  // The pending run to the film (before the film is read, and on destruction).
  void flush() {
    if (count_ == 0) return;
    int64_t* s = &film_.raw_sums()[size_t(pixel_) * 3];
    for (int c = 0; c < 3; ++c) std::atomic_ref<int64_t>(s[c]).fetch_add(sum_[c], std::memory_order_relaxed);
    std::atomic_ref<uint32_t>(film_.counts()[pixel_]).fetch_add(count_, std::memory_order_relaxed);
    sum_[0] = sum_[1] = sum_[2] = 0;
    count_ = 0;
  }

 private:
  Film& film_;
  bool direct_;
  uint32_t pixel_ = 0, count_ = 0;
  int64_t sum_[3] = {0, 0, 0};
};

}  // namespace pb::cpu
