// Unidirectional path tracer for light-path-expression guides.
//
// Paths start at the camera. Each scattering vertex samples one lobe of a
// small Principled-like BSDF and is labelled with that lobe's event (D, S or
// T); light reached at a vertex, by next-event estimation (NEE) or by a
// BSDF-sampled ray, adds the event L. Every expression keeps one DFA state
// (compiled eye-to-light) per path, so matching costs one table lookup per
// vertex, and a path stops as soon as no expression can match any extension.
//
// NEE evaluates the diffuse and glossy lobes separately (one contribution per
// label) so that LDE and LSE stay apart; BSDF-sampled hits on area lights and
// emissive triangles are weighted against NEE by the power heuristic, per
// lobe. Point, spot and sun lights are reached by NEE only; the constant world
// only by BSDF-sampled rays (cosine sampling is already its ideal strategy).
#include "tempera/embree_tracer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <new>

#include "tempera/error.hpp"
#include "tempera/lpe.hpp"
#include "tempera/parallel.hpp"
#include "tempera/rng.hpp"

namespace tempera {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kSingularRoughness = 0.01f;  // below: a perfect mirror
constexpr int kRouletteFromBounce = 3;
constexpr int kMaxSamples = 1 << 20;  // per pixel: path random streams are pixel * 2^20 + sample

// ---------------------------------------------------------------- Embree ---

void check_embree(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error == RTC_ERROR_NONE) return;
  if (error == RTC_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
  const std::string message = concat("Embree failed to ", what, " (error ", int(error), ")");
  if (error == RTC_ERROR_INVALID_ARGUMENT || error == RTC_ERROR_INVALID_OPERATION) throw ValueError(message);
  throw std::runtime_error(message);
}

// One device and one BVH per render, released with it.
class EmbreeScene {
 public:
  EmbreeScene(const Scene& scene, int threads) {
    device_ = rtcNewDevice(concat("threads=", resolve_threads(threads)).c_str());
    check_embree(nullptr, "create a device");
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    if (!scene.triangles.empty()) {
      RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      // Embree's own buffers carry the padding its SIMD loads need.
      void* vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                               sizeof(Float3), scene.vertices.size());
      void* indices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                              3 * sizeof(std::uint32_t), scene.triangles.size());
      check_embree(device_, "allocate the geometry");
      std::memcpy(vertices, scene.vertices.data(), scene.vertices.size() * sizeof(Float3));
      std::memcpy(indices, scene.triangles.data(), scene.triangles.size() * 3 * sizeof(std::uint32_t));
      rtcCommitGeometry(geometry);
      rtcAttachGeometry(scene_, geometry);
      rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(scene_);
    check_embree(device_, "build the BVH");
  }
  ~EmbreeScene() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  struct Hit {
    float t;
    std::uint32_t triangle;
    float u, v;  // barycentrics of corners 1 and 2
  };

  bool intersect(Float3 origin, Float3 direction, float t_near, float t_far, Hit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    set_ray(rh.ray, origin, direction, t_near, t_far);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit = {rh.ray.tfar, rh.hit.primID, rh.hit.u, rh.hit.v};
    return true;
  }

  bool occluded(Float3 origin, Float3 direction, float t_far) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray{};
    set_ray(ray, origin, direction, 0.0f, t_far);
    rtcOccluded1(scene_, &context, &ray);
    return ray.tfar < 0.0f;  // Embree marks a blocked ray with tfar = -inf
  }

 private:
  static void set_ray(RTCRay& ray, Float3 o, Float3 d, float t_near, float t_far) {
    ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
    ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
    ray.tnear = t_near;
    ray.tfar = t_far;
    ray.mask = ~0u;
  }

  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

// ---------------------------------------------------------------- sampling ---

struct Frame {  // orthonormal basis around a unit normal
  Float3 t, b, n;
  explicit Frame(Float3 normal) : n(normal) {
    // Branch-free basis (Duff et al. 2017).
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
  }
  Float3 to_world(Float3 v) const { return t * v.x + b * v.y + n * v.z; }
};

