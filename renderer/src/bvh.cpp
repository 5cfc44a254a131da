#include "fovea/renderer/bvh.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>

#include <glm/common.hpp>

namespace fovea::renderer {

namespace {

constexpr int kSahDepth = 60;

struct Aabb {
  glm::vec3 lo{std::numeric_limits<float>::max()};
  glm::vec3 hi{-std::numeric_limits<float>::max()};
  void grow(glm::vec3 p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  void grow(const Aabb& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
  bool empty() const { return lo.x > hi.x; }
  float area() const {
    if (empty()) return 0.0f;
    const glm::vec3 d = hi - lo;
    return 2.0f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
};

struct Prim {
  Aabb box;
  glm::vec3 centroid;
};

struct Node {
  Aabb box;
  std::uint32_t begin = 0, count = 0;
  std::unique_ptr<Node> left, right;
};

class Builder {
 public:
  Builder(std::vector<Prim>& prims, std::vector<std::uint32_t>& order, const BvhOptions& o, int threads)
      : prims_(prims), order_(order), o_(o) {
    parallel_depth_ = 0;
    while ((1 << parallel_depth_) < threads) ++parallel_depth_;
  }

  std::unique_ptr<Node> build(std::uint32_t begin, std::uint32_t end, int depth) {
    auto node = std::make_unique<Node>();
    Aabb cbox;
    for (std::uint32_t i = begin; i < end; ++i) {
      node->box.grow(prims_[order_[i]].box);
      cbox.grow(prims_[order_[i]].centroid);
    }
    const std::uint32_t n = end - begin;
    node->begin = begin;
    node->count = n;
    // The traversal stack grows with the depth: past kSahDepth, leaves are accepted up to
    // the size a node can encode and larger ones halved (median split below).
    const bool deep = depth + 1 >= kSahDepth;
    if (n == 1 || (deep && n <= shaders::kPtBvhMaxLeaf)) return node;
    if (depth + 1 >= int(shaders::kPtBvhMaxDepth)) throw std::logic_error("build_bvh: depth bound exceeded");

    const Split s = deep ? Split{} : best_split(begin, end, node->box, cbox);
    std::uint32_t mid = begin;
    if (s.axis >= 0) {
      if (s.cost >= float(n) && n <= std::uint32_t(o_.max_leaf)) return node;
      const float lo = cbox.lo[s.axis], scale = float(o_.bins) / (cbox.hi[s.axis] - cbox.lo[s.axis]);
      mid = std::uint32_t(std::partition(order_.begin() + begin, order_.begin() + end,
                                         [&](std::uint32_t p) { return bin(prims_[p].centroid[s.axis], lo, scale) < s.bin; }) -
                          order_.begin());
    } else if (n <= std::uint32_t(o_.max_leaf)) {
      return node;
    }
    if (mid == begin || mid == end) {
      // Coincident centroids (or rounding at a bin edge): split at the median instead.
      int axis = 0;
      const glm::vec3 ext = cbox.hi - cbox.lo;
      if (ext.y > ext[axis]) axis = 1;
      if (ext.z > ext[axis]) axis = 2;
      mid = begin + n / 2;
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) { return prims_[a].centroid[axis] < prims_[b].centroid[axis]; });
    }
    node->count = 0;
    if (depth < parallel_depth_ && n > 4096) {
      auto left = std::async(std::launch::async, [&, begin, mid, depth] { return build(begin, mid, depth + 1); });
      node->right = build(mid, end, depth + 1);
      node->left = left.get();
    } else {
      node->left = build(begin, mid, depth + 1);
      node->right = build(mid, end, depth + 1);
    }
    return node;
  }

 private:
  struct Split {
    int axis = -1;
    int bin = 0;  // primitives in bins [0, bin) go left
    float cost = std::numeric_limits<float>::max();
  };

  int bin(float c, float lo, float scale) const {
    return std::clamp(int((c - lo) * scale), 0, o_.bins - 1);
  }

  // Binned SAH (Wald 2007): cost = C_t + (N_l·A_l + N_r·A_r) / A, in triangle-test units.
  Split best_split(std::uint32_t begin, std::uint32_t end, const Aabb& box, const Aabb& cbox) const {
    Split best;
    const float inv_area = 1.0f / std::max(box.area(), std::numeric_limits<float>::min());
    const int B = o_.bins;
    for (int axis = 0; axis < 3; ++axis) {
      const float ext = cbox.hi[axis] - cbox.lo[axis];
      if (!(ext > 0.0f)) continue;
      const float lo = cbox.lo[axis], scale = float(B) / ext;
      if (!std::isfinite(scale)) continue;
      std::vector<Aabb> boxes(B);
      std::vector<std::uint32_t> counts(B, 0);
      for (std::uint32_t i = begin; i < end; ++i) {
        const Prim& p = prims_[order_[i]];
        const int b = bin(p.centroid[axis], lo, scale);
        boxes[b].grow(p.box);
        ++counts[b];
      }
      std::vector<float> right_area(B, 0.0f);
      std::vector<std::uint32_t> right_count(B, 0);
      Aabb acc;
      std::uint32_t cnt = 0;
      for (int b = B - 1; b > 0; --b) {
        acc.grow(boxes[b]);
        cnt += counts[b];
        right_area[b] = acc.area();
        right_count[b] = cnt;
      }
      acc = Aabb();
      cnt = 0;
      for (int b = 1; b < B; ++b) {
        acc.grow(boxes[b - 1]);
        cnt += counts[b - 1];
        if (cnt == 0 || right_count[b] == 0) continue;
        const float cost = o_.traversal_cost + (float(cnt) * acc.area() + float(right_count[b]) * right_area[b]) * inv_area;
        if (cost < best.cost) best = {axis, b, cost};
      }
    }
    return best;
  }

  std::vector<Prim>& prims_;
  std::vector<std::uint32_t>& order_;
  const BvhOptions& o_;
  int parallel_depth_ = 0;
};

// Quantises the slot boxes to the node's grid, rounding outwards and checking the planes
// as the shader decodes them (origin + q·2^e, exact product, one rounding). Boxes first
// grow by a relative margin so that rounding in the slab test can never cull a triangle
// the watertight triangle test would hit.
void encode_boxes(shaders::PtBvhNode& n, const std::vector<Aabb>& slots) {
  Aabb all;
  std::vector<Aabb> padded(slots.size());
  for (std::size_t k = 0; k < slots.size(); ++k) {
    for (int i = 0; i < 3; ++i) {
      const float pad = std::max(std::max(std::abs(slots[k].lo[i]), std::abs(slots[k].hi[i])) * 1e-6f, 1e-12f);
      padded[k].lo[i] = slots[k].lo[i] - pad;
      padded[k].hi[i] = slots[k].hi[i] + pad;
    }
    all.grow(padded[k]);
  }
  float* origin[3] = {&n.origin_x, &n.origin_y, &n.origin_z};
  std::uint32_t* lo[3] = {&n.lo_x, &n.lo_y, &n.lo_z};
  std::uint32_t* hi[3] = {&n.hi_x, &n.hi_y, &n.hi_z};
  for (int i = 0; i < 3; ++i) {
    const float o = all.lo[i];
    // Grid step 2^e: 253 steps span the union (2 spare for rounding), and a step is at
    // least 2 ulps of the coordinates so that the grid planes are distinct floats.
    int e = 0;
    std::frexp(std::max((all.hi[i] - o) / 253.0f, 2.0f * std::max(std::abs(o), std::abs(all.hi[i])) *
                                                        std::numeric_limits<float>::epsilon()), &e);
    e = std::clamp(e, -126, 127);
    const float step = std::ldexp(1.0f, e);
    *origin[i] = o;
    n.exponents |= std::uint32_t(std::uint8_t(std::int8_t(e))) << (8 * i);
    const auto plane = [&](int q) { return o + float(q) * step; };
    for (std::size_t k = 0; k < slots.size(); ++k) {
      int ql = std::clamp(int(std::floor((padded[k].lo[i] - o) / step)), 0, 255);
      int qh = std::clamp(int(std::ceil((padded[k].hi[i] - o) / step)), 0, 255);
      while (ql > 0 && plane(ql) > padded[k].lo[i]) --ql;
      while (qh < 255 && plane(qh) < padded[k].hi[i]) ++qh;
      if (plane(ql) > padded[k].lo[i] || plane(qh) < padded[k].hi[i])
        throw std::logic_error("build_bvh: box quantisation failed");
      *lo[i] |= std::uint32_t(ql) << (8 * k);
      *hi[i] |= std::uint32_t(qh) << (8 * k);
    }
  }
}

double sah_cost(const Node& t, float root_inv_area) {
  if (!t.left) return double(t.count) * t.box.area() * root_inv_area;
  return double(t.box.area()) * root_inv_area + sah_cost(*t.left, root_inv_area) + sah_cost(*t.right, root_inv_area);
}

// Collapses the binary subtree under `t` into the 4-wide node `index` (children of the
// largest inner slot are pulled up until four slots are filled) and recurses.
void flatten(const Node& t, std::size_t index, int depth, Bvh& out) {
  out.depth = std::max(out.depth, depth);
  std::vector<const Node*> slots;
  if (t.left) slots = {t.left.get(), t.right.get()};
  else slots = {&t};  // a single-leaf tree
  while (slots.size() < 4) {
    int widest = -1;
    for (int k = 0; k < int(slots.size()); ++k)
      if (slots[k]->left && (widest < 0 || slots[k]->box.area() > slots[widest]->box.area())) widest = k;
    if (widest < 0) break;
    const Node* w = slots[widest];
    slots[widest] = w->left.get();
    slots.push_back(w->right.get());
  }
  shaders::PtBvhNode n{};
  std::vector<std::pair<const Node*, std::size_t>> inner;
  std::vector<Aabb> boxes;
  for (int k = 0; k < 4; ++k) {
    if (k >= int(slots.size())) {
      n.child[k] = shaders::kPtNoHit;
      continue;
    }
    boxes.push_back(slots[k]->box);
    if (slots[k]->left) {
      n.child[k] = std::uint32_t(out.nodes.size() + inner.size());
      inner.emplace_back(slots[k], n.child[k]);
    } else {
      n.child[k] = slots[k]->begin;
      n.counts |= slots[k]->count << (8 * k);
    }
  }
  encode_boxes(n, boxes);
  out.nodes[index] = n;
  out.nodes.resize(out.nodes.size() + inner.size());
  for (const auto& [child, at] : inner) flatten(*child, at, depth + 1, out);
}

}  // namespace

Bvh build_bvh(std::span<const glm::vec3> positions, const BvhOptions& options) {
  if (positions.empty() || positions.size() % 3 != 0)
    throw std::invalid_argument("build_bvh: need a non-empty list of triangles (3 vertices each)");
  if (options.bins < 2 || options.max_leaf < 1)
    throw std::invalid_argument("build_bvh: bins >= 2 and max_leaf >= 1 required");
  const std::size_t n = positions.size() / 3;
  if (n >= std::size_t(std::numeric_limits<std::uint32_t>::max()))
    throw std::invalid_argument("build_bvh: too many triangles");
  std::vector<Prim> prims(n);
  for (std::size_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) prims[t].box.grow(positions[3 * t + k]);
    prims[t].centroid = (positions[3 * t] + positions[3 * t + 1] + positions[3 * t + 2]) / 3.0f;
  }
  Bvh out;
  out.order.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.order[i] = std::uint32_t(i);
  const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  Builder b(prims, out.order, options, threads);
  const auto root = b.build(0, std::uint32_t(n), 0);
  out.nodes.reserve(n / 2 + 1);
  out.nodes.resize(1);
  flatten(*root, 0, 1, out);
  const float ra = root->box.area();
  out.sah_cost = sah_cost(*root, ra > 0 ? 1.0f / ra : 0.0f);
  return out;
}

}  // namespace fovea::renderer
