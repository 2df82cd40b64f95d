#include "rtcl/render/image.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "rtcl/error.hpp"
#include "rtcl/io/atomic_file.hpp"

namespace rtcl {

namespace {

std::string extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

float srgb_decode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

}  // namespace

float srgb_encode(float linear) {
  float v = std::clamp(std::isnan(linear) ? 0.0f : linear, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

bool is_float_format(const std::string& path) {
  std::string ext = extension(path);
  return ext == ".exr" || ext == ".hdr" || ext == ".pfm";
}

void check_image_path(const std::string& path) {
  if (extension(path).empty())
    throw Error(path + ": no file extension to choose the image format by (e.g. .png, .exr)");
  if (!OIIO::ImageOutput::create(path)) {
    OIIO::geterror();  // clear OpenImageIO's message: ours names the problem
    throw Error(path + ": no image format for the extension '" + extension(path) + "' (e.g. .png, .exr)");
  }
  check_writable(path);
}

void write_image(const std::string& path, const Image& image) {
  if (image.width == 0 || image.height == 0 || image.rgb.size() != std::size_t(image.width) * image.height * 3)
    throw Error(path + ": cannot write an empty or inconsistent image");
  check_image_path(path);
  const bool linear = is_float_format(path);
  std::vector<unsigned char> bytes;
  if (!linear) {
    bytes.resize(image.rgb.size());
    for (std::size_t i = 0; i < bytes.size(); ++i)
      bytes[i] = static_cast<unsigned char>(std::lround(srgb_encode(image.rgb[i]) * 255.0f));
  }
  write_file_atomically(path, [&](const std::string& temp) {
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) throw Error(path + ": " + OIIO::geterror());
    OIIO::ImageSpec spec(static_cast<int>(image.width), static_cast<int>(image.height), 3,
                         linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", linear ? "Linear" : "sRGB");
    spec.attribute("Software", "rtcl render");
    bool ok = out->open(temp, spec) &&
              (linear ? out->write_image(OIIO::TypeDesc::FLOAT, image.rgb.data())
                      : out->write_image(OIIO::TypeDesc::UINT8, bytes.data())) &&
              out->close();
    if (!ok) throw Error(path + ": writing the image failed: " + out->geterror());
  });
}

Image read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path + ": cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels < 1) throw Error(path + ": empty image");
  std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw Error(path + ": reading the image failed: " + in->geterror());
  bool encoded = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  Image image;
  image.width = static_cast<std::uint32_t>(spec.width);
  image.height = static_cast<std::uint32_t>(spec.height);
  image.rgb.resize(std::size_t(image.width) * image.height * 3);
  for (std::size_t p = 0; p < std::size_t(image.width) * image.height; ++p)
    for (int c = 0; c < 3; ++c) {
      float v = all[p * spec.nchannels + std::min(c, spec.nchannels - 1)];
      image.rgb[p * 3 + c] = encoded ? srgb_decode(v) : v;
    }
  in->close();
  return image;
}

}  // namespace rtcl