// Uniform point on the unit disk (concentric map keeps strata compact).
std::array<float, 2> sample_disk(float u1, float u2) {
  const float a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) r = a, phi = kPi / 4 * (b / a);
  else r = b, phi = kPi / 2 - kPi / 4 * (a / b);
  return {r * std::cos(phi), r * std::sin(phi)};
}

Float3 sample_cosine(float u1, float u2) {
  const auto d = sample_disk(u1, u2);
  return {d[0], d[1], std::sqrt(std::fmax(0.0f, 1 - d[0] * d[0] - d[1] * d[1]))};
}

// Radical inverses of the first two Sobol dimensions: a (0,2)-sequence, so
// any power-of-two prefix of the samples stratifies the pixel.
float sobol_dim0(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v >>= 1)
    if (i & 1) r ^= v;
  return float(r >> 8) * (1.0f / 16777216.0f);
}
float sobol_dim1(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return float(r >> 8) * (1.0f / 16777216.0f);
}
float scrambled(float u, std::uint32_t scramble) {  // XOR scrambling keeps the (0,2) property
  return float((std::uint32_t(u * 16777216.0f) ^ (scramble >> 8)) & 0xFFFFFF) * (1.0f / 16777216.0f);
}

float power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

// ---------------------------------------------------------------- BSDF ---

enum Lobe { kDiffuse, kGlossy, kGlass, kLobeCount };

Float3 schlick(Float3 f0, float cos_theta) {
  const float m = 1 - std::clamp(cos_theta, 0.0f, 1.0f);
  const float m5 = m * m * m * m * m;
  return f0 + (Float3{1, 1, 1} - f0) * m5;
}

