#include "pathbench/output/image_io.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "pathbench/output/output_file.h"

#if PATHBENCH_HAVE_OIIO
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#endif

namespace pb {

namespace {

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

float linear_to_srgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

// PFM stores rows bottom to top, little-endian when the scale is negative.
void write_pfm(OutputFile& out, const std::vector<float>& rgb, unsigned w, unsigned h) {
  out.write(fmt::format("PF\n{} {}\n-1.0\n", w, h));
  for (unsigned y = h; y-- > 0;) out.write(&rgb[size_t(y) * w * 3], size_t(w) * 3 * sizeof(float));
}

#if PATHBENCH_HAVE_OIIO
// OpenImageIO writes through this proxy into the OutputFile's descriptor, so every
// byte it writes is checked (OIIO's own stdio handle loses errors such as a full
// disk at fclose) and no second handle to the file is opened by name.
class CheckedProxy final : public OIIO::Filesystem::IOProxy {
 public:
  explicit CheckedProxy(OutputFile& f) : IOProxy(f.temp_path(), Write), file_(f) {}
  const char* proxytype() const override { return "pathbench-output"; }
  size_t write(const void* buf, size_t n) override {
    const size_t done = pwrite(buf, n, m_pos);
    m_pos += int64_t(done);
    return done;
  }
  size_t pwrite(const void* buf, size_t n, int64_t offset) override {
    if (!file_.write_at(buf, n, off_t(offset))) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = errno;
      return 0;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    size_ = std::max(size_, size_t(offset) + n);
    return n;
  }
  size_t size() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return size_;
  }
  int error_number() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
  }

 private:
  OutputFile& file_;
  mutable std::mutex mutex_;
  size_t size_ = 0;
  int error_ = 0;
};

void write_oiio(OutputFile& f, const std::string& ext, const std::vector<float>& rgb, unsigned w, unsigned h,
                const ImageMetadata& metadata) {
  using namespace OIIO;
  const std::string& path = f.path();
  auto out = ImageOutput::create(ext.substr(1));  // the format by its (lower-case) name
  if (!out) throw InputError(fmt::format("{}: OpenImageIO cannot write this format ({})", display_path(path), OIIO::geterror()));
  if (!out->supports("ioproxy"))
    throw InputError(fmt::format("{}: OpenImageIO cannot write '{}' through a checked handle; use .exr, .png or .pfm",
                                 display_path(path), ext));
  CheckedProxy proxy(f);
  const bool eight_bit = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  ImageSpec spec(int(w), int(h), 3, eight_bit ? TypeDesc::UINT8 : TypeDesc::FLOAT);
  for (const auto& [key, value] : metadata) spec.attribute(key, value);
  bool ok = out->set_ioproxy(&proxy) && out->open(f.temp_path(), spec);
  if (ok && eight_bit) {
    std::vector<unsigned char> px(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) px[i] = (unsigned char)std::lround(linear_to_srgb(rgb[i]) * 255.0f);
    ok = out->write_image(TypeDesc::UINT8, px.data());
  } else if (ok) {
    ok = out->write_image(TypeDesc::FLOAT, rgb.data());
  }
  ok = out->close() && ok;
  if (proxy.error_number()) f.fail("write failed", proxy.error_number());
  if (!ok) throw InputError(fmt::format("{}: {}", display_path(path), out->geterror()));
}
#endif

// Read through read_input_file (regular files only, bounded); the header's size must
// match the data, so a hostile header cannot ask for a huge allocation.
std::vector<float> read_pfm(const std::string& path, unsigned& w, unsigned& h) {
  const std::string data = read_input_file(path, "image file (PFM)", limits::kMaxImageBytes);
  std::istringstream in(data.substr(0, std::min<size_t>(data.size(), 256)));
  std::string magic;
  uint64_t w64 = 0, h64 = 0;
  double scale = 0;
  in >> magic >> w64 >> h64 >> scale;
  if (magic != "PF" || !in || !(scale < 0) || w64 == 0 || h64 == 0 || w64 > (1u << 30) || h64 > (1u << 30))
    throw InputError(fmt::format("{}: not a little-endian RGB PFM", path));
  const size_t header = size_t(in.tellg()) + 1;  // one whitespace byte after the scale
  const uint64_t bytes = w64 * h64 * 12;
  if (header > data.size() || data.size() - header != bytes)
    throw InputError(fmt::format("{}: a {}x{} PFM needs {} bytes of pixels, the file has {}", path, w64, h64, bytes,
                                 data.size() < header ? 0 : data.size() - header));
  w = unsigned(w64);
  h = unsigned(h64);
  std::vector<float> rgb(size_t(w) * h * 3);
  const size_t row = size_t(w) * 3 * sizeof(float);
  for (unsigned y = 0; y < h; ++y)  // rows bottom to top
    std::memcpy(&rgb[size_t(h - 1 - y) * w * 3], data.data() + header + y * row, row);
  return rgb;
}

}  // namespace

bool image_io_has_oiio() { return PATHBENCH_HAVE_OIIO; }

std::string image_extension(const std::string& path) { return extension_of(path); }

void write_image(OutputFile& out, const std::vector<float>& rgb, unsigned w, unsigned h, const ImageMetadata& metadata) {
  const std::string& path = out.path();
  if (rgb.size() != size_t(w) * h * 3) throw std::runtime_error(fmt::format("{}: image buffer has the wrong size", path));
  const std::string ext = extension_of(path);
  if (ext == ".pfm") {
    write_pfm(out, rgb, w, h);
  } else {
#if PATHBENCH_HAVE_OIIO
    write_oiio(out, ext, rgb, w, h, metadata);
#else
    throw InputError(fmt::format(
        "{}: this build has no OpenImageIO (PATHBENCH_OIIO=OFF), so it cannot write '{}' files; write .pfm instead",
        display_path(path), ext));
#endif
  }
  out.finish();
}

void write_image(const std::string& path, const std::vector<float>& rgb, unsigned w, unsigned h,
                 const ImageMetadata& metadata) {
  OutputFile out(path);
  write_image(out, rgb, w, h, metadata);
  out.commit();
}

std::vector<float> read_image(const std::string& path, unsigned& w, unsigned& h) {
  if (extension_of(path) == ".pfm") return read_pfm(path, w, h);
#if PATHBENCH_HAVE_OIIO
  using namespace OIIO;
  auto in = ImageInput::open(path);
  if (!in) throw std::runtime_error(fmt::format("{}: {}", path, OIIO::geterror()));
  const ImageSpec& spec = in->spec();
  w = unsigned(spec.width);
  h = unsigned(spec.height);
  std::vector<float> all(size_t(w) * h * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, all.data()))
    throw std::runtime_error(fmt::format("{}: {}", path, in->geterror()));
  std::vector<float> rgb(size_t(w) * h * 3);
  for (size_t p = 0; p < size_t(w) * h; ++p)
    for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = all[p * spec.nchannels + std::min(c, spec.nchannels - 1)];
  return rgb;
#else
  throw std::runtime_error(fmt::format("{}: this build has no OpenImageIO; only .pfm can be read", path));
#endif
}

}  // namespace pb
