// GLSL only: BVH traversal and the watertight ray-triangle test. The including shader
// declares the texel buffers `utextureBuffer nodes` (PtBvhNode, 4 texels per node) and
// `utextureBuffer tris` (PtTriangle, 3 per triangle) first; pt_node() and pt_tri() decode them.
#ifndef FOVEA_SHADERS_PT_TRAVERSE_H
#define FOVEA_SHADERS_PT_TRAVERSE_H


layout(constant_id = kPtSpecBvhStack) const uint kPtStackSize = kPtBvhStackSize;
layout(constant_id = kPtSpecSharedBytes) const uint kPtSharedBytes = 0u;

// The traversal stack, entries (node, floatBitsToUint(entry distance)): in shared memory
// when the workgroup's stacks fit, else a private array. On lavapipe a private array
// indexed by a per-invocation value is memory traffic anyway, and the shared one made
// primary rays 9-27% faster on the shipped scenes (docs/renderer.md, fifth round). Shared
// memory is entry-major (entry k of invocation i at k · group size + i), so invocations at
// the same depth touch neighbouring words. The including shaders declare no shared memory
// of their own; one that did would have to lower kPtSharedBytes by it.
const uint kPtGroupInvocations = gl_WorkGroupSize.x * gl_WorkGroupSize.y * gl_WorkGroupSize.z;
const bool kPtStackShared = kPtStackSize * kPtGroupInvocations * 8u <= kPtSharedBytes;
shared uvec2 pt_stack_shared[kPtStackShared ? kPtStackSize * kPtGroupInvocations : 1u];
uvec2 pt_stack_private[kPtStackShared ? 1u : kPtStackSize];

void pt_stack_store(uint sp, uvec2 e) {
  if (kPtStackShared) pt_stack_shared[sp * kPtGroupInvocations + gl_LocalInvocationIndex] = e;
  else pt_stack_private[sp] = e;
}

uvec2 pt_stack_load(uint sp) {
  if (kPtStackShared) return pt_stack_shared[sp * kPtGroupInvocations + gl_LocalInvocationIndex];
  return pt_stack_private[sp];
}

const float kPtInf = 1e30;

// Built with FOVEA_TRAVERSE_STATS (pt_raycast.stats.comp.spv): node visits and triangle
// tests of the current ray, for the benchmark's traversal statistics.
#ifdef FOVEA_TRAVERSE_STATS
uint pt_stat_nodes = 0u, pt_stat_tris = 0u;
#define PT_STAT(counter) ++counter
#else
#define PT_STAT(counter)
#endif

// Ize 2013, "Robust BVH ray traversal": scaling the far slab distance by 1 + 2γ(3)
// keeps rounding in the box test from culling hits.
const float kPtBoxFarScale = 1.0 + 2.0 * (3.0 * 5.9604645e-8) / (1.0 - 3.0 * 5.9604645e-8);

// Nodes and triangles are read as whole uvec4 texels: lavapipe loads a storage buffer's
// struct member by member, each load a loop over the SIMD lanes with a bounds test per
// component when the address differs per invocation; a texel fetch is one vector gather.
// Four vec4 storage loads per node instead of sixteen scalar ones made traversal ~15%
// faster, texel fetches instead of those took primary rays to 0.70-0.76x the time
// (docs/renderer.md, "Sixth round").
PtBvhNode pt_node(uint n) {
  const int i = int(4u * n);
  const uvec4 a = texelFetch(nodes, i), b = texelFetch(nodes, i + 1), c = texelFetch(nodes, i + 2), d = texelFetch(nodes, i + 3);
  PtBvhNode r;
  r.origin_x = uintBitsToFloat(a.x);
  r.origin_y = uintBitsToFloat(a.y);
  r.origin_z = uintBitsToFloat(a.z);
  r.exponents = a.w;
  r.lo_x = b.x; r.lo_y = b.y; r.lo_z = b.z;
  r.hi_x = b.w; r.hi_y = c.x; r.hi_z = c.y;
  r.child[0] = c.z; r.child[1] = c.w; r.child[2] = d.x; r.child[3] = d.y;
  r.counts = d.z;
  r.pad = d.w;
  return r;
}

PtTriangle pt_tri(uint i) {
  const int k = int(3u * i);
  const uvec4 a = texelFetch(tris, k), b = texelFetch(tris, k + 1), c = texelFetch(tris, k + 2);
  PtTriangle t;
  t.v0_x = uintBitsToFloat(a.x); t.v0_y = uintBitsToFloat(a.y); t.v0_z = uintBitsToFloat(a.z);
  t.material = a.w;
  t.v1_x = uintBitsToFloat(b.x); t.v1_y = uintBitsToFloat(b.y); t.v1_z = uintBitsToFloat(b.z);
  t.source = b.w;
  t.v2_x = uintBitsToFloat(c.x); t.v2_y = uintBitsToFloat(c.y); t.v2_z = uintBitsToFloat(c.z);
  t.light_pdf = uintBitsToFloat(c.w);
  return t;
}

