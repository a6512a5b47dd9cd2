// The GLSL 3.30 core shaders of the GL renderer (pipeline/render/ALGORITHM.md sections 3 to 5).
// Pixel (x, y) of an image is texel (x, y) and fragment (x + 0.5, y + 0.5): rows are kept in
// image order in every texture and framebuffer, so nothing is flipped.
#pragma once

#include <string_view>

namespace px::render::gl {

// A triangle covering the viewport, for the per-pixel passes.
inline constexpr std::string_view kFullScreenVertexShader = R"(
const vec2 kCorners[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
void main() { gl_Position = vec4(kCorners[gl_VertexID], 0.0, 1.0); }
)";

// Section 3: the viewing weights. The pixel's ray meets the view-mesh plane at q (behind the
// camera too: the paper's backwards projection in front of the mesh); q's triangle of the
// extended mesh gives three views and barycentric weights, else the nearest outer edge does.
// Out: slot views (view index as float, -1 = none) and their weights.
inline constexpr std::string_view kViewWeightsFragmentShader = R"(
uniform mat3 dir_from_pixel;  // R^T K^-1 of the output camera
uniform vec3 centre;
uniform vec3 mesh_origin;
uniform vec3 mesh_normal;
uniform vec3 mesh_axis1;
uniform vec3 mesh_axis2;
// (x, y, view, 0): 3 per triangle, then 2 per outer edge; MESH_VECTORS is defined ahead of this text.
uniform vec4 mesh[MESH_VECTORS];
uniform int num_triangles;
uniform int num_edges;
uniform int single_view;    // the one view with weight 1 everywhere, -1: the mesh decides
uniform int hint_triangle;  // the triangle holding the frame centre's q (-1 none): tried first
uniform float weight_exponent;  // RenderOptions::viewing_weight_exponent: w^e, renormalised
layout(location = 0) out vec4 slot_views;
layout(location = 1) out vec4 slot_weights;

vec4 views_out;
vec4 weights_out;
void Add(float view, float weight) {
  for (int k = 0; k < 3; ++k) {
    if (views_out[k] == view) { weights_out[k] += weight; return; }
    if (views_out[k] < 0.0) { views_out[k] = view; weights_out[k] = weight; return; }
  }
}

// FlattenViewingWeights (view_mesh.h): w^e over the three slots, summing to 1 again.
vec4 Flatten(vec4 w) {
  if (weight_exponent == 1.0) return w;
  // sqrt for the default 0.5: exact where a driver's pow is an approximation (llvmpipe's is).
  vec3 p = weight_exponent == 0.5 ? sqrt(max(w.xyz, vec3(0.0))) : pow(max(w.xyz, vec3(1e-30)), vec3(weight_exponent));
  p *= step(vec3(1e-30), w.xyz);  // weight 0 stays 0
  float sum = p.x + p.y + p.z;
  return sum > 0.0 ? vec4(p / sum, 0.0) : w;
}

// q's barycentric weights in triangle t, or a negative x where the triangle is degenerate.
vec3 Barycentric(int t, vec2 q) {
  vec4 a = mesh[3 * t];
  vec2 v0 = mesh[3 * t + 1].xy - a.xy, v1 = mesh[3 * t + 2].xy - a.xy, v2 = q - a.xy;
  float den = v0.x * v1.y - v1.x * v0.y;
  if (abs(den) < 1e-20) return vec3(-1.0);
  float wb = (v2.x * v1.y - v1.x * v2.y) / den;
  float wc = (v0.x * v2.y - v2.x * v0.y) / den;
  return vec3(1.0 - wb - wc, wb, wc);
}
void Emit(int t, vec3 w) {
  Add(mesh[3 * t].z, max(w.x, 0.0));
  Add(mesh[3 * t + 1].z, max(w.y, 0.0));
  Add(mesh[3 * t + 2].z, max(w.z, 0.0));
  slot_views = views_out;
  slot_weights = Flatten(weights_out);
}

void main() {
  views_out = vec4(-1.0);
  weights_out = vec4(0.0);
  if (single_view >= 0) {
    slot_views = vec4(float(single_view), -1.0, -1.0, -1.0);
    slot_weights = vec4(1.0, 0.0, 0.0, 0.0);
    return;
  }
  vec3 d = dir_from_pixel * vec3(gl_FragCoord.xy - 0.5, 1.0);
  float s = dot(mesh_normal, d);
  float h = dot(mesh_normal, centre - mesh_origin);
  vec3 x = abs(s) <= 1e-9 * length(d) ? centre : centre - (h / s) * d;
  vec2 q = vec2(dot(x - mesh_origin, mesh_axis1), dot(x - mesh_origin, mesh_axis2));
  // Well inside the hint triangle, q is in no other (the triangles do not overlap and the search
  // below accepts only 1e-6 outside one): the search would find the same, most pixels skip it.
  if (hint_triangle >= 0) {
    vec3 w = Barycentric(hint_triangle, q);
    if (min(w.x, min(w.y, w.z)) > 1e-3) {
      Emit(hint_triangle, w);
      return;
    }
  }
  for (int t = 0; t < num_triangles; ++t) {
    vec3 w = Barycentric(t, q);
    if (w.x >= -1e-6 && w.y >= -1e-6 && w.z >= -1e-6) {
      Emit(t, w);
      return;
    }
  }
  float best = 1e30;
  float best_t = 0.0;
  vec4 best_a = vec4(0.0), best_b = vec4(0.0);
  for (int e = 0; e < num_edges; ++e) {
    vec4 a = mesh[3 * num_triangles + 2 * e];
    vec4 b = mesh[3 * num_triangles + 2 * e + 1];
    vec2 ab = b.xy - a.xy;
    float t = clamp(dot(q - a.xy, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
    float dist = length(q - (a.xy + t * ab));
    if (dist < best) { best = dist; best_t = t; best_a = a; best_b = b; }
  }
  Add(best_a.z, 1.0 - best_t);
  Add(best_b.z, best_t);
  slot_views = views_out;
  slot_weights = Flatten(weights_out);
}
)";

// Section 4: one view's segments as instanced rectangles, front to back. Each instance carries
// its projected corners, the homography from output pixel to source pixel and its plane's inverse
// depth in output pixels.
inline constexpr std::string_view kSegmentVertexShader = R"(
layout(location = 0) in vec4 corners01;
layout(location = 1) in vec4 corners23;
layout(location = 2) in vec3 h_row0;
layout(location = 3) in vec3 h_row1;
layout(location = 4) in vec3 h_row2;
layout(location = 5) in vec3 inv_depth_plane;
layout(location = 6) in vec2 segment_and_weight;  // segment index, texture weight (texture_stretch.h)
uniform vec2 viewport_size;
flat out vec3 h0;
flat out vec3 h1;
flat out vec3 h2;
flat out vec3 plane;
flat out int segment;
flat out float texture_weight;
void main() {
  // Strip order 0, 1, 3, 2 of the corners (x0-1, y0-1), (x0+w, y0-1), (x0+w, y0+h), (x0-1, y0+h).
  vec2 c = gl_VertexID == 0 ? corners01.xy : gl_VertexID == 1 ? corners01.zw
         : gl_VertexID == 2 ? corners23.zw : corners23.xy;
  gl_Position = vec4((c + 0.5) / viewport_size * 2.0 - 1.0, 0.0, 1.0);
  h0 = h_row0;
  h1 = h_row1;
  h2 = h_row2;
  plane = inv_depth_plane;
  segment = int(segment_and_weight.x + 0.5);
  texture_weight = segment_and_weight.y;
}
)";

// The masked bilinear sample of the segment images, composited into the pixel's slot for this
// view (the three rendering buffers): blending is (SRC_ALPHA_SATURATE, ONE) on 16-bit normalised
// targets, i.e. C += min(alpha, 1 - A) colour and A = min(A + alpha, 1), as ALGORITHM.md 4 asks.
inline constexpr std::string_view kSegmentFragmentShader = R"(
// Per texel: layers 0 and 1 as BGRA8 packed in a uint (weight in the top byte), then the two
// layers' segment indices (-1 none): one fetch per texel.
uniform usampler2D texels;
uniform sampler2D slot_views;
uniform float view_index;
uniform int slot;  // the rendering buffer drawn into: the view's fragments elsewhere are discarded
uniform float z_scale;  // depths are stored as z / z_scale in [0, 1]
flat in vec3 h0;
flat in vec3 h1;
flat in vec3 h2;
flat in vec3 plane;
flat in int segment;
flat in float texture_weight;
layout(location = 0) out vec4 colour_out;
layout(location = 1) out vec4 depth_out;
vec4 Unpack(uint bgra) {
  return vec4(uvec4(bgra, bgra >> 8u, bgra >> 16u, bgra >> 24u) & 255u) / 255.0;
}
void main() {
  if (texelFetch(slot_views, ivec2(gl_FragCoord.xy), 0)[slot] != view_index) discard;
  vec3 p = vec3(gl_FragCoord.xy - 0.5, 1.0);
  vec3 src = vec3(dot(h0, p), dot(h1, p), dot(h2, p));
  vec2 uv = src.xy / src.z;
  float z = 1.0 / dot(plane, p);
  vec2 base = floor(uv);
  vec2 f = uv - base;
  ivec2 size = textureSize(texels, 0);
  float alpha = 0.0;
  vec3 colour = vec3(0.0);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      ivec2 t = ivec2(base) + ivec2(i, j);
      if (t.x < 0 || t.y < 0 || t.x >= size.x || t.y >= size.y) continue;
      float beta = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
      uvec4 texel = texelFetch(texels, t, 0);
      vec4 l0 = Unpack(texel.x);
      vec4 l1 = Unpack(texel.y);
      float a0 = int(texel.z) == segment ? l0.a : 0.0;
      float a1 = int(texel.w) == segment ? l1.a : 0.0;
      alpha += beta * (a0 + a1);
      colour += beta * (a0 * l0.rgb + a1 * l1.rgb);
    }
  }
  if (alpha <= 1e-6) discard;
  colour = colour / alpha;
  alpha *= texture_weight;
  if (alpha <= 1e-6) discard;
  colour_out = vec4(colour, min(alpha, 1.0));
  depth_out = vec4(z / z_scale, 0.0, 0.0, min(alpha, 1.0));
}
)";

