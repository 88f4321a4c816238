#pragma once
// Private to the glTF reader (gltf_scene.cpp): what is checked in the bytes of a .gltf
// or .glb before tinygltf sees them, where tinygltf 2.7 itself would crash, overflow
// its stack or spend gigabytes. Each check throws InputError naming the file and the
// limit.
#include <string>
#include <string_view>

namespace pb::scene_io {

// The JSON text tinygltf parses: all of a .gltf, or a .glb's JSON chunk once the GLB
// container (header, chunk lengths) is checked to lie inside the file. tinygltf does
// not check that the BIN chunk's header and data end inside the file, and copies
// from past its end.
std::string_view gltf_json_text(const std::string& path, const std::string& text, bool binary);

// JSON nested at most kMaxJsonDepth deep (tinygltf converts extras and extensions
// recursively, a stack frame per level: 20,000 levels overflow the stack) and with at
// most limits::kMaxGltfJsonValues values. One pass, no recursion; only brackets and
// commas outside strings are counted, so malformed JSON is left to tinygltf's parser.
void check_gltf_json_shape(const std::string& path, std::string_view json);

}  // namespace pb::scene_io