struct PtRayPre {
  vec3 org;
  float tmin;
  vec3 inv;  // 1 / dir with zero components replaced by ±1e-20 (no 0·∞ in slabs)
  bvec3 neg;  // inv < 0: the slab is entered at the box's upper plane
  int kx, ky, kz;
  vec3 shear;  // Woop et al. 2013 (JCGT 2(1)) shear constants Sx, Sy, Sz
};

struct PtHit {
  float t;
  uint tri;   // triangle index (texels 3·tri … 3·tri + 2 of tris)
  vec2 bary;  // weights of vertices 1 and 2
};

// v[k] by selects: lavapipe lowers a vector indexed by a per-invocation value to memory
// traffic (docs/reconstruction.md), which made this test ~20× slower than its arithmetic.
float pt_axis(vec3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

PtRayPre pt_prepare(vec3 org, vec3 dir, float tmin) {
  PtRayPre r;
  r.org = org;
  r.tmin = tmin;
  const vec3 a = abs(dir);
  r.kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  const float dz = pt_axis(dir, r.kz);
  if (dz < 0.0) {  // keep the winding, so the sign of U, V, W stays meaningful
    const int k = r.kx;
    r.kx = r.ky;
    r.ky = k;
  }
  r.shear = vec3(pt_axis(dir, r.kx) / dz, pt_axis(dir, r.ky) / dz, 1.0 / dz);
  for (int i = 0; i < 3; ++i) r.inv[i] = 1.0 / (a[i] > 1e-20 ? dir[i] : (dir[i] < 0.0 ? -1e-20 : 1e-20));
  r.neg = lessThan(r.inv, vec3(0.0));
  return r;
}

// Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, Fig. 4), both faces.
bool pt_hit_triangle(PtRayPre r, uint i, float tmax, inout PtHit hit) {
  PT_STAT(pt_stat_tris);
  const PtTriangle tri = pt_tri(i);
  const vec3 A = vec3(tri.v0_x, tri.v0_y, tri.v0_z) - r.org;
  const vec3 B = vec3(tri.v1_x, tri.v1_y, tri.v1_z) - r.org;
  const vec3 C = vec3(tri.v2_x, tri.v2_y, tri.v2_z) - r.org;
  const float Az = pt_axis(A, r.kz), Bz = pt_axis(B, r.kz), Cz = pt_axis(C, r.kz);
  const float Ax = pt_axis(A, r.kx) - r.shear.x * Az, Ay = pt_axis(A, r.ky) - r.shear.y * Az;
  const float Bx = pt_axis(B, r.kx) - r.shear.x * Bz, By = pt_axis(B, r.ky) - r.shear.y * Bz;
  const float Cx = pt_axis(C, r.kx) - r.shear.x * Cz, Cy = pt_axis(C, r.ky) - r.shear.y * Cz;
  const float U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  const float det = U + V + W;
  if (det == 0.0) return false;
  const float T = U * (r.shear.z * Az) + V * (r.shear.z * Bz) + W * (r.shear.z * Cz);
  const float sd = det < 0.0 ? -1.0 : 1.0;
  if (T * sd <= r.tmin * det * sd) return false;
  // Compared as the distance it reports, and equal distances resolved to the lower index,
  // so the closest hit does not depend on the order in which triangles are tested
  // (T < tmax·det rounds differently from triangle to triangle).
  const float rcp = 1.0 / det;
  const float t = T * rcp;
  if (!(t < tmax || (t == tmax && i < hit.tri && hit.tri != kPtNoHit))) return false;
  hit.t = t;
  hit.tri = i;
  hit.bary = vec2(V, W) * rcp;
  return true;
}

// The four slots' planes origin + q·2^e of one axis (bytes of `q`); the product is exact,
// so these are the floats the builder checked against the boxes.
vec4 pt_planes(float origin, float step, uint q) {
  return origin + vec4((uvec4(q) >> uvec4(0u, 8u, 16u, 24u)) & 0xFFu) * step;
}

// Tests the triangles [first, first + count) (a leaf); true on a hit when any_hit.
bool pt_hit_leaf(PtRayPre r, uint first, uint count, bool any_hit, inout PtHit hit) {
  for (uint i = first; i < first + count; ++i)
    if (pt_hit_triangle(r, i, hit.t, hit) && any_hit) return true;
  return false;
}

// Compare-exchange of two (entry distance, node) pairs, nearer first.
void pt_order(inout float ta, inout uint na, inout float tb, inout uint nb) {
  if (tb < ta) {
    const float t = ta; ta = tb; tb = t;
    const uint n = na; na = nb; nb = n;
  }
}

// Stack-based traversal of the 4-wide tree. Each step fetches one node and tests its four
// boxes at once; leaf children are intersected right away (their hits shorten the ray
// before the inner children are culled), inner children are visited nearest first and the
// others deferred with their entry distance, so a pop needs no refetch to be culled.
// any_hit: stop at the first hit (shadow rays).
bool pt_traverse(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out PtHit hit) {
  hit.t = tmax;
  hit.tri = kPtNoHit;
  hit.bary = vec2(0.0);
  const PtRayPre r = pt_prepare(org, dir, tmin);
  uint sp = 0u;
  uint n = 0u;
  while (true) {
    const PtBvhNode b = pt_node(n);
    PT_STAT(pt_stat_nodes);
    // Step 2^e built from its bits (e is clamped to the normal range by the builder).
    const uvec3 e = (uvec3(b.exponents) >> uvec3(0u, 8u, 16u)) & 0xFFu;
    const vec3 step = uintBitsToFloat(uvec3((ivec3(e << 24u) >> 24) + 127) << 23u);
    // Near and far planes chosen by the direction's sign once per axis instead of min/max
    // of both slab distances per box: the same distances (rounding is monotonic), 12 fewer
    // vector operations per node.
    const vec4 t0x = (pt_planes(b.origin_x, step.x, r.neg.x ? b.hi_x : b.lo_x) - r.org.x) * r.inv.x;
    const vec4 t1x = (pt_planes(b.origin_x, step.x, r.neg.x ? b.lo_x : b.hi_x) - r.org.x) * r.inv.x;
    const vec4 t0y = (pt_planes(b.origin_y, step.y, r.neg.y ? b.hi_y : b.lo_y) - r.org.y) * r.inv.y;
    const vec4 t1y = (pt_planes(b.origin_y, step.y, r.neg.y ? b.lo_y : b.hi_y) - r.org.y) * r.inv.y;
    const vec4 t0z = (pt_planes(b.origin_z, step.z, r.neg.z ? b.hi_z : b.lo_z) - r.org.z) * r.inv.z;
    const vec4 t1z = (pt_planes(b.origin_z, step.z, r.neg.z ? b.lo_z : b.hi_z) - r.org.z) * r.inv.z;
    const vec4 enter = max(max(t0x, t0y), max(t0z, vec4(r.tmin)));
    const vec4 leave = min(min(t1x, t1y), min(t1z, vec4(hit.t))) * kPtBoxFarScale;
    const uvec4 child = uvec4(b.child[0], b.child[1], b.child[2], b.child[3]);
    const uvec4 count = (uvec4(b.counts) >> uvec4(0u, 8u, 16u, 24u)) & 0xFFu;
    const bvec4 overlap = bvec4(uvec4(lessThanEqual(enter, leave)) * uvec4(notEqual(child, uvec4(kPtNoHit))));
    for (int k = 0; k < 4; ++k)
      if (overlap[k] && count[k] > 0u && pt_hit_leaf(r, child[k], count[k], any_hit, hit)) return true;
    // Inner children still in front of the closest hit, sorted (5-comparator network).
    const bvec4 inner = bvec4(uvec4(overlap) * uvec4(equal(count, uvec4(0u))) *
                              uvec4(lessThanEqual(enter, vec4(hit.t * kPtBoxFarScale))));
    float ta = inner.x ? enter.x : kPtInf, tb = inner.y ? enter.y : kPtInf;
    float tc = inner.z ? enter.z : kPtInf, td = inner.w ? enter.w : kPtInf;
    uint na = child.x, nb = child.y, nc = child.z, nd = child.w;
    pt_order(ta, na, tb, nb);
    pt_order(tc, nc, td, nd);
    pt_order(ta, na, tc, nc);
    pt_order(tb, nb, td, nd);
    pt_order(tb, nb, tc, nc);
    if (td < kPtInf) pt_stack_store(sp++, uvec2(nd, floatBitsToUint(td)));
    if (tc < kPtInf) pt_stack_store(sp++, uvec2(nc, floatBitsToUint(tc)));
    if (tb < kPtInf) pt_stack_store(sp++, uvec2(nb, floatBitsToUint(tb)));
    if (ta < kPtInf) {
      n = na;
      continue;
    }
    // Pop the next subtree that still starts before the closest hit found so far.
    bool next = false;
    while (sp > 0u && !next) {
      const uvec2 e = pt_stack_load(--sp);
      n = e.x;
      next = uintBitsToFloat(e.y) <= hit.t * kPtBoxFarScale;
    }
    if (!next) break;
  }
  return hit.tri != kPtNoHit;
}

// The same queries without the BVH: the reference the BVH is tested against.
bool pt_brute_force(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out PtHit hit) {
  hit.t = tmax;
  hit.tri = kPtNoHit;
  hit.bary = vec2(0.0);
  const PtRayPre r = pt_prepare(org, dir, tmin);
  const uint count = uint(textureSize(tris)) / 3u;
  for (uint i = 0u; i < count; ++i)
    if (pt_hit_triangle(r, i, hit.t, hit) && any_hit) return true;
  return hit.tri != kPtNoHit;
}

#endif
