#pragma once
// Image output. EXR (float, linear) and PNG (sRGB, 8-bit) through OpenImageIO;
// PFM (float, linear) always, with no dependency, so a build without OpenImageIO
// (an offline GPU host) can still hand images back for comparison.
#include <string>
#include <utility>
#include <vector>

namespace pb {

class OutputFile;

// Named string attributes written into the image's header (EXR attributes, PNG text
// chunks): the scene, settings, seed, spp and commit a render came from. PFM has no
// place for them.
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

bool image_io_has_oiio();
// The file name's extension in lower case (".exr"); ".EXR" names the same format.
std::string image_extension(const std::string& path);
// Writes RGB float pixels, row 0 at the top. The format follows the file name's
// extension (.exr, .png, .pfm; OpenImageIO's other formats where it can write them
// through a checked handle). Writes to a temporary file (OutputFile: every write
// checked, fsync) and renames it, so a failure leaves nothing. Throws InputError
// with the path and reason on failure (a full disk, a folder that cannot be written).
void write_image(const std::string& path, const std::vector<float>& rgb, unsigned width, unsigned height,
                 const ImageMetadata& metadata = {});
// The same into `out`, finished but not committed: the caller renames it into place
// with out.commit(), e.g. once every output of a run has been written.
void write_image(OutputFile& out, const std::vector<float>& rgb, unsigned width, unsigned height,
                 const ImageMetadata& metadata = {});
// Reads an RGB float image (.pfm always; others through OpenImageIO).
std::vector<float> read_image(const std::string& path, unsigned& width, unsigned& height);

}  // namespace pb
