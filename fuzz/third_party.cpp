// Fuzz builds only: the header-only parsers behind the scene loaders (tinygltf,
// tinyobjloader, stb_image) compiled from their Debian headers with the fuzzer's coverage
// and sanitizers. The executable's definitions take precedence over those of the Debian
// shared libraries, so crashes and undefined behaviour inside them are found too, and
// libFuzzer sees their branches.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define STB_IMAGE_IMPLEMENTATION
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>
