#pragma once
// tinygltf as pathbench compiles it (gltf_impl.cpp holds the implementation): no image
// decoding or writing (textures are named in a warning, never read), no file system
// of its own (every buffer file is read through the scene's FileReader: regular files
// only, bounded; and no wordexp() shell expansion of file names).
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>
