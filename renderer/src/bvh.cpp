#include "fovea/renderer/bvh.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

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

// A sample ray with its segment [tmin, tmax] (tmax: its closest hit in the SAH tree).
struct Ray {
  glm::vec3 org, dir, inv;
  float tmin = 0, tmax = std::numeric_limits<float>::max();
};

bool overlaps(const Aabb& b, const Ray& r) {
  if (b.empty()) return false;
  const glm::vec3 t0 = (b.lo - r.org) * r.inv, t1 = (b.hi - r.org) * r.inv;
  const glm::vec3 near = glm::min(t0, t1), far = glm::max(t0, t1);
  return std::max({near.x, near.y, near.z, r.tmin}) <= std::min({far.x, far.y, far.z, r.tmax});
}

// Weight, in rays, of the surface-area estimate in a child's hit probability: nodes that
// few sample rays reach fall back to the SAH (Bittner & Havran 2009 switch to it below a
// ray count; a blend avoids the jump).
constexpr float kRayPrior = 16.0f;

struct Node {
  Aabb box;
  std::uint32_t begin = 0, count = 0;
  std::unique_ptr<Node> left, right;
};

class Builder {
 public:
  // rays: the sample rays whose distribution replaces surface areas (empty: plain SAH).
  Builder(std::vector<Prim>& prims, std::vector<std::uint32_t>& order, const BvhOptions& o, int threads,
          const std::vector<Ray>& rays)
      : prims_(prims), order_(order), o_(o), rays_(rays), eye_(o.eye.value_or(glm::vec3(0.0f))) {
    parallel_depth_ = 0;
    while ((1 << parallel_depth_) < threads) ++parallel_depth_;
  }

