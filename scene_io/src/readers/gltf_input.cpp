// The glTF reader's checks on the bytes before tinygltf parses them (gltf_input.h).
#include "readers/gltf_input.h"

#include <fmt/core.h>

#include <cstdint>

#include "pathbench/common/errors.h"
#include "pathbench/common/json_input.h"
#include "pathbench/common/limits.h"

namespace pb::scene_io {

namespace {

uint32_t le32(const std::string& s, uint64_t at) {
  const auto b = [&](uint64_t i) { return uint32_t(static_cast<unsigned char>(s[size_t(at + i)])); };
  return b(0) | b(1) << 8 | b(2) << 16 | b(3) << 24;
}

}  // namespace

std::string_view gltf_json_text(const std::string& path, const std::string& text, bool binary) {
  if (!binary) return text;
  auto fail = [&](const std::string& what) { throw InputError(fmt::format("{}: malformed GLB: {}", path, what)); };
  // The layout (glTF 2.0, "Binary glTF Layout"): a 12-byte header (magic, version,
  // length), then chunks of an 8-byte header (length, type) and their data; the first
  // is JSON, an optional second BIN. Every offset in 64 bits: no sum can wrap.
  const uint64_t size = text.size();
  if (size < 20) fail(fmt::format("{} bytes: too short for a header and a JSON chunk (20 bytes at least)", size));
  if (text.compare(0, 4, "glTF") != 0) fail("the file does not start with the magic 'glTF'");
  const uint64_t length = le32(text, 8), json_length = le32(text, 12);
  if (length > size) fail(fmt::format("the header's length {} is more than the file's {} bytes", length, size));
  if (le32(text, 16) != 0x4E4F534Au) fail("the first chunk is not of type JSON");
  const uint64_t json_end = 20 + json_length;
  if (json_length == 0 || json_end > length)
    fail(fmt::format("the JSON chunk ({} bytes from byte 20) does not fit in the {} bytes of the file", json_length,
                     length));
  if (json_end < length) {
    if (json_end + 8 > length) fail(fmt::format("the BIN chunk's header at byte {} reaches past the end ({})", json_end, length));
    const uint64_t bin_length = le32(text, json_end);
    if (json_end + 8 + bin_length > length)
      fail(fmt::format("the BIN chunk ({} bytes from byte {}) reaches past the end of the file ({} bytes)", bin_length,
                       json_end + 8, length));
  }
  return std::string_view(text).substr(20, size_t(json_length));
}

void check_gltf_json_shape(const std::string& path, std::string_view json) {
  // Keys per object are not bounded here: tinygltf's objects are std::maps.
  check_json_bounds(json, path, {kMaxJsonDepth, SIZE_MAX, limits::kMaxGltfJsonValues});
}

}  // namespace pb::scene_io
