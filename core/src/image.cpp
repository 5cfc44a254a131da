#include "fovea/core/image.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include "fovea/core/error.hpp"

namespace fovea::core {

float srgb_encode(float x) {
  if (!(x > 0)) return 0;  // also NaN
  if (x >= 1) return 1;
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1 / 2.4f) - 0.055f;
}

float srgb_decode(float x) {
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}

void write_file_atomic(const std::string& path, std::span<const std::uint8_t> bytes) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  // The path is the user's: an unwritable one is bad input (the directory's name, rights).
  if (!f) throw InputError(path + ": cannot open for writing: " + std::strerror(errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": rename failed: " + ec.message());
  }
}

void write_file_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void write_png(const std::string& path, const Image& img, Encoding enc) {
  if (img.width < 1 || img.height < 1) throw std::runtime_error(path + ": empty image");
  std::vector<std::uint8_t> rgba(size_t(img.width) * img.height * 4);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      float v = img.pixels[i][c];
      if (c < 3 && enc == Encoding::Srgb) v = srgb_encode(v);
      v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
      rgba[i * 4 + c] = static_cast<std::uint8_t>(std::lround(v * 255.0f));
    }
  std::vector<std::uint8_t> png;
  auto sink = [](void* ctx, void* data, int size) {
    auto* v = static_cast<std::vector<std::uint8_t>*>(ctx);
    v->insert(v->end(), static_cast<std::uint8_t*>(data), static_cast<std::uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(sink, &png, img.width, img.height, 4, rgba.data(), img.width * 4))
    throw std::runtime_error(path + ": PNG encoding failed");
  write_file_atomic(path, png);
}

Image read_png(const std::string& path, Encoding enc) {
  int w = 0, h = 0, n = 0;
  std::uint8_t* data = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (!data) throw InputError(path + ": cannot read PNG (" + std::string(stbi_failure_reason()) + ")");
  Image img(w, h);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      float v = data[i * 4 + c] / 255.0f;
      img.pixels[i][c] = (c < 3 && enc == Encoding::Srgb) ? srgb_decode(v) : v;
    }
  stbi_image_free(data);
  return img;
}

}  // namespace fovea::core
