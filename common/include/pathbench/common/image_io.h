#pragma once
// Image output. EXR (float, linear) and PNG (sRGB, 8-bit) through OpenImageIO;
// PFM (float, linear) always, with no dependency, so a build without OpenImageIO
// (an offline GPU host) can still hand images back for comparison.
#include <string>
#include <vector>

namespace pb {

bool image_io_has_oiio();
// Writes RGB float pixels, row 0 at the top. The format follows the file name's
// extension (.exr, .png, .pfm, and what OpenImageIO supports). Writes to a temporary
// file and renames it, so a failure leaves nothing half-written. Throws
// std::runtime_error with the path and reason on failure.
void write_image(const std::string& path, const std::vector<float>& rgb, unsigned width, unsigned height);
// Reads an RGB float image (.pfm always; others through OpenImageIO).
std::vector<float> read_image(const std::string& path, unsigned& width, unsigned& height);

}  // namespace pb
