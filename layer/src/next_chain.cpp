#include "next_chain.hpp"

#include <cstring>

#include <openxr/openxr_reflection.h>

namespace fovea::layer {

std::size_t structure_size(XrStructureType type) {
  switch (type) {
#define FOVEA_LAYER_SIZE(name, type_enum) \
  case type_enum: return sizeof(name);
    XR_LIST_STRUCTURE_TYPES_CORE(FOVEA_LAYER_SIZE)
#undef FOVEA_LAYER_SIZE
    default: return 0;
  }
}

const void* ChainCopies::without(const void* chain, XrStructureType drop, std::size_t* lost) {
  if (lost) *lost = 0;
  std::vector<const XrBaseInStructure*> before;
  const auto* node = static_cast<const XrBaseInStructure*>(chain);
  for (; node && node->type != drop; node = node->next) before.push_back(node);
  if (!node) return chain;  // nothing to drop: the chain as it is
  const void* head = node->next;
  // Relinked back to front so each copy points at the one after it.
  for (auto it = before.rbegin(); it != before.rend(); ++it) {
    const std::size_t size = structure_size((*it)->type);
    if (size < sizeof(XrBaseInStructure)) {
      if (lost) *lost = std::size_t(before.rend() - it);  // it and everything before it
      return head;
    }
    auto& block = blocks_.emplace_back((size + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t));
    std::memcpy(block.data(), *it, size);
    reinterpret_cast<XrBaseInStructure*>(block.data())->next = static_cast<const XrBaseInStructure*>(head);
    head = block.data();
  }
  return head;
}

}  // namespace fovea::layer