// Benchmarks only (GlSceneRenderer::set_segment_floor): the segment pass's rectangles with no
// fragment work, i.e. what llvmpipe's rasteriser costs before the shader does anything.
inline constexpr std::string_view kSegmentFloorFragmentShader = R"(
layout(location = 0) out vec4 colour_out;
layout(location = 1) out vec4 depth_out;
void main() { discard; }
)";

// Section 5: the soft z-buffer of eq. (1) over the three slots, with the two tiers.
// Out: (B, G, R on 0..255, alpha) and (depth in metres, 0, 0, 0).
inline constexpr std::string_view kSoftZResolveFragmentShader = R"(
// Separate samplers: GLSL 3.30 indexes sampler arrays by constant expressions only.
uniform sampler2D colour_slot0;
uniform sampler2D colour_slot1;
uniform sampler2D colour_slot2;
uniform sampler2D depth_slot0;
uniform sampler2D depth_slot1;
uniform sampler2D depth_slot2;
uniform sampler2D slot_weights;
uniform float z_scale;
uniform float rho;
uniform float gamma;
layout(location = 0) out vec4 colour_alpha;
layout(location = 1) out vec4 depth_out;
float SoftZ(float dz) {
  if (dz <= gamma) return 1.0;
  if (dz > rho - gamma) return 0.0;
  return 0.5 * (1.0 + cos(3.14159265 * (dz - gamma) / (rho - 2.0 * gamma)));
}
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 v = texelFetch(slot_weights, p, 0);
  vec4 c[3];
  float z[3];
  bool seen[3];
  bool tier1 = false;
  bool tier2 = false;
  c[0] = texelFetch(colour_slot0, p, 0);
  c[1] = texelFetch(colour_slot1, p, 0);
  c[2] = texelFetch(colour_slot2, p, 0);
  vec3 zs = vec3(texelFetch(depth_slot0, p, 0).r, texelFetch(depth_slot1, p, 0).r, texelFetch(depth_slot2, p, 0).r);
  for (int k = 0; k < 3; ++k) {
    seen[k] = c[k].a > 1e-4;
    z[k] = seen[k] ? zs[k] * z_scale / c[k].a : 0.0;
    if (seen[k] && v[k] > 0.0) tier1 = true;
    if (seen[k] && v[k] <= 0.0) tier2 = true;
  }
  if (!tier1 && !tier2) {
    colour_alpha = vec4(0.0);
    depth_out = vec4(0.0);
    return;
  }
  float zc = 1e30;
  float weight[3];
  for (int k = 0; k < 3; ++k) {
    bool in_tier = seen[k] && (tier1 ? v[k] > 0.0 : v[k] <= 0.0);
    weight[k] = in_tier ? (tier1 ? v[k] : 1.0) : 0.0;
    if (in_tier) zc = min(zc, z[k]);
  }
  vec3 sum_colour = vec3(0.0);
  float sum_alpha = 0.0, sum_b = 0.0, sum_wz = 0.0, sum_z = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (weight[k] <= 0.0) continue;
    float w = SoftZ(z[k] - zc);
    float b = weight[k] * w;
    sum_colour += b * c[k].rgb;  // premultiplied: each slot's rgb is C_k
    sum_alpha += b * c[k].a;
    sum_b += b;
    sum_wz += w * z[k];
    sum_z += w;
  }
  colour_alpha = vec4(255.0 * sum_colour / sum_alpha, sum_alpha / sum_b);
  depth_out = vec4(sum_wz / sum_z, 0.0, 0.0, 0.0);
}
)";

}  // namespace px::render::gl
