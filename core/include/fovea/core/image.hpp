#pragma once
// Images: linear float RGBA in memory; PNG (8-bit sRGB or as-is) on disk. Files are
// written to a temporary name and renamed, so a failed write never leaves a truncated file.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

namespace fovea::core {

struct Image {
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;  // row-major, top row first

  Image() = default;
  Image(int w, int h, glm::vec4 fill = {0, 0, 0, 1}) : width(w), height(h), pixels(size_t(w) * h, fill) {}
  glm::vec4& at(int x, int y) { return pixels[size_t(y) * width + x]; }
  const glm::vec4& at(int x, int y) const { return pixels[size_t(y) * width + x]; }
};

enum class Encoding { Srgb, Linear };

// RGB(A) PNG; values are clamped to [0,1], NaN written as 0. Throws InputError when the path
// cannot be opened for writing, std::runtime_error when writing fails.
void write_png(const std::string& path, const Image& img, Encoding enc = Encoding::Srgb);
// Reads an 8-bit PNG into linear floats (inverse of write_png). Throws InputError.
Image read_png(const std::string& path, Encoding enc = Encoding::Srgb);

// Writes bytes to `path` through `path.tmp.<pid>` + rename.
void write_file_atomic(const std::string& path, std::span<const std::uint8_t> bytes);
void write_file_atomic(const std::string& path, const std::string& text);

float srgb_encode(float linear);
float srgb_decode(float encoded);

}  // namespace fovea::core