// Unpolarized Fresnel reflectance; eta = n_transmitted / n_incident.
float fresnel_dielectric(float cos_i, float eta) {
  const float sin_t2 = (1 - cos_i * cos_i) / (eta * eta);
  if (sin_t2 >= 1) return 1;
  const float cos_t = std::sqrt(1 - sin_t2);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

float ggx_d(float cos_h, float alpha2) {
  const float c2 = cos_h * cos_h;
  const float d = c2 * (alpha2 - 1) + 1;
  return alpha2 / (kPi * d * d);
}
float ggx_g1(float cos_v, float alpha2) {
  const float c2 = cos_v * cos_v;
  return 2 / (1 + std::sqrt(1 + alpha2 * (1 - c2) / c2));
}

struct Surface {
  Float3 p, n, ng;  // shading and geometric normals, both on the viewer's side
  Float3 wo;        // towards the previous vertex
  Float3 base, f0, emission;
  float alpha2 = 0;  // GGX alpha^2
  bool mirror = false;
  float eta = 1;     // glass: n behind / n in front of the surface
  float weight[kLobeCount] = {};  // lobe scale factors
  float pick[kLobeCount] = {};    // lobe selection probabilities
};

struct LobeValue {
  Float3 f;        // BSDF value times cos(wi)
  float pdf = 0;   // selection probability times direction pdf (solid angle)
};

// A reflection lobe's value for direction wi (zero for singular lobes).
LobeValue evaluate(const Surface& s, Lobe lobe, Float3 wi) {
  const float cos_i = dot(s.n, wi), cos_o = dot(s.n, s.wo);
  if (cos_i <= 0 || dot(s.ng, wi) <= 0 || s.pick[lobe] <= 0) return {};
  if (lobe == kDiffuse) return {s.base * (s.weight[kDiffuse] * cos_i / kPi), s.pick[kDiffuse] * cos_i / kPi};
  if (lobe != kGlossy || s.mirror) return {};
  const Float3 h = normalize(wi + s.wo);
  const float cos_h = dot(s.n, h), d = ggx_d(cos_h, s.alpha2);
  const float g = ggx_g1(cos_i, s.alpha2) * ggx_g1(cos_o, s.alpha2);
  const Float3 f = schlick(s.f0, dot(wi, h)) * (s.weight[kGlossy] * d * g / (4 * cos_o));
  return {f, s.pick[kGlossy] * d * cos_h / (4 * dot(s.wo, h))};
}

struct Scatter {
  LpeEvent event;
  Float3 wi;
  Float3 weight;     // f cos / pdf
  float pdf = 0;     // for MIS; 0 for singular directions
};

// Samples one lobe; false when the surface absorbs everything.
bool sample(const Surface& s, Rng& rng, Scatter& out) {
  float u = rng.uniform();
  int lobe = 0;
  while (lobe < kLobeCount - 1 && u >= s.pick[lobe]) u -= s.pick[lobe++];
  if (s.pick[lobe] <= 0) return false;
  const float u1 = rng.uniform(), u2 = rng.uniform();
  if (lobe == kGlass) {
    const float cos_o = dot(s.n, s.wo);
    const float fresnel = fresnel_dielectric(cos_o, s.eta);
    const float scale = s.weight[kGlass] / s.pick[kGlass];
    if (u1 < fresnel) {
      out = {LpeEvent::S, s.n * (2 * cos_o) - s.wo, Float3{1, 1, 1} * scale, 0};
    } else {
      // Radiance is not rescaled by eta^2 (as in Cycles): it cancels on
      // closed objects and guides compare shading, not absolute energy.
      const float cos_t = std::sqrt(std::fmax(0.0f, 1 - (1 - cos_o * cos_o) / (s.eta * s.eta)));
      const Float3 wi = normalize(-s.wo / s.eta + s.n * (cos_o / s.eta - cos_t));
      out = {LpeEvent::T, wi, s.base * scale, 0};
    }
    return true;
  }
  if (lobe == kGlossy && s.mirror) {
    const float cos_o = dot(s.n, s.wo);
    const Float3 wi = s.n * (2 * cos_o) - s.wo;
    if (dot(s.ng, wi) <= 0) return false;
    out = {LpeEvent::S, wi, schlick(s.f0, cos_o) * (s.weight[kGlossy] / s.pick[kGlossy]), 0};
    return true;
  }
  const Frame frame(s.n);
  Float3 wi;
  if (lobe == kDiffuse) {
    wi = frame.to_world(sample_cosine(u1, u2));
  } else {
    const float tan2 = s.alpha2 * u1 / (1 - u1);
    const float cos_h = 1 / std::sqrt(1 + tan2), sin_h = std::sqrt(std::fmax(0.0f, 1 - cos_h * cos_h));
    const float phi = 2 * kPi * u2;
    const Float3 h = frame.to_world({sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h});
    wi = h * (2 * dot(s.wo, h)) - s.wo;
  }
  const LobeValue value = evaluate(s, Lobe(lobe), wi);
  if (value.pdf <= 0) return false;
  out = {lobe == kDiffuse ? LpeEvent::D : LpeEvent::S, wi, value.f / value.pdf, value.pdf};
  return true;
}

// ---------------------------------------------------------------- tracer ---

struct LightSample {
  Float3 wi;
  float distance = 0;   // to the sampled point (infinite for the sun)
  Float3 shadow_end;    // where the shadow ray stops: the point, off any surface it lies on
  Float3 radiance;      // incoming radiance divided by the sample's pdf
  float pdf = 0;        // solid angle; 0 for lights BSDF rays cannot hit
};

class Tracer {
 public:
  Tracer(const Scene& scene, const std::vector<LpeDfa>& dfas, const TraceOptions& options)
      : scene_(scene), dfas_(dfas), options_(options), bvh_(scene, options.threads) {
    // Emissive triangles are sampled by area times luminance of emission.
    triangle_light_pdf_.assign(scene.triangles.size(), 0.0f);
    double total = 0;
    for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
      const float power = luminance(material(t).emission) * triangle_area(t);
      if (!(power > 0)) continue;
      emissive_.push_back(t);
      total += power;
      emissive_cdf_.push_back(total);
    }
    for (std::size_t i = 0; i < emissive_.size(); ++i) {
      const std::uint32_t t = emissive_[i];
      const double previous = i ? emissive_cdf_[i - 1] : 0.0;
      triangle_light_pdf_[t] = float((emissive_cdf_[i] - previous) / total) / triangle_area(t);
    }
    for (double& c : emissive_cdf_) c /= total;
  }

  // Radiance of one pixel sample, accumulated into sums[expression].
  void trace_sample(int px, int py, std::uint32_t index, std::uint32_t scramble_x, std::uint32_t scramble_y,
                    Rng& rng, std::vector<int>& states, std::vector<Float3>& sums, float& alpha) const {
    const Camera& cam = scene_.camera;
    const float sx = scrambled(sobol_dim0(index), scramble_x), sy = scrambled(sobol_dim1(index), scramble_y);
    const float ndc_x = 2 * (float(px) + sx) / float(cam.width) - 1;
    const float ndc_y = 1 - 2 * (float(py) + sy) / float(cam.height);
    Float3 origin, direction;
    float depth_scale;  // ray length per unit of view depth
    if (cam.type == Camera::Type::perspective) {
      const float t = cam.width >= cam.height ? cam.tan_half_fov_x : cam.tan_half_fov_y;
      const Float3 d{ndc_x * cam.tan_half_fov_x + 2 * cam.shift_x * t, ndc_y * cam.tan_half_fov_y + 2 * cam.shift_y * t,
                     -1};
      depth_scale = length(d);
      origin = transform_point({0, 0, 0});
      direction = normalize(transform_vector(d));
    } else {
      const float s = std::max(cam.ortho_width, cam.ortho_height);
      origin = transform_point({ndc_x * cam.ortho_width / 2 + cam.shift_x * s,
                                ndc_y * cam.ortho_height / 2 + cam.shift_y * s, 0});
      direction = normalize(transform_vector({0, 0, -1}));
      depth_scale = 1;
    }
    float t_near = cam.clip_start * depth_scale, t_far = cam.clip_end * depth_scale;

    bool any_alive = false;
    for (std::size_t k = 0; k < dfas_.size(); ++k) {
      states[k] = dfas_[k].step(dfas_[k].start, LpeEvent::E);
      any_alive |= dfas_[k].alive(states[k]);
    }
    Float3 throughput{1, 1, 1};
    float previous_pdf = 0;  // of the BSDF sample that led here; 0: camera or singular
    for (int bounce = 0;; ++bounce) {
      EmbreeScene::Hit hit{};
      const bool hit_geometry = bvh_.intersect(origin, direction, t_near, t_far, hit);
      if (bounce == 0 && hit_geometry) alpha += 1;
      if (!any_alive) return;
      const float t_geometry = hit_geometry ? hit.t : t_far;
      add_area_lights_crossed(origin, direction, t_near, t_geometry, throughput, previous_pdf, states, sums);
      if (!hit_geometry) {
        add_emission(states, sums, throughput * scene_.world_radiance, 1.0f);
        return;
      }
      const Surface s = surface_at(hit, origin, direction);
      if (max_component(s.emission) > 0) {
        const float cos_l = std::fabs(dot(s.ng, direction));
        const float pdf_light = triangle_light_pdf_[hit.triangle] * hit.t * hit.t / cos_l;
        add_emission(states, sums, throughput * s.emission, mis_weight(previous_pdf, pdf_light));
      }
      if (bounce > options_.max_bounces) return;
      next_event(s, throughput, states, sums, rng);

      Scatter scatter;
      if (!sample(s, rng, scatter)) return;
      any_alive = false;
      for (std::size_t k = 0; k < dfas_.size(); ++k) {
        states[k] = dfas_[k].step(states[k], scatter.event);
        any_alive |= dfas_[k].alive(states[k]);
      }
      if (!any_alive) return;
      throughput *= scatter.weight;
      if (bounce >= kRouletteFromBounce) {
        const float survive = std::min(0.95f, max_component(throughput));
        if (!(rng.uniform() < survive)) return;
        throughput = throughput / survive;
      }
      previous_pdf = scatter.pdf;
      origin = offset(s.p, s.ng, scatter.wi);
      direction = scatter.wi;
      t_near = 0;
      t_far = std::numeric_limits<float>::infinity();
    }
  }

 private:
  const Material& material(std::uint32_t t) const { return scene_.materials[scene_.triangle_materials[t]]; }
  Float3 corner(std::uint32_t t, int c) const { return scene_.vertices[scene_.triangles[t][c]]; }
  float triangle_area(std::uint32_t t) const {
    return 0.5f * length(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
  }
  Float3 transform_point(Float3 p) const {
    const auto& m = scene_.camera.camera_to_world;
    return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
            m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
  }
  Float3 transform_vector(Float3 v) const {
    const auto& m = scene_.camera.camera_to_world;
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
            m[8] * v.x + m[9] * v.y + m[10] * v.z};
  }

  // Ray origin pushed off the surface, to the side the ray leaves by.
  static Float3 offset(Float3 p, Float3 ng, Float3 wi) {
    const float scale = 2e-5f * (1 + std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}));
    return p + ng * (dot(ng, wi) > 0 ? scale : -scale);
  }

  static float mis_weight(float bsdf_pdf, float light_pdf) {
    return bsdf_pdf > 0 && light_pdf > 0 ? power_heuristic(bsdf_pdf, light_pdf) : 1.0f;
  }

  // Adds `radiance` (the path ending at an emitter) to every expression that
  // accepts the path closed by L.
  void add_emission(const std::vector<int>& states, std::vector<Float3>& sums, Float3 radiance, float weight) const {
    if (!(max_component(radiance) > 0)) return;
    for (std::size_t k = 0; k < dfas_.size(); ++k)
      if (dfas_[k].accepts(dfas_[k].step(states[k], LpeEvent::L))) sums[k] += radiance * weight;
  }

  Surface surface_at(const EmbreeScene::Hit& hit, Float3 origin, Float3 direction) const {
    const std::uint32_t t = hit.triangle;
    const Material& m = material(t);
    const float b1 = hit.u, b2 = hit.v, b0 = 1 - b1 - b2;
    Surface s;
    s.p = origin + direction * hit.t;
    s.wo = -direction;
    s.ng = normalize(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    const bool front = dot(s.ng, s.wo) > 0;
    s.n = s.ng;
    if (!scene_.normals.empty()) {
      const Float3* n = &scene_.normals[3 * std::size_t(t)];
      s.n = normalize(n[0] * b0 + n[1] * b1 + n[2] * b2);
    }
    if (!front) s.ng = -s.ng, s.n = -s.n;
    // Interpolated normals can face away from the viewer at silhouettes.
    if (dot(s.n, s.wo) <= 1e-4f) s.n = s.ng;
    float u = 0, v = 0;
    if (!scene_.uvs.empty()) {
      const auto* uv = &scene_.uvs[3 * std::size_t(t)];
      u = uv[0][0] * b0 + uv[1][0] * b1 + uv[2][0] * b2;
      v = uv[0][1] * b0 + uv[1][1] * b1 + uv[2][1] * b2;
    }
    s.base = base_color_at(m, u, v);
    s.emission = m.emission;
    const float metallic = std::clamp(m.metallic, 0.0f, 1.0f);
    const float transmission = std::clamp(m.transmission, 0.0f, 1.0f);
    const float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
    s.mirror = roughness < kSingularRoughness;
    s.alpha2 = std::max(roughness * roughness * roughness * roughness, 1e-8f);
    const float specular_f0 = 0.08f * std::max(m.specular, 0.0f);
    s.f0 = Float3{specular_f0, specular_f0, specular_f0} * (1 - metallic) + s.base * metallic;
    s.eta = front ? m.ior : 1 / m.ior;
    s.weight[kDiffuse] = (1 - metallic) * (1 - transmission);
    s.weight[kGlossy] = 1 - (1 - metallic) * transmission;
    s.weight[kGlass] = (1 - metallic) * transmission;
    // Pick lobes by their rough share of reflected energy.
    const float energy[kLobeCount] = {s.weight[kDiffuse] * luminance(s.base),
                                      s.weight[kGlossy] * luminance(schlick(s.f0, dot(s.n, s.wo))),
                                      s.weight[kGlass]};
    const float total = energy[0] + energy[1] + energy[2];
    for (int i = 0; i < kLobeCount; ++i) s.pick[i] = total > 0 ? energy[i] / total : 0;
    return s;
  }

  // Adds the area lights the ray crosses from their emitting side within
  // (t_near, t_far). Lights are transparent, as in Cycles: rays go on behind
  // them, and they cast no shadows either.
  void add_area_lights_crossed(Float3 o, Float3 d, float t_near, float t_far, Float3 throughput, float previous_pdf,
                               const std::vector<int>& states, std::vector<Float3>& sums) const {
    for (const Light& l : scene_.lights) {
      if (l.type != Light::Type::area) continue;
      const float cos_l = -dot(d, l.normal);
      if (cos_l <= 0) continue;
      const float t = dot(l.center - o, l.normal) / dot(d, l.normal);
      if (!(t > t_near && t < t_far)) continue;
      const Float3 q = o + d * t - l.center;
      const float a = 2 * dot(q, l.axis_u) / l.size_u, b = 2 * dot(q, l.axis_v) / l.size_v;
      const bool inside = l.shape == Light::Shape::rect ? std::fabs(a) <= 1 && std::fabs(b) <= 1 : a * a + b * b <= 1;
      if (!inside) continue;
      const float light_pdf = t * t / (area_of(l) * cos_l);  // of NEE choosing this point
      add_emission(states, sums, throughput * l.radiance, mis_weight(previous_pdf, light_pdf));
    }
  }

  static float area_of(const Light& l) {
    return l.shape == Light::Shape::rect ? l.size_u * l.size_v : kPi * l.size_u * l.size_v / 4;
  }

  // One sample of light `l` as seen from p; false if it cannot light p.
  bool sample_light(const Light& l, Float3 p, Rng& rng, LightSample& out) const {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    switch (l.type) {
      case Light::Type::point:
      case Light::Type::spot: {
        // A disk of the light's radius facing p (as Cycles' soft point lights).
        const Float3 towards = l.position - p;
        const float d0 = length(towards);
        if (!(d0 > 0)) return false;
        const Frame frame(towards / d0);
        const auto disk = sample_disk(u1, u2);
        const Float3 x = l.position + (frame.t * disk[0] + frame.b * disk[1]) * l.radius;
        const Float3 to_x = x - p;
        out.distance = length(to_x);
        out.wi = to_x / out.distance;
        out.shadow_end = x;
        // Radiance I / (pi r^2) over the pdf 1 / (pi r^2) per area, to solid angle.
        const float cos_l = dot(frame.n, out.wi);
        out.radiance = l.intensity * (cos_l / (out.distance * out.distance));
        out.pdf = 0;
        if (l.type == Light::Type::spot) {
          const float cos_a = dot(l.direction, -out.wi), cos_edge = std::cos(l.spot_half_angle);
          if (cos_a <= cos_edge) return false;
          const float smooth = (1 - cos_edge) * l.spot_blend;
          if (smooth > 0) {
            const float x01 = std::min(1.0f, (cos_a - cos_edge) / smooth);
            out.radiance = out.radiance * (x01 * x01 * (3 - 2 * x01));
          }
        }
        return true;
      }
      case Light::Type::sun: {
        // Uniform in the sun's cone; irradiance already is radiance over pdf.
        const float cos_max = std::cos(l.angle / 2);
        const float cos_t = 1 - u1 * (1 - cos_max), sin_t = std::sqrt(std::fmax(0.0f, 1 - cos_t * cos_t));
        out.wi = Frame(l.direction).to_world({sin_t * std::cos(2 * kPi * u2), sin_t * std::sin(2 * kPi * u2), cos_t});
        out.distance = std::numeric_limits<float>::infinity();
        out.radiance = l.irradiance;
        out.pdf = 0;
        return true;
      }
      case Light::Type::area: {
        float a, b;
        if (l.shape == Light::Shape::rect) {
          a = u1 - 0.5f, b = u2 - 0.5f;
        } else {
          const auto disk = sample_disk(u1, u2);
          a = disk[0] / 2, b = disk[1] / 2;
        }
        const Float3 x = l.center + l.axis_u * (a * l.size_u) + l.axis_v * (b * l.size_v);
        out.shadow_end = x;
        return to_area_sample(x - p, l.normal, l.radiance, 1 / area_of(l), out);
      }
    }
    return false;
  }

  // Converts a point sampled on an emitting surface (pdf per area) to a
  // direction sample; one-sided unless two_sided.
  static bool to_area_sample(Float3 to_x, Float3 normal, Float3 radiance, float pdf_area, LightSample& out,
                             bool two_sided = false) {
    const float d2 = dot(to_x, to_x);
    if (!(d2 > 0)) return false;
    out.distance = std::sqrt(d2);
    out.wi = to_x / out.distance;
    float cos_l = -dot(normal, out.wi);
    if (two_sided) cos_l = std::fabs(cos_l);
    if (cos_l <= 0) return false;
    out.pdf = pdf_area * d2 / cos_l;
    out.radiance = radiance / out.pdf;
    return true;
  }

  bool sample_emissive_triangle(Float3 p, Rng& rng, LightSample& out) const {
    const double u = rng.uniform();
    const std::size_t i = std::min(std::size_t(std::lower_bound(emissive_cdf_.begin(), emissive_cdf_.end(), u) -
                                               emissive_cdf_.begin()),
                                   emissive_.size() - 1);
    const std::uint32_t t = emissive_[i];
    const float r1 = std::sqrt(rng.uniform()), r2 = rng.uniform();
    const Float3 x = corner(t, 0) * (1 - r1) + corner(t, 1) * (r1 * (1 - r2)) + corner(t, 2) * (r1 * r2);
    const Float3 n = normalize(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    out.shadow_end = offset(x, n, p - x);  // so that the shadow ray cannot reach the emitter
    return to_area_sample(x - p, n, material(t).emission, triangle_light_pdf_[t], out, true);
  }

  // Next-event estimation at s: one sample per light (and one for all
  // emissive triangles), each lobe's contribution filed under its own event.
  void next_event(const Surface& s, Float3 throughput, const std::vector<int>& states, std::vector<Float3>& sums,
                  Rng& rng) const {
    // Which lobes lead to a match when closed by a light right here?
    bool wanted[2] = {false, false};
    const LpeEvent events[2] = {LpeEvent::D, LpeEvent::S};
    for (int lobe = 0; lobe < 2; ++lobe)
      for (std::size_t k = 0; k < dfas_.size() && !wanted[lobe]; ++k)
        wanted[lobe] = dfas_[k].accepts(dfas_[k].step(dfas_[k].step(states[k], events[lobe]), LpeEvent::L));
    wanted[kDiffuse] &= s.pick[kDiffuse] > 0;
    wanted[kGlossy] &= s.pick[kGlossy] > 0 && !s.mirror;
    if (!wanted[kDiffuse] && !wanted[kGlossy]) return;

    auto shade = [&](const LightSample& ls) {
      LobeValue values[2];
      bool any = false;
      for (int lobe = 0; lobe < 2; ++lobe)
        if (wanted[lobe]) {
          values[lobe] = evaluate(s, Lobe(lobe), ls.wi);
          any |= values[lobe].pdf > 0;
        }
      if (!any) return;
      // Both ends are off their surfaces, so the segment between them can
      // only hit other geometry.
      const Float3 origin = offset(s.p, s.ng, ls.wi);
      if (std::isinf(ls.distance)) {
        if (bvh_.occluded(origin, ls.wi, ls.distance)) return;
      } else {
        const Float3 segment = ls.shadow_end - origin;
        const float span = length(segment);
        if (!(span > 0) || bvh_.occluded(origin, segment / span, span)) return;
      }
      for (int lobe = 0; lobe < 2; ++lobe) {
        if (!(values[lobe].pdf > 0)) continue;
        const float weight = ls.pdf > 0 ? power_heuristic(ls.pdf, values[lobe].pdf) : 1.0f;
        const Float3 c = throughput * values[lobe].f * ls.radiance * weight;
        for (std::size_t k = 0; k < dfas_.size(); ++k)
          if (dfas_[k].accepts(dfas_[k].step(dfas_[k].step(states[k], events[lobe]), LpeEvent::L))) sums[k] += c;
      }
    };
    LightSample ls;
    for (const Light& l : scene_.lights)
      if (sample_light(l, s.p, rng, ls)) shade(ls);
    if (!emissive_.empty() && sample_emissive_triangle(s.p, rng, ls)) shade(ls);
  }

  const Scene& scene_;
  const std::vector<LpeDfa>& dfas_;
  const TraceOptions& options_;
  EmbreeScene bvh_;
  std::vector<std::uint32_t> emissive_;
  std::vector<double> emissive_cdf_;
  std::vector<float> triangle_light_pdf_;  // per triangle: pdf per area of NEE picking a point on it
};

}  // namespace

