#include "texture_decode.hpp"

#include <algorithm>
#include <iterator>
#include <limits>

#include <stb/stb_image.h>

#include "fovea/core/error.hpp"

namespace fovea::renderer::detail {

bool decode_texture(std::span<const unsigned char> bytes, const SceneLimits& limits, const std::string& origin,
                    std::size_t& decoded, Texture& t, std::string& why) {
  int w = 0, h = 0, n = 0;
  if (bytes.empty() || bytes.size() > std::size_t(std::numeric_limits<int>::max()) ||
      !stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n) || w < 1 || h < 1) {
    why = "undecodable";
    return false;
  }
  if (w > limits.max_texture_size || h > limits.max_texture_size) {
    why = std::to_string(w) + "x" + std::to_string(h) + " is larger than " + std::to_string(limits.max_texture_size) +
          " pixels a side";
    return false;
  }
  // stb's 16-bit readers other than PNG's (PNM with maxval > 255, PSD) trust the header's
  // size over the bytes present: a short 16-bit PNM overflowed in stbi__convert_16_to_8
  // (fuzz/regressions/gltf). glTF's images are PNG or JPEG; OBJ scenes use 8-bit formats.
  static constexpr unsigned char kPng[] = {0x89, 'P', 'N', 'G'};
  const bool png = bytes.size() >= sizeof kPng && std::equal(std::begin(kPng), std::end(kPng), bytes.begin());
  if (!png && stbi_is_16_bit_from_memory(bytes.data(), int(bytes.size()))) {
    why = "a 16-bit image other than PNG (not supported)";
    return false;
  }
  const std::size_t need = std::size_t(w) * std::size_t(h) * 4;
  if (need > limits.max_texture_bytes - decoded)
    throw core::InputError(origin + ": textures need more than " + std::to_string(limits.max_texture_bytes >> 20) +
                           " MiB decoded, refused");
  unsigned char* px = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 4);
  if (!px) {
    why = "undecodable";
    return false;
  }
  decoded += need;
  t.width = w;
  t.height = h;
  t.rgba.assign(px, px + need);
  stbi_image_free(px);
  return true;
}

}  // namespace fovea::renderer::detail
