// A build without the CUDA tracer (PATHBENCH_CUDA off or no nvcc): run/'s GPU tracer says
// why it is not there, and every call that would trace refuses with that reason.
#include "pathbench/common/errors.h"
#include "pathbench/run/tracer.h"

namespace pb::run {

namespace {
constexpr const char* kWhy = "this build has no CUDA tracer (configure with -DPATHBENCH_CUDA=ON and nvcc on PATH)";

class NoGpuTracer final : public Tracer {
 public:
  bool available(std::string* why_not) const override {
    if (why_not) *why_not = kWhy;
    return false;
  }
  void render(const Scene&, const RenderSettings&, Film&, RunReport&, bool) const override { refuse(); }
  std::unique_ptr<PreparedScene> prepare(const Scene&, const RenderSettings&) const override { refuse(); }
  int device_count() const override { return 0; }
  int select_device(int) const override { return -1; }

 private:
  [[noreturn]] static void refuse() { throw InputError(std::string("--device gpu: ") + kWhy); }
};
}  // namespace

const Tracer& gpu_tracer() {
  static const NoGpuTracer t;
  return t;
}

}  // namespace pb::run
