#pragma once
// The rank render's report (ranks_render.h), apart from MPI so that it is tested in
// every build: one rank's entry, and rank 0's merge of all entries into the frame's
// report, extra["ranks"]:
//   per_rank             device, host, GPU index or threads, samples per pixel, chunks,
//                        tracer seconds, rays, memory, of each rank;
//   load_balance         max / mean of the ranks' tracer seconds (1 = even);
//   parallel_efficiency  sum of the ranks' tracer seconds / (ranks x frame seconds; the
//                        longest rank's own wall seconds where a rank left the common
//                        barrier early and traced longer than rank 0's frame): the
//                        share of the ranks' time spent tracing rather than waiting, in
//                        chunk overhead or in the reduction (1 = none lost). Strong-scaling
//                        efficiency against one rank (T1 / (N x TN)) needs a one-rank run:
//                        tools/mpi_scaling.py computes it;
//   device_share         the frame's samples traced by each device kind (hybrid runs);
//   reduce_seconds       the film reduction onto rank 0.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pathbench/common/report.h"
#include "pathbench/common/settings.h"

namespace pb::run {

nlohmann::json rank_entry(int rank, const std::string& host, const RenderSettings& s, const RunReport& r,
                          int gpu_index, uint64_t samples, int chunks, double wall_seconds);  // samples: (pixel, sample) pairs

// Sums rays, paths and discarded samples of `ranks` (rank_entry dumps, in rank order) into
// `report` (rank 0's own), sets its times to the frame's, and adds extra["ranks"].
void merge_ranks(RunReport& report, const std::vector<std::string>& ranks, double frame_seconds,
                 double reduce_seconds, const std::string& balance);

// The first word where two settings_key strings differ, for the refusal's message.
std::string first_difference(const std::string& rank0, const std::string& mine);

}  // namespace pb::run
