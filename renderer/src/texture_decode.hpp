#pragma once
// Texture decoding shared by the scene loaders, within the scene's limits.
#include <cstddef>
#include <span>
#include <string>

#include "fovea/renderer/scene.hpp"

namespace fovea::renderer::detail {

// Decodes an encoded image (any format stb_image reads) to RGBA8. Returns false with `why`
// if it is undecodable or larger than limits.max_texture_size a side; throws InputError
// naming `origin` when the textures decoded so far (`decoded`, bytes) plus this one would
// pass limits.max_texture_bytes. The size is read from the header before decoding.
bool decode_texture(std::span<const unsigned char> bytes, const SceneLimits& limits, const std::string& origin,
                    std::size_t& decoded, Texture& t, std::string& why);

}  // namespace fovea::renderer::detail
