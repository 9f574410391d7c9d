#include "tempera/engine/motion.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/engine/patch_distance.hpp"  // sample_bilinear

namespace tempera {

namespace {

void require_velocity(const ImageView& v, const char* what) {
  require_nonempty(v, what);
  if (v.channels != 2)
    throw ValueError(concat(what, " must have 2 channels (x, y velocity in pixels), got ", v.channels));
  require_finite(v, what);
}

void require_epsilon(float epsilon) {
  if (!(epsilon > 0.0f) || !std::isfinite(epsilon))
    throw ValueError(concat("occlusion epsilon must be a positive finite number, got ", epsilon));
}

// Bilinear sample of all channels at (x, y); border pixels extend outwards.
void sample_bilinear(const ImageView& img, float x, float y, float* out) {
  tempera::sample_bilinear(img.data, img.width, img.height, img.channels, img.channels, x, y, out);
}

// Shared by χ- and χ+: follow `here` (sign -1: backward, +1: forward) to the
// other frame and compare with the velocity `there` that the other frame
// holds for the same motion step.
Image occlusion(const ImageView& here, const char* here_what, const ImageView& there, const char* there_what,
                float sign, float epsilon) {
  require_velocity(here, here_what);
  require_velocity(there, there_what);
  require_same_size(here, here_what, there, there_what);
  require_epsilon(epsilon);
  Image out(here.width, here.height, 1);
  parallel_for(here.height, 0, [&](int y) {
    for (int x = 0; x < here.width; ++x) {
      const float* v = here.pixel(x, y);
      const float qx = float(x) + sign * v[0], qy = float(y) + sign * v[1];
      // Outside the frame's pixel footprints: the point was (or will be) not
      // visible, so there is nothing to be coherent with.
      const bool inside = qx >= -0.5f && qx < float(here.width) - 0.5f && qy >= -0.5f &&
                          qy < float(here.height) - 0.5f;
      float w[2] = {0.0f, 0.0f};
      if (inside) sample_bilinear(there, qx, qy, w);
      const float dx = w[0] - v[0], dy = w[1] - v[1];
      out.at(x, y, 0) = inside && dx * dx + dy * dy < epsilon ? 1.0f : 0.0f;
    }
  });
  return out;
}

}  // namespace

Image occlusion_backward(const ImageView& v_minus_t, const ImageView& v_plus_prev, float epsilon) {
  return occlusion(v_minus_t, "v_minus_t", v_plus_prev, "v_plus_prev", -1.0f, epsilon);
}

Image occlusion_forward(const ImageView& v_plus_t, const ImageView& v_minus_next, float epsilon) {
  return occlusion(v_plus_t, "v_plus_t", v_minus_next, "v_minus_next", +1.0f, epsilon);
}

Image warp_backward(const ImageView& previous, const ImageView& v_minus_t) {
  require_nonempty(previous, "previous");
  require_finite(previous, "previous");
  require_velocity(v_minus_t, "v_minus_t");
  require_same_size(previous, "previous", v_minus_t, "v_minus_t");
  Image out(previous.width, previous.height, previous.channels);
  parallel_for(previous.height, 0, [&](int y) {
    for (int x = 0; x < previous.width; ++x) {
      const float* v = v_minus_t.pixel(x, y);
      sample_bilinear(previous, float(x) - v[0], float(y) - v[1], out.pixel(x, y));
    }
  });
  return out;
}

}  // namespace tempera
