#pragma once
// The tracer's ray queries: one Embree device and BVH per render, with
// per-triangle ray visibility (Blender's Ray Visibility) applied by a
// context filter when the scene has any.
#include <embree3/rtcore.h>

#include <cstdint>

#include "tempera/tracer/scene.hpp"

namespace tempera::tracer {

class EmbreeScene {
 public:
  EmbreeScene(const Scene& scene, int threads);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  struct Hit {
    float t;
    std::uint32_t triangle;
    float u, v;  // barycentrics of corners 1 and 2
  };

  // Closest hit in (t_near, t_far) among triangles visible to rays of kind
  // `visibility` (a Visibility bit).
  bool intersect(Float3 origin, Float3 direction, float t_near, float t_far, Hit& hit,
                 unsigned visibility = kVisibleAll) const;
  // Whether any shadow-casting triangle lies in (0, t_far).
  bool occluded(Float3 origin, Float3 direction, float t_far) const;

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  const std::uint8_t* visibility_ = nullptr;  // per triangle, or null: all visible
};

}  // namespace tempera::tracer
