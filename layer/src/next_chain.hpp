#pragma once
// Keeping an application's `next` chain on a structure the layer replaces, without the
// structures the layer consumes (e.g. the depth it chains to a projection view, which
// describes the application's image, not the layer's).
#include <cstddef>
#include <vector>

#include <openxr/openxr.h>

namespace fovea::layer {

// The size of an OpenXR core structure of type `type` (openxr_reflection.h); 0 when the
// headers do not know it.
std::size_t structure_size(XrStructureType type);

// Storage for the copied part of chains; valid until the next clear().
class ChainCopies {
 public:
  // `chain` without its first structure of type `drop`. The structures after it are shared
  // with the application's chain (valid while the application's call is); those before it are
  // copied and relinked. A structure before it of a size the headers do not know cannot be
  // copied: the chain then starts after it, and `*lost` (if given) counts what was left out.
  const void* without(const void* chain, XrStructureType drop, std::size_t* lost = nullptr);
  void clear() { blocks_.clear(); }

 private:
  std::vector<std::vector<std::max_align_t>> blocks_;
};

}  // namespace fovea::layer
