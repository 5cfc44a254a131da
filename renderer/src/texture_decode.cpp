#include "texture_decode.hpp"

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
