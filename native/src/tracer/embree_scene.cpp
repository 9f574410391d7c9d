#include "embree_scene.hpp"

#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"

namespace tempera::tracer {
namespace {

void check_embree(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error == RTC_ERROR_NONE) return;
  if (error == RTC_ERROR_OUT_OF_MEMORY) throw std::bad_alloc();
  const std::string message = concat("Embree failed to ", what, " (error ", int(error), ")");
  if (error == RTC_ERROR_INVALID_ARGUMENT || error == RTC_ERROR_INVALID_OPERATION) throw ValueError(message);
  throw std::runtime_error(message);
}

// The intersect context carries which rays are asking (the context must come first).
struct VisibilityContext {
  RTCIntersectContext context;
  const std::uint8_t* visibility;
  unsigned mask;
};

void visibility_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const VisibilityContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    if (!(ctx->visibility[prim] & ctx->mask)) args->valid[i] = 0;
  }
}

void set_ray(RTCRay& ray, Float3 o, Float3 d, float t_near, float t_far) {
  ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
  ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
  ray.tnear = t_near;
  ray.tfar = t_far;
  ray.mask = ~0u;
}

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene, int threads) {
  device_ = rtcNewDevice(concat("threads=", resolve_threads(threads)).c_str());
  check_embree(nullptr, "create a device");
  scene_ = rtcNewScene(device_);
  if (!scene.triangle_visibility.empty()) visibility_ = scene.triangle_visibility.data();
  rtcSetSceneFlags(scene_, visibility_ ? RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION)
                                       : RTC_SCENE_FLAG_ROBUST);
  if (!scene.triangles.empty()) {
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree's own buffers carry the padding its SIMD loads need.
    void* vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Float3),
                                             scene.vertices.size());
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

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

bool EmbreeScene::intersect(Float3 origin, Float3 direction, float t_near, float t_far, Hit& hit,
                            unsigned visibility) const {
  VisibilityContext ctx;
  rtcInitIntersectContext(&ctx.context);
  ctx.visibility = visibility_;
  ctx.mask = visibility;
  if (visibility_ && visibility != kVisibleAll) ctx.context.filter = visibility_filter;
  RTCRayHit rh{};
  set_ray(rh.ray, origin, direction, t_near, t_far);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &ctx.context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit = {rh.ray.tfar, rh.hit.primID, rh.hit.u, rh.hit.v};
  return true;
}

bool EmbreeScene::occluded(Float3 origin, Float3 direction, float t_far) const {
  VisibilityContext ctx;
  rtcInitIntersectContext(&ctx.context);
  ctx.visibility = visibility_;
  ctx.mask = kVisibleShadow;
  if (visibility_) ctx.context.filter = visibility_filter;
  RTCRay ray{};
  set_ray(ray, origin, direction, 0.0f, t_far);
  rtcOccluded1(scene_, &ctx.context, &ray);
  return ray.tfar < 0.0f;  // Embree marks a blocked ray with tfar = -inf
}

}  // namespace tempera::tracer
