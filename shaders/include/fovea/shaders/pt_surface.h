// GLSL only: the first hit's surface (position, normals, material, textured base colour)
// for the tracers of display pixels and grid cells (pt_trace.comp, pt_primary.comp). The
// including shader declares first the texel buffers `shading` (PtShading, 4 texels each),
// `materials` (PtMaterial, 3 texels each) and `texels` (RGBA8), the storage buffer
// `tex_table` (PtTextureInfo) and the specialization constant `kTextures`, and includes
// pt_scene.h and pt_traverse.h (pt_tri, PtHit).
#ifndef FOVEA_SHADERS_PT_SURFACE_H
#define FOVEA_SHADERS_PT_SURFACE_H

PtShading pt_shading(uint i) {
  const int k = int(4u * i);
  const vec4 a = texelFetch(shading, k), b = texelFetch(shading, k + 1), c = texelFetch(shading, k + 2),
             d = texelFetch(shading, k + 3);
  return PtShading(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, c.y, c.z, c.w, d.x, d.y, d.z, d.w);
}

PtMaterial pt_material(uint i) {
  const int k = int(3u * i);
  const vec4 a = texelFetch(materials, k), b = texelFetch(materials, k + 1), c = texelFetch(materials, k + 2);
  return PtMaterial(a.x, a.y, a.z, floatBitsToInt(a.w), b.x, b.y, b.z, b.w, c.x, c.y, floatBitsToUint(c.z), c.w);
}

vec3 srgb_to_linear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// Texel (x, y), repeating, of the level of `size` texels at `offset`.
vec3 texel(uint offset, ivec2 size, int x, int y) {
  x = (x % size.x + size.x) % size.x;
  y = (y % size.y + size.y) % size.y;
  return srgb_to_linear(unpackUnorm4x8(texelFetch(texels, int(offset + uint(y * size.x + x))).x).rgb);
}

// Bilinear, repeating, on linear values.
vec3 bilinear(uint offset, ivec2 size, vec2 uv) {
  const vec2 p = fract(uv) * vec2(size) - 0.5;
  const vec2 f = fract(p);
  const ivec2 a = ivec2(floor(p)), b = a + 1;
  return mix(mix(texel(offset, size, a.x, a.y), texel(offset, size, b.x, a.y), f.x),
             mix(texel(offset, size, a.x, b.y), texel(offset, size, b.x, b.y), f.x), f.y);
}

// Trilinear over the texture's mip chain (GpuScene: level l of max(w >> l, 1) × max(h >> l, 1)
// texels after level l − 1) at level of detail `lod` (0: the full texture).
vec3 sample_texture(int index, vec2 uv, float lod) {
  const PtTextureInfo t = tex_table[index];
  lod = clamp(lod, 0.0, float(max(t.levels, 1u) - 1u));
  const int l0 = int(lod);
  const float f = lod - float(l0);
  uint offset = t.offset;
  ivec2 size = ivec2(t.width, t.height);
  for (int l = 0; l < l0; ++l) {
    offset += uint(size.x * size.y);
    size = max(size / 2, ivec2(1));
  }
  vec3 c = bilinear(offset, size, uv);
  if (f > 0.0) c = mix(c, bilinear(offset + uint(size.x * size.y), max(size / 2, ivec2(1)), uv), f);
  return c;
}

// Texture level of detail of a ray cone `width` wide (world units) where it meets a triangle
// (Akenine-Möller et al. 2019, "Texture Level of Detail Strategies for Real-Time Ray Tracing",
// Ray Tracing Gems ch. 20, Eq. 34): Δ0 = ½·log2(texel area / world area of the triangle) plus
// log2(width), with the footprint's stretch 1/|cos θ| taken as its area's square root
// (−½·log2|cos θ|): the full stretch blurred a grazing floor's bricks across as well (fovea
// SSIM at 16 ppd, bricks met at 8°: Cartesian 0.80 against 0.97, visual-polar 0.61 against
// 0.78; tests/pipeline/grazing_texture_test.cpp, docs/reconstruction.md).
float cone_lod(PtTextureInfo t, vec3 e1, vec3 e2, vec2 duv1, vec2 duv2, float width, float cos_theta) {
  const float world = length(cross(e1, e2));
  const float tex = float(t.width) * float(t.height) * abs(duv1.x * duv2.y - duv2.x * duv1.y);
  if (!(width > 0.0) || !(world > 0.0) || !(tex > 0.0)) return 0.0;
  return 0.5 * log2(tex / world) + log2(width) - 0.5 * log2(max(cos_theta, 1e-4));
}

