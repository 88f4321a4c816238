// The exact film reduction over MPI ranks (World::reduce_film, reduce_film_rows): every
// rank's 64-bit integer sums and counts into rank 0's film, overflow checked.
#include <algorithm>
#include <climits>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "mpi_detail.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/world.h"

namespace pb::run {

namespace {
// A sum no film holds (|sum| < 2^62 + 2^62): the checked reduction's "overflowed", sticky.
constexpr int64_t kOverflowed = INT64_MIN;
void checked_sum(void* in, void* inout, int* len, MPI_Datatype*) {
  const int64_t* a = static_cast<const int64_t*>(in);
  int64_t* b = static_cast<int64_t*>(inout);
  for (int i = 0; i < *len; ++i)
    if (a[i] == kOverflowed || b[i] == kOverflowed || __builtin_add_overflow(a[i], b[i], &b[i])) b[i] = kOverflowed;
}

// MPI counts are int: reduce long arrays in pieces.
template <class T> void reduce_to_root(T* data, size_t n, MPI_Datatype type, MPI_Op op, bool root) {
  constexpr size_t kPiece = size_t(1) << 28;
  for (size_t at = 0; at < n; at += kPiece) {
    const int count = int(std::min(kPiece, n - at));
    MPI_Reduce(root ? MPI_IN_PLACE : data + at, root ? data + at : nullptr, count, type, op, 0, MPI_COMM_WORLD);
  }
}

// reduce_film's rules, checked on every rank alike (so that all throw or none does).
void check_same_film(World& w, const Film& film) {
  const std::string shape = fmt::format("{}x{} scale {:a} variance {}", film.width(), film.height(), film.scale(),
                                        film.has_variance());
  for (const std::string& other : w.all(shape))
    if (other != shape)
      throw std::invalid_argument(fmt::format("reduce_film: the ranks' films differ ({} vs {})", shape, other));
}

// Rows' data travel in pieces of at most this many values (MPI counts are int).
constexpr size_t kRowPiece = size_t(1) << 24;
constexpr int kRowsTag = 7301;

// Elements [at, at + n) of one array of the film, sent to rank 0 or received there and
// added (checked for integers: `ok` turns false on an overflow, the rest still added).
template <class T> void send_piece(const T* data, size_t n, MPI_Datatype type) {
  for (size_t at = 0; at < n; at += kRowPiece)
    MPI_Send(data + at, int(std::min(kRowPiece, n - at)), type, 0, kRowsTag, MPI_COMM_WORLD);
}
template <class T> void receive_add(T* into, size_t n, MPI_Datatype type, int from, std::vector<T>& buf, bool& ok) {
  for (size_t at = 0; at < n; at += kRowPiece) {
    const size_t m = std::min(kRowPiece, n - at);
    buf.resize(m);
    MPI_Recv(buf.data(), int(m), type, from, kRowsTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    ok &= add_values(into + at, buf.data(), m);
  }
}
// Rows [first, first + count) of the film's arrays (sums, counts, variance sums): sent to
// rank 0, or received there from `from` and added (`in` keeps the scratch and `ok`).
void send_rows(const Film& film, size_t first, size_t count) {
  const size_t px0 = first * film.width(), px = count * film.width();
  send_piece(film.raw_sums().data() + px0 * 3, px * 3, MPI_INT64_T);
  send_piece(film.counts().data() + px0, px, MPI_UINT32_T);
  if (film.has_variance()) send_piece(film.raw_sum_sq().data() + px0 * 3, px * 3, MPI_DOUBLE);
}
struct Inbox {
  std::vector<int64_t> sums;
  std::vector<uint32_t> counts;
  std::vector<double> sq;
  bool ok = true;
};
void receive_rows(Film& film, size_t first, size_t count, int from, Inbox& in) {
  const size_t px0 = first * film.width(), px = count * film.width();
  receive_add(film.raw_sums().data() + px0 * 3, px * 3, MPI_INT64_T, from, in.sums, in.ok);
  receive_add(film.counts().data() + px0, px, MPI_UINT32_T, from, in.counts, in.ok);
  if (film.has_variance()) receive_add(film.raw_sum_sq().data() + px0 * 3, px * 3, MPI_DOUBLE, from, in.sq, in.ok);
}
}  // namespace

void World::reduce_film(Film& film) {
  if (!mpi_ || size_ == 1) return;
  check_same_film(*this, film);
  // MPI_SUM cannot overflow where the ranks' largest |sums| add up below 2^63 (every
  // partial sum is bounded by that); otherwise a checked sum marks overflowed pixels.
  uint64_t largest = 0;
  for (int64_t v : film.raw_sums()) largest = std::max(largest, v < 0 ? uint64_t(0) - uint64_t(v) : uint64_t(v));
  std::vector<uint64_t> largest_all(size_t(size_), 0);
  MPI_Allgather(&largest, 1, MPI_UINT64_T, largest_all.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  const bool safe = sums_cannot_overflow(largest_all);
  MPI_Op checked = MPI_OP_NULL;
  if (!safe) MPI_Op_create(checked_sum, 1, &checked);
  reduce_to_root(film.raw_sums().data(), film.raw_sums().size(), MPI_INT64_T, safe ? MPI_SUM : checked, root());
  if (!safe) MPI_Op_free(&checked);
  // Counts: every sample index of the frame is traced by one rank, so they add up to spp.
  reduce_to_root(film.counts().data(), film.counts().size(), MPI_UINT32_T, MPI_SUM, root());
  if (film.has_variance()) reduce_to_root(film.raw_sum_sq().data(), film.raw_sum_sq().size(), MPI_DOUBLE, MPI_SUM, root());
  if (!safe && root())
    for (int64_t v : film.raw_sums())
      if (v == kOverflowed) throw std::overflow_error("reduce_film: a pixel sum overflows");
}

void World::reduce_film_rows(Film& film, const std::vector<RowRange>& mine) {
  if (!mpi_ || size_ == 1) return;
  check_same_film(*this, film);
  // Every rank's row ranges, as (first, count) pairs, to rank 0.
  // (Rows outside the film are a bug: thrown after the collectives, so no rank waits.)
  std::vector<uint32_t> flat;
  bool inside = true;
  for (const RowRange& r : mine) inside &= uint64_t(r.first) + r.count <= film.height();
  for (const RowRange& r : inside ? mine : std::vector<RowRange>{}) {
    flat.push_back(r.first);
    flat.push_back(r.count);
  }
  const int n = int(flat.size());
  std::vector<int> counts(root() ? size_t(size_) : 0), displs(counts.size());
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  int total = 0;
  for (size_t r = 0; r < counts.size(); ++r) displs[r] = total, total += counts[r];
  std::vector<uint32_t> all_rows(static_cast<size_t>(total));
  MPI_Gatherv(flat.data(), n, MPI_UINT32_T, all_rows.data(), counts.data(), displs.data(), MPI_UINT32_T, 0,
              MPI_COMM_WORLD);
  // Then each rank's rows, in rank order: rank 0 receives them all before it judges an
  // overflow, so that no sender is left blocked in MPI_Send.
  if (!root()) {
    if (!inside) throw std::invalid_argument("reduce_film_rows: rows outside the film");
    for (const RowRange& r : mine) send_rows(film, r.first, r.count);
    return;
  }
  Inbox in;
  for (int from = 1; from < size_; ++from)
    for (int i = displs[size_t(from)]; i < displs[size_t(from)] + counts[size_t(from)]; i += 2)
      receive_rows(film, all_rows[size_t(i)], all_rows[size_t(i) + 1], from, in);
  if (!inside) throw std::invalid_argument("reduce_film_rows: rows outside the film");
  if (!in.ok) throw std::overflow_error("reduce_film: a pixel sum or sample count overflows");
}

// A sender's header (send_film_rows): its film's width, height, scale (bits), variance, then
// its row ranges as (first, count) pairs.
constexpr int kRowsHeaderTag = 7302;
// The next message from `from` with `tag`, whatever its length, as values of `type` (T's).
template <class T> std::vector<T> receive_message(int from, int tag, MPI_Datatype type) {
  MPI_Status st;
  MPI_Probe(from, tag, MPI_COMM_WORLD, &st);
  int n = 0;
  MPI_Get_count(&st, type, &n);
  std::vector<T> v(size_t(std::max(n, 0)));
  MPI_Recv(v.data(), n, type, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return v;
}
std::vector<uint64_t> rows_header(const Film& film, const std::vector<RowRange>& mine) {
  uint64_t scale_bits;
  const double scale = film.scale();
  std::memcpy(&scale_bits, &scale, sizeof scale_bits);
  std::vector<uint64_t> h{film.width(), film.height(), scale_bits, film.has_variance() ? 1u : 0u};
  for (const RowRange& r : mine) h.push_back(r.first), h.push_back(r.count);
  return h;
}

void World::send_film_rows(Film& film, const std::vector<RowRange>& mine, const std::vector<int>& senders) {
  if (!mpi_ || size_ == 1) return;
  if (!root()) {
    if (mine.empty()) return;  // rank 0 expects nothing of a rank that traced nothing
    const std::vector<uint64_t> h = rows_header(film, mine);
    MPI_Send(h.data(), int(h.size()), MPI_UINT64_T, 0, kRowsHeaderTag, MPI_COMM_WORLD);
    for (const RowRange& r : mine)
      if (uint64_t(r.first) + r.count <= film.height()) send_rows(film, r.first, r.count);  // else refused (the header says)
    return;
  }
  // Rank 0: every sender's header, then its rows (into scratch where they cannot be added:
  // every message is received before anything is refused, so that no sender is left blocked).
  const std::vector<uint64_t> own = rows_header(film, {});
  Inbox in;
  std::string refused;
  for (int from : senders) {
    const std::vector<uint64_t> h = receive_message<uint64_t>(from, kRowsHeaderTag, MPI_UINT64_T);
    const bool same = h.size() >= own.size() && std::equal(own.begin(), own.end(), h.begin()) && h.size() % 2 == 0;
    if (!same && refused.empty())
      refused = fmt::format("send_film_rows: rank {}'s film differs from rank 0's (size, scale or variance)", from);
    for (size_t i = own.size(); i + 1 < h.size(); i += 2) {
      const uint64_t first = h[i], count = h[i + 1];
      if (same && first + count <= film.height()) {
        receive_rows(film, first, count, from, in);
        continue;
      }
      if (refused.empty()) refused = fmt::format("send_film_rows: rank {} sent rows outside the film", from);
      if (first + count > h[1]) continue;  // outside its own film too: it sent nothing for them
      // Not added: its messages are drained (as many as it sent: send_piece's pieces).
      const uint64_t px = count * h[0];
      for (uint64_t values : {px * 3, px, h[3] ? px * 3 : 0})
        for (uint64_t at = 0; at < values; at += kRowPiece) receive_message<uint8_t>(from, kRowsTag, MPI_BYTE);
    }
  }
  if (!refused.empty()) throw std::invalid_argument(refused);
  if (!in.ok) throw std::overflow_error("reduce_film: a pixel sum or sample count overflows");
}

}  // namespace pb::run