TraceResult trace_lpe(const Scene& scene, const std::vector<std::string>& expressions, const TraceOptions& options,
                      const TraceProgress& progress) {
  if (options.samples < 1 || options.samples > kMaxSamples)
    throw ValueError(concat("samples must be in [1, ", kMaxSamples, "], got ", options.samples));
  if (options.max_bounces < 0) throw ValueError(concat("max_bounces must be >= 0, got ", options.max_bounces));
  std::vector<LpeDfa> dfas;
  for (const auto& e : expressions) dfas.push_back(compile_lpe(e, LpeOrder::eye_to_light));
  validate_scene(scene);

  const int width = scene.camera.width, height = scene.camera.height;
  TraceResult result;
  for (std::size_t k = 0; k < dfas.size(); ++k) result.images.emplace_back(width, height, 3);
  result.alpha = Image(width, height, 1);
  const Tracer tracer(scene, dfas, options);

  int rows_done = 0;
  std::mutex progress_mutex;
  parallel_for(height, options.threads, [&](int y) {
    std::vector<int> states(dfas.size());
    std::vector<Float3> sums(dfas.size());
    for (int x = 0; x < width; ++x) {
      const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(width) + std::uint64_t(x);
      Rng pixel_rng(mix64(options.seed), pixel);  // a seed of its own: no stream shared with paths
      const std::uint32_t scramble_x = std::uint32_t(pixel_rng.next()), scramble_y = std::uint32_t(pixel_rng.next());
      std::fill(sums.begin(), sums.end(), Float3{});
      float alpha = 0;
      for (int i = 0; i < options.samples; ++i) {
        Rng rng(options.seed, pixel * kMaxSamples + std::uint64_t(i));
        tracer.trace_sample(x, y, std::uint32_t(i), scramble_x, scramble_y, rng, states, sums, alpha);
      }
      const float inv = 1.0f / float(options.samples);
      for (std::size_t k = 0; k < dfas.size(); ++k) {
        float* out = result.images[k].pixel(x, y);
        out[0] = sums[k].x * inv, out[1] = sums[k].y * inv, out[2] = sums[k].z * inv;
      }
      result.alpha.at(x, y, 0) = alpha * inv;
    }
    if (progress) {
      // Counted under the lock so that reports never go backwards.
      std::lock_guard lock(progress_mutex);
      if (!progress(double(++rows_done) / height)) throw CancelledError("tracing cancelled");
    }
  });
  return result;
}

}  // namespace tempera