// The cone angle (radians) of a primary ray in view direction `dir` (unit, view space) whose
// samples are `step` apart on the z = -1 tangent plane: the step times cos^1.5 of the angle off
// the axis (a tangent-plane step dt spans dt·cos² radially and dt·cos across; their geometric mean).
float pt_cone_spread(float step, vec3 dir) {
  const float off_axis = dir.z < 0.0 ? -dir.z : 0.0;
  return step * off_axis * sqrt(off_axis);
}

struct Surface {
  vec3 p, ng, ns;  // position, geometric and shading normals, both facing the incoming ray
  bool front;      // the ray hit the front (counter-clockwise) side
  bool lit;        // front face, or a back face of a double-sided material
  uint material;
  vec3 base;
  vec3 emission;
  float light_pdf;  // P(select) / area of this triangle as a light
};

// `cone`: the ray cone's width at the hit (world units; 0: the texture's full resolution).
Surface surface(PtHit h, vec3 org, vec3 dir, float cone) {
  Surface s;
  const PtTriangle t = pt_tri(h.tri);
  const PtShading sh = pt_shading(h.tri);
  const vec3 v0 = vec3(t.v0_x, t.v0_y, t.v0_z), v1 = vec3(t.v1_x, t.v1_y, t.v1_z), v2 = vec3(t.v2_x, t.v2_y, t.v2_z);
  const float w0 = 1.0 - h.bary.x - h.bary.y;
  s.p = w0 * v0 + h.bary.x * v1 + h.bary.y * v2;
  vec3 ng = normalize(cross(v1 - v0, v2 - v0));
  s.front = dot(ng, dir) < 0.0;
  vec3 ns = w0 * vec3(sh.n0_x, sh.n0_y, sh.n0_z) + h.bary.x * vec3(sh.n1_x, sh.n1_y, sh.n1_z) +
            h.bary.y * vec3(sh.n2_x, sh.n2_y, sh.n2_z);
  ns = dot(ns, ns) > 0.0 ? normalize(ns) : ng;
  // Both normals on the viewer's side: glTF lights the back faces of double-sided materials
  // with the normal reversed (glTF 2.0 §3.9.5); single-sided back faces stay black.
  if (!s.front) ng = -ng;
  if (dot(ns, ng) < 0.0) ns = -ns;
  s.ng = ng;
  s.ns = ns;
  s.material = t.material;
  const PtMaterial m = pt_material(t.material);
  s.lit = s.front || m.double_sided != 0u;
  s.base = s.lit ? vec3(m.base_r, m.base_g, m.base_b) : vec3(0.0);
  if (kTextures && m.texture >= 0 && s.lit) {
    const vec2 uv0 = vec2(sh.uv0_x, sh.uv0_y), uv1 = vec2(sh.uv1_x, sh.uv1_y), uv2 = vec2(sh.uv2_x, sh.uv2_y);
    const vec2 uv = w0 * uv0 + h.bary.x * uv1 + h.bary.y * uv2;
    const float lod = cone_lod(tex_table[m.texture], v1 - v0, v2 - v0, uv1 - uv0, uv2 - uv0, cone, abs(dot(ng, dir)));
    s.base *= sample_texture(m.texture, uv, lod);
  }
  s.emission = s.lit ? vec3(m.emit_r, m.emit_g, m.emit_b) : vec3(0.0);
  s.light_pdf = t.light_pdf;
  return s;
}

#endif