  // parent_rays: the sample rays that reach the parent node.
  std::unique_ptr<Node> build(std::uint32_t begin, std::uint32_t end, int depth,
                              const std::vector<std::uint32_t>& parent_rays) {
    auto node = std::make_unique<Node>();
    Aabb cbox;
    for (std::uint32_t i = begin; i < end; ++i) {
      node->box.grow(prims_[order_[i]].box);
      cbox.grow(prims_[order_[i]].centroid);
    }
    std::vector<std::uint32_t> rays;
    for (const std::uint32_t r : parent_rays)
      if (overlaps(node->box, rays_[r])) rays.push_back(r);
    const std::uint32_t n = end - begin;
    node->begin = begin;
    node->count = n;
    // The traversal stack grows with the depth: past kSahDepth, leaves are accepted up to
    // the size a node can encode and larger ones halved (median split below).
    const bool deep = depth + 1 >= kSahDepth;
    if (n == 1 || (deep && n <= shaders::kPtBvhMaxLeaf)) return node;
    if (depth + 1 >= int(shaders::kPtBvhMaxDepth)) throw std::logic_error("build_bvh: depth bound exceeded");

    const Split s = deep ? Split{} : best_split(begin, end, node->box, cbox, rays);
    std::uint32_t mid = begin;
    if (s.axis >= 0 || s.cone >= 0) {
      if (s.cost >= float(n) && n <= std::uint32_t(o_.max_leaf)) return node;
      const float lo = s.axis >= 0 ? cbox.lo[s.axis] : 0.0f;
      const float scale = s.axis >= 0 ? float(o_.bins) / (cbox.hi[s.axis] - cbox.lo[s.axis]) : 0.0f;
      mid = std::uint32_t(std::partition(order_.begin() + begin, order_.begin() + end,
                                         [&](std::uint32_t p) {
                                           return s.axis >= 0 ? bin(prims_[p].centroid[s.axis], lo, scale) < s.bin
                                                              : cone(prims_[p]) == s.cone;
                                         }) -
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
      auto left = std::async(std::launch::async, [&, begin, mid, depth] { return build(begin, mid, depth + 1, rays); });
      node->right = build(mid, end, depth + 1, rays);
      node->left = left.get();
    } else {
      node->left = build(begin, mid, depth + 1, rays);
      node->right = build(mid, end, depth + 1, rays);
    }
    return node;
  }

 private:
  struct Split {
    int axis = -1;
    int bin = 0;    // primitives in bins [0, bin) go left
    int cone = -1;  // or: the primitives in this cone() go left
    float cost = std::numeric_limits<float>::max();
  };

  // Which of the six cones around the eye (2·axis + 1 if negative, by the dominant
  // component of centroid − eye) holds the primitive's centroid: a cube map around the eye.
  int cone(const Prim& p) const {
    const glm::vec3 d = p.centroid - eye_, a = glm::abs(d);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    return 2 * axis + (d[axis] < 0.0f);
  }

  // A child's probability of a visit: the SAH's area ratio, or with sample rays, the
  // fraction `hits` of the node's `rays` reaching the child box, blended with the area
  // ratio (kRayPrior).
  static float probability(std::size_t hits, float area_ratio, std::size_t rays) {
    if (rays == 0) return area_ratio;
    return (float(hits) + kRayPrior * area_ratio) / (float(rays) + kRayPrior);
  }

  int bin(float c, float lo, float scale) const {
    return std::clamp(int((c - lo) * scale), 0, o_.bins - 1);
  }

  // Binned SAH (Wald 2007): cost = C_t + N_l·P_l + N_r·P_r in triangle-test units, P the
  // probability that a ray reaching the node reaches the child. The SAH's P = A_child / A
  // assumes rays from outside the node; rays from inside it (an eye inside a closed room,
  // every secondary ray) visit every box around their origin, which the SAH does not see:
  // its halving splits of an enclosure make boxes that all contain the eye. The ray
  // distribution heuristic (Bittner & Havran 2009, "RDH: ray distribution heuristics for
  // construction of spatial data structures") counts instead the sample rays whose
  // segments reach each child box: P = (hits + k·A_child/A) / (rays + k), k = kRayPrior.
  Split best_split(std::uint32_t begin, std::uint32_t end, const Aabb& box, const Aabb& cbox,
                   const std::vector<std::uint32_t>& rays) const {
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
      // left[b], right[b]: the boxes of bins [0, b) and [b, B).
      std::vector<Aabb> left(B), right(B);
      std::vector<std::uint32_t> right_count(B, 0);
      for (int b = B - 1; b > 0; --b) {
        right[b] = b + 1 < B ? right[b + 1] : Aabb();
        right[b].grow(boxes[b]);
        right_count[b] = (b + 1 < B ? right_count[b + 1] : 0) + counts[b];
      }
      for (int b = 1; b < B; ++b) {
        left[b] = left[b - 1];
        left[b].grow(boxes[b - 1]);
      }
      // Sample rays reaching each candidate child. left[b] grows with b and right[b]
      // shrinks, so a ray reaching one reaches every larger one: one binary search per ray
      // for the first left box and the last right box it reaches.
      std::vector<std::uint32_t> left_hits(B, 0), right_hits(B, 0);
      for (const std::uint32_t r : rays) {
        int lo = 1, hi = B;  // the first b in [1, B) with left[b] reached, B for none
        while (lo < hi) {
          const int mid = (lo + hi) / 2;
          if (overlaps(left[mid], rays_[r])) hi = mid;
          else lo = mid + 1;
        }
        if (lo < B) ++left_hits[lo];
        lo = 0;  // the last b in [1, B) with right[b] reached, 0 for none
        hi = B - 1;
        while (lo < hi) {
          const int mid = (lo + hi + 1) / 2;
          if (overlaps(right[mid], rays_[r])) lo = mid;
          else hi = mid - 1;
        }
        ++right_hits[lo];
      }
      for (int b = 2; b < B; ++b) left_hits[b] += left_hits[b - 1];
      for (int b = B - 2; b > 0; --b) right_hits[b] += right_hits[b + 1];
      std::uint32_t cnt = 0;
      for (int b = 1; b < B; ++b) {
        cnt += counts[b - 1];
        if (cnt == 0 || right_count[b] == 0) continue;
        const float cost = o_.traversal_cost +
                           float(cnt) * probability(left_hits[b], left[b].area() * inv_area, rays.size()) +
                           float(right_count[b]) * probability(right_hits[b], right[b].area() * inv_area, rays.size());
        if (cost < best.cost) best = {axis, b, -1, cost};
      }
    }
    // With sample rays, also the cones around the eye, one against the rest. The greedy
    // cost sees no difference at the top of a closed room or sphere around the eye (halves
    // and cones both leave a big child that every eye ray visits), yet halving keeps the
    // eye in a box at every level below while after at most five cones no box contains it;
    // so a node around the eye takes its best cone whenever one splits it.
    if (!rays.empty()) {
      Split cones;
      Aabb cone_box[6];
      std::uint32_t cone_count[6] = {};
      for (std::uint32_t i = begin; i < end; ++i) {
        const Prim& p = prims_[order_[i]];
        const int c = cone(p);
        cone_box[c].grow(p.box);
        ++cone_count[c];
      }
      for (int c = 0; c < 6; ++c) {
        const Aabb& in = cone_box[c];
        Aabb out;
        for (int o = 0; o < 6; ++o)
          if (o != c) out.grow(cone_box[o]);
        const std::uint32_t n_in = cone_count[c];
        if (n_in == 0 || n_in == end - begin) continue;
        std::size_t hits_in = 0, hits_out = 0;
        for (const std::uint32_t r : rays) {
          hits_in += overlaps(in, rays_[r]);
          hits_out += overlaps(out, rays_[r]);
        }
        const float cost = o_.traversal_cost + float(n_in) * probability(hits_in, in.area() * inv_area, rays.size()) +
                           float(end - begin - n_in) * probability(hits_out, out.area() * inv_area, rays.size());
        if (cost < cones.cost) cones = {-1, 0, c, cost};
      }
      const bool eye_inside = glm::all(glm::lessThanEqual(box.lo, eye_)) && glm::all(glm::lessThanEqual(eye_, box.hi));
      if (cones.cone >= 0 && (eye_inside || cones.cost < best.cost)) best = cones;
    }
    return best;
  }

