#pragma once
// The table of temporary output files that a fatal signal must remove (internal to
// output_file.cpp; the public switch is pb::install_output_signal_cleanup).
namespace pb::detail {

// Records a temporary file's path; returns its slot, or -1 when the table is full
// or the path too long (the file is then still removed on every normal exit path).
int register_temp_file(const char* path) noexcept;
void unregister_temp_file(int slot) noexcept;

}  // namespace pb::detail
