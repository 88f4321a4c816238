#pragma once
// The one way pathbench reads an input file (scene JSON, OBJ, MTL, reference image,
// benchmark JSON): regular files only, with a size limit that names itself. The file
// is opened non-blocking (a FIFO does not hang the open) and checked with fstat on the
// opened descriptor (no stat-then-open race), so /dev/zero, /dev/urandom, a FIFO or a
// directory give one InputError instead of a hang or unbounded memory.
#include <cstdint>
#include <string>

namespace pb {

// Reads all of `path`. `what` names the kind of file for messages ("scene file"); the
// limit error reads "<path>: <what>s are limited to 64 MiB (this one is ...)". Throws
// InputError for a missing, unreadable, special or oversized file.
std::string read_input_file(const std::string& path, const char* what, uint64_t max_bytes);

// "64 MiB", "1 GiB", "512 bytes": for limit messages.
std::string format_bytes(uint64_t bytes);

}  // namespace pb