  std::vector<Prim>& prims_;
  std::vector<std::uint32_t>& order_;
  const BvhOptions& o_;
  const std::vector<Ray>& rays_;
  glm::vec3 eye_;
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

// Slot k's box of a 4-wide node, decoded as the shader does.
Aabb slot_box(const shaders::PtBvhNode& n, int k) {
  const float origin[3] = {n.origin_x, n.origin_y, n.origin_z};
  const std::uint32_t lo[3] = {n.lo_x, n.lo_y, n.lo_z}, hi[3] = {n.hi_x, n.hi_y, n.hi_z};
  Aabb b;
  for (int i = 0; i < 3; ++i) {
    const float step = std::ldexp(1.0f, int(std::int8_t(std::uint8_t(n.exponents >> (8 * i)))));
    b.lo[i] = origin[i] + float((lo[i] >> (8 * k)) & 0xFFu) * step;
    b.hi[i] = origin[i] + float((hi[i] >> (8 * k)) & 0xFFu) * step;
  }
  return b;
}

// Möller–Trumbore, both faces: shortens r.tmax to a hit in (tmin, tmax). Only to end the
// sample rays' segments and count traversal work, so no watertightness needed.
void hit_triangle(const glm::vec3* v, Ray& r) {
  const glm::vec3 e1 = v[1] - v[0], e2 = v[2] - v[0], p = glm::cross(r.dir, e2);
  const float det = glm::dot(e1, p);
  if (det == 0.0f) return;
  const glm::vec3 s = r.org - v[0], q = glm::cross(s, e1);
  const float u = glm::dot(s, p) / det, w = glm::dot(r.dir, q) / det, t = glm::dot(e2, q) / det;
  if (u >= 0.0f && w >= 0.0f && u + w <= 1.0f && t > r.tmin && t < r.tmax) r.tmax = t;
}

// Closest hit of r in the 4-wide tree, visited in pt_traverse's order (leaf slots first,
// then the inner slots nearest first, the others deferred with their entry distance):
// shortens r.tmax to the hit and returns the node visits plus triangle tests.
// `stack` and `inner` are scratch space.
using Entries = std::vector<std::pair<float, std::uint32_t>>;
std::uint64_t walk(const Bvh& bvh, std::span<const glm::vec3> positions, Ray& r, Entries& stack, Entries& inner) {
  stack.clear();
  std::uint64_t work = 0;
  std::uint32_t n = 0;
  while (true) {
    ++work;
    const shaders::PtBvhNode& node = bvh.nodes[n];
    inner.clear();
    for (int k = 0; k < 4; ++k) {
      if (node.child[k] == shaders::kPtNoHit) continue;
      const Aabb b = slot_box(node, k);
      if (!overlaps(b, r)) continue;
      const std::uint32_t count = (node.counts >> (8 * k)) & 0xFFu;
      for (std::uint32_t i = node.child[k]; i < node.child[k] + count; ++i, ++work)
        hit_triangle(&positions[3 * std::size_t(bvh.order[i])], r);
      if (count == 0) {
        const glm::vec3 t0 = (b.lo - r.org) * r.inv, t1 = (b.hi - r.org) * r.inv, near = glm::min(t0, t1);
        inner.emplace_back(std::max({near.x, near.y, near.z, r.tmin}), node.child[k]);
      }
    }
    std::sort(inner.begin(), inner.end());
    while (!inner.empty() && inner.back().first > r.tmax) inner.pop_back();
    for (std::size_t k = inner.size(); k > 1; --k) stack.push_back(inner[k - 1]);
    if (!inner.empty()) {
      n = inner.front().second;
      continue;
    }
    bool next = false;
    while (!stack.empty() && !next) {
      n = stack.back().second;
      next = stack.back().first <= r.tmax;
      stack.pop_back();
    }
    if (!next) return work;
  }
}

// Mean work per ray (walk) of `rays` in `bvh`; the rays' tmax become their hits.
double ray_cost(const Bvh& bvh, std::span<const glm::vec3> positions, std::vector<Ray>& rays) {
  std::uint64_t work = 0;
  Entries stack, inner;
  for (Ray& r : rays) work += walk(bvh, positions, r, stack, inner);
  return double(work) / double(rays.size());
}

Ray make_ray(glm::vec3 org, glm::vec3 dir, float tmin) {
  Ray r{org, dir, {}, tmin};
  // Zero components replaced as in pt_prepare, so that slabs never compute 0·∞.
  for (int i = 0; i < 3; ++i) r.inv[i] = 1.0f / (std::abs(dir[i]) > 1e-20f ? dir[i] : std::copysign(1e-20f, dir[i]));
  return r;
}

// What a path tracer shoots: half the rays from the eye in uniformly distributed
// directions (a head-mounted display looks anywhere), half from area-uniform points on
// the triangles in cosine-distributed directions on either side (bounces and shadow rays).
std::vector<Ray> sample_rays(std::span<const glm::vec3> positions, glm::vec3 eye, int count) {
  std::mt19937 rng(20091126u);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto sphere = [&] {
    const float z = 1.0f - 2.0f * u(rng), phi = 2.0f * std::numbers::pi_v<float> * u(rng), s = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return glm::vec3(s * std::cos(phi), s * std::sin(phi), z);
  };
  Aabb all;
  std::vector<double> cdf(positions.size() / 3);
  double area = 0;
  for (std::size_t t = 0; t < cdf.size(); ++t) {
    const glm::vec3* v = &positions[3 * t];
    for (int k = 0; k < 3; ++k) all.grow(v[k]);
    area += 0.5 * double(glm::length(glm::cross(v[1] - v[0], v[2] - v[0])));
    cdf[t] = area;
  }
  const float offset = 1e-5f * glm::length(all.hi - all.lo);
  std::vector<Ray> rays;
  for (int i = 0; i < count; ++i) {
    if (i % 2 == 0 || !(area > 0)) {
      rays.push_back(make_ray(eye, sphere(), 0.0f));
      continue;
    }
    const std::size_t t = std::min(std::size_t(std::upper_bound(cdf.begin(), cdf.end(), double(u(rng)) * area) - cdf.begin()),
                                   cdf.size() - 1);
    const glm::vec3* v = &positions[3 * t];
    const float a = std::sqrt(u(rng)), b = u(rng);
    const glm::vec3 p = v[0] + a * (1.0f - b) * (v[1] - v[0]) + a * b * (v[2] - v[0]);
    const glm::vec3 nrm = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0])) * (u(rng) < 0.5f ? -1.0f : 1.0f);
    // Cosine-distributed about nrm: the unit sphere shifted by the normal (normalised).
    glm::vec3 d = nrm + sphere();
    d = glm::dot(d, d) > 1e-12f ? glm::normalize(d) : nrm;
    rays.push_back(make_ray(p + offset * nrm, d, 0.0f));
  }
  return rays;
}

