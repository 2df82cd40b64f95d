// Rendered images and their files (OpenImageIO: the format follows the file
// extension). Float formats (.exr, .hdr, .pfm) keep linear floats; others
// (.png, .jpg, .tif, ...) get 8-bit sRGB-encoded values clamped to [0, 1].
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rtcl {

struct Image {
  std::uint32_t width = 0, height = 0;
  std::vector<float> rgb;  // linear RGB, 3 floats per pixel, rows from the top

  float at(std::uint32_t x, std::uint32_t y, int channel) const { return rgb[(std::size_t(y) * width + x) * 3 + channel]; }
};

// True for extensions written as linear floats.
bool is_float_format(const std::string& path);

// Writes the image whole or not at all (a temporary file in the same
// directory, renamed at the end). Throws Error naming the path for an
// unknown extension, a missing or unwritable directory, or a write failure.
void write_image(const std::string& path, const Image& image);

// Throws Error naming the path unless its extension names an image format
// OpenImageIO can write and its directory is writable: a check before a long
// render (write_image still reports its own failures).
void check_image_path(const std::string& path);

// Reads an image file as linear RGB (sRGB-decoded when the file is 8-bit).
// Throws Error naming the path.
Image read_image(const std::string& path);

// sRGB transfer function of a linear value, clamped to [0, 1].
float srgb_encode(float linear);

}  // namespace rtcl
