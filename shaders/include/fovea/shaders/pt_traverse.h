// GLSL only: BVH traversal and the watertight ray-triangle test. The including shader
// declares `PtBvhNode nodes[]` and `PtTriangle tris[]` storage buffers first.
#ifndef FOVEA_SHADERS_PT_TRAVERSE_H
#define FOVEA_SHADERS_PT_TRAVERSE_H

const float kPtInf = 1e30;
// Ize 2013, "Robust BVH ray traversal": scaling the far slab distance by 1 + 2γ(3)
// keeps rounding in the box test from culling hits.
const float kPtBoxFarScale = 1.0 + 2.0 * (3.0 * 5.9604645e-8) / (1.0 - 3.0 * 5.9604645e-8);

struct PtRayPre {
  vec3 org;
  float tmin;
  vec3 inv;  // 1 / dir with zero components replaced by ±1e-20 (no 0·∞ in slabs)
  int kx, ky, kz;
  vec3 shear;  // Woop et al. 2013 (JCGT 2(1)) shear constants Sx, Sy, Sz
};

struct PtHit {
  float t;
  uint tri;   // index into tris[]
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
  return r;
}

// Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, Fig. 4), both faces.
bool pt_hit_triangle(PtRayPre r, uint i, float tmax, inout PtHit hit) {
  const PtTriangle tri = tris[i];
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
  if (T * sd <= r.tmin * det * sd || T * sd >= tmax * det * sd) return false;
  const float rcp = 1.0 / det;
  hit.t = T * rcp;
  hit.tri = i;
  hit.bary = vec2(V, W) * rcp;
  return true;
}

// Entry distance of the ray into node n's box, or kPtInf when it misses [tmin, tmax].
float pt_box_entry(PtRayPre r, uint n, float tmax) {
  const PtBvhNode b = nodes[n];
  const vec3 t0 = (vec3(b.lo_x, b.lo_y, b.lo_z) - r.org) * r.inv;
  const vec3 t1 = (vec3(b.hi_x, b.hi_y, b.hi_z) - r.org) * r.inv;
  const vec3 tn = min(t0, t1), tf = max(t0, t1);
  const float enter = max(max(tn.x, tn.y), max(tn.z, r.tmin));
  const float leave = min(min(tf.x, tf.y), min(tf.z, tmax)) * kPtBoxFarScale;
  return enter <= leave ? enter : kPtInf;
}

// Stack-based traversal, nearer child first. any_hit: stop at the first hit (shadow rays).
bool pt_traverse(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out PtHit hit) {
  hit.t = tmax;
  hit.tri = kPtNoHit;
  hit.bary = vec2(0.0);
  const PtRayPre r = pt_prepare(org, dir, tmin);
  if (pt_box_entry(r, 0u, tmax) >= kPtInf) return false;
  uint stack[kPtBvhMaxDepth];
  uint sp = 0u;
  uint n = 0u;
  while (true) {
    const PtBvhNode node = nodes[n];
    if (node.count > 0u) {
      for (uint i = node.first; i < node.first + node.count; ++i)
        if (pt_hit_triangle(r, i, hit.t, hit) && any_hit) return true;
    } else {
      const float tl = pt_box_entry(r, node.first, hit.t), tr = pt_box_entry(r, node.first + 1u, hit.t);
      if (tl < kPtInf && tr < kPtInf) {
        n = tl <= tr ? node.first : node.first + 1u;
        stack[sp++] = tl <= tr ? node.first + 1u : node.first;
        continue;
      }
      if (tl < kPtInf || tr < kPtInf) {
        n = tl < kPtInf ? node.first : node.first + 1u;
        continue;
      }
    }
    // Pop the next subtree that still starts before the closest hit found so far.
    bool next = false;
    while (sp > 0u && !next) {
      n = stack[--sp];
      next = pt_box_entry(r, n, hit.t) < kPtInf;
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
  const uint count = uint(tris.length());
  for (uint i = 0u; i < count; ++i)
    if (pt_hit_triangle(r, i, hit.t, hit) && any_hit) return true;
  return hit.tri != kPtNoHit;
}

#endif