// The binary tree over prims (SAH, or ray-guided with `rays`), collapsed to 4-wide nodes.
Bvh make_tree(std::vector<Prim>& prims, const BvhOptions& options, const std::vector<Ray>& rays) {
  const std::size_t n = prims.size();
  Bvh out;
  out.order.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.order[i] = std::uint32_t(i);
  const int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  Builder b(prims, out.order, options, threads, rays);
  std::vector<std::uint32_t> all(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) all[i] = std::uint32_t(i);
  const auto root = b.build(0, std::uint32_t(n), 0, all);
  out.nodes.reserve(n / 2 + 1);
  out.nodes.resize(1);
  flatten(*root, 0, 1, out);
  const float ra = root->box.area();
  out.sah_cost = sah_cost(*root, ra > 0 ? 1.0f / ra : 0.0f);
  return out;
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
  Bvh sah = make_tree(prims, options, {});
  if (!options.eye || options.ray_samples <= 0) return sah;
  // The sample rays' segments end at their closest hits (found in the SAH tree), so boxes
  // behind a hit do not count as visited.
  const std::vector<Ray> unclipped = sample_rays(positions, *options.eye, options.ray_samples);
  std::vector<Ray> rays = unclipped;
  sah.ray_cost = sah.sah_ray_cost = ray_cost(sah, positions, rays);
  Bvh guided = make_tree(prims, options, rays);
  std::vector<Ray> again = unclipped;
  guided.ray_cost = ray_cost(guided, positions, again);
  guided.sah_ray_cost = sah.sah_ray_cost;
  guided.ray_guided = true;
  return guided.ray_cost < sah.ray_cost ? guided : sah;
}

}  // namespace fovea::renderer
