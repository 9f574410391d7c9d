// Python binding of the rigid-body method (rigid.hpp, rigid_frame.hpp,
// rigid_exemplar.hpp, quadratic_fit.hpp); tempera.methods.rigid.rigid wraps it. Tracks
// cross as the dicts of tracks.json (tempera.methods.rigid.rigid_tracks), maps as (2, 6)
// arrays in the paper's column order (x, y, x^2, y^2, xy, 1).
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>

#include "bind_frame_job.hpp"
#include "bind_method.hpp"
#include "bind_options.hpp"
#include "numpy_bridge.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/methods/rigid/quadratic_fit.hpp"
#include "tempera/methods/rigid/rigid.hpp"
#include "tempera/methods/rigid/rigid_exemplar.hpp"
#include "tempera/methods/rigid/rigid_frame.hpp"
#include "tempera/methods/rigid/rigid_job.hpp"
#include "tempera/methods/rigid/stroke_resynthesis.hpp"

namespace py = pybind11;
using namespace tempera;
using py_bridge::FloatArray;

namespace {

Vec2 vec2(const py::handle& h, const char* what) {
  const auto v = py::cast<std::vector<double>>(h);
  if (v.size() != 2) throw ValueError(concat(what, " must have 2 numbers"));
  return {v[0], v[1]};
}

Track track_of(const py::dict& d) {
  for (const char* key : {"centre", "velocity", "theta", "radius"})
    if (!d.contains(key)) throw ValueError(concat("a track needs '", key, "'"));
  const py::list centre = d["centre"], velocity = d["velocity"];
  const auto theta = py::cast<std::vector<double>>(d["theta"]);
  const auto radius = py::cast<std::vector<double>>(d["radius"]);
  const std::size_t n = centre.size();
  if (velocity.size() != n || theta.size() != n || radius.size() != n)
    throw ValueError("a track's centre, velocity, theta and radius need one entry per frame");
  Track t;
  for (std::size_t f = 0; f < n; ++f) {
    TrackFrame tf;
    tf.centre = vec2(centre[f], "a centre");
    tf.velocity = vec2(velocity[f], "a velocity");
    tf.theta = theta[f];
    tf.radius = radius[f];
    t.frames.push_back(tf);
  }
  if (d.contains("events"))
    for (const auto& e : py::list(d["events"])) {
      const py::dict ed = py::reinterpret_borrow<py::dict>(e);
      t.events.push_back({py::cast<int>(ed["frame"]), vec2(ed["contact"], "a contact"), vec2(ed["normal"], "a normal")});
    }
  validate_track(t);
  derive_trajectory_angles(t);
  return t;
}

py::dict dict_of(const Track& t) {
  py::list centre, velocity, events;
  std::vector<double> theta, radius, delta, alpha;
  for (const TrackFrame& f : t.frames) {
    centre.append(py::make_tuple(f.centre.x, f.centre.y));
    velocity.append(py::make_tuple(f.velocity.x, f.velocity.y));
    theta.push_back(f.theta), radius.push_back(f.radius), delta.push_back(f.delta), alpha.push_back(f.alpha);
  }
  for (const RigidEvent& e : t.events) {
    py::dict ed;
    ed["frame"] = e.frame;
    ed["contact"] = py::make_tuple(e.contact.x, e.contact.y);
    ed["normal"] = py::make_tuple(e.normal.x, e.normal.y);
    ed["obstacle"] = "static";
    events.append(ed);
  }
  py::dict d;
  d["centre"] = centre, d["velocity"] = velocity, d["theta"] = theta, d["radius"] = radius;
  d["delta"] = delta, d["alpha"] = alpha, d["events"] = events;
  return d;
}

py::array_t<double> array_of(const QuadraticMap& D) {
  py::array_t<double> a({2, 6});
  std::copy(D.d.begin(), D.d.end(), a.mutable_data());
  return a;
}

QuadraticMap map_of(const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 2 || a.shape(0) != 2 || a.shape(1) != 6) throw ValueError("a quadratic map must be a (2, 6) array");
  QuadraticMap D;
  std::copy(a.data(), a.data() + 12, D.d.begin());
  return D;
}

const TrackFrame& frame_of(const Track& t, int f) {
  if (f < 0 || f >= int(t.frames.size())) throw ValueError(concat("frame ", f, " is outside the track's ", t.frames.size()));
  return t.frames[std::size_t(f)];
}

void bind_strokes(py::module_& m) {
  m.def(
      "stroke_guide",
      [](const FloatArray& rgba, float d_max) {
        const ImageView v = py_bridge::view_of(rgba, "drawing");
        if (v.channels != 4) throw ValueError("the drawing must be an RGBA image");
        return py_bridge::to_numpy(stroke_guide(v, d_max));
      },
      py::arg("rgba"), py::arg("d_max"), "G = 1 - distance to the ink / d_max (H, W, 1); use tempera.methods.rigid.rigid_strokes.");
  m.def(
      "resynthesize_strokes",
      [](const FloatArray& drawing, const FloatArray& exemplar, float d_max, float weight, std::uint64_t seed,
         const py::object& progress) {
        const ImageView d = py_bridge::view_of(drawing, "drawing"), e = py_bridge::view_of(exemplar, "stroke exemplar");
        const ProgressCallback report = py_bridge::python_progress(progress);
        Image out;
        {
          py::gil_scoped_release release;
          out = resynthesize_strokes(d, e, d_max, weight, seed, report);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("drawing"), py::arg("exemplar"), py::arg("d_max"), py::arg("weight"), py::arg("seed") = 1,
      py::arg("progress") = py::none(), "The drawing's strokes re-made from the stroke exemplar (RGBA).");
  m.def(
      "generated_stroke_exemplar",
      [](int size, float width, std::uint64_t seed) { return py_bridge::to_numpy(generated_stroke_exemplar(size, width, seed)); },
      py::arg("size") = 160, py::arg("width") = 4.0f, py::arg("seed") = 0, "The project's brush-pen stroke exemplar (RGBA).");
  m.def(
      "load_stroke_exemplar", [](const std::string& spec) { return py_bridge::to_numpy(load_stroke_exemplar(spec)); },
      py::arg("spec"), "The stroke exemplar 'generated' or an image file names (RGBA).");
  m.attr("GENERATED_STROKE_COLOUR") =
      py::make_tuple(kGeneratedStrokeColour[0], kGeneratedStrokeColour[1], kGeneratedStrokeColour[2]);
}

void bind_rigid(py::module_& m) {
  py_bridge::bind_options_class<RigidOptions>(m, "RigidOptions", rigid_option_table(),
                                              "Options of the rigid-body method (native/include/tempera/methods/rigid/rigid.hpp).");
  py_bridge::bind_options_class<QuadraticFitOptions>(
      m, "QuadraticFitOptions", quadratic_fit_option_table(),
      "Options of the quadratic registration (native/include/tempera/methods/rigid/quadratic_fit.hpp).");
  py_bridge::bind_options_class<ExemplarStyle>(
      m, "ExemplarStyle", exemplar_style_table(),
      "The generated exemplar's style (native/include/tempera/methods/rigid/rigid_exemplar.hpp).");

  m.def("rigid_exemplar_folders", &rigid_exemplar_folders, py::arg("examples"),
        "The exemplar folders of EXAMPLES (itself, or its subfolders holding tracks.json, sorted); "
        "FileNotFoundError or ValueError naming the folder.");
  m.def(
      "check_rigid_track", [](const py::dict& track) { track_of(track); }, py::arg("track"),
      "ValueError (or TypeError) naming what is wrong with a track dict (tracks.json is user input).");
  m.def(
      "bouncing_ball",
      [](std::pair<double, double> start, std::pair<double, double> velocity, double radius, double gravity,
         double floor, double restitution, double spin, int frames) {
        return dict_of(bouncing_ball({start.first, start.second}, {velocity.first, velocity.second}, radius, gravity,
                                     floor, restitution, spin, frames));
      },
      py::arg("start"), py::arg("velocity"), py::arg("radius"), py::arg("gravity"), py::arg("floor"),
      py::arg("restitution"), py::arg("spin"), py::arg("frames"), "A 2D bouncing ball's track with its bounces.");
  m.def(
      "generator_map", [](const py::dict& track, int frame, const ExemplarStyle& style) {
        return array_of(generator_map(track_of(track), frame, style));
      },
      py::arg("track"), py::arg("frame"), py::arg("style"), "D_gen, the generated exemplar's map (the oracle).");
  m.def(
      "draw_exemplar_frame",
      [](const py::dict& track, int frame, const ExemplarStyle& style, int width, int height) {
        const Track t = track_of(track);
        frame_of(t, frame);
        Image out;
        {
          py::gil_scoped_release release;
          out = draw_exemplar_frame(t, frame, style, width, height);
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("track"), py::arg("frame"), py::arg("style"), py::arg("width"), py::arg("height"),
      "The generated 'hand-drawn' frame (RGBA).");
  m.def(
      "proxy_mask",
      [](const py::dict& track, int frame, const std::string& shape, int width, int height) {
        const Track t = track_of(track);
        return py_bridge::to_numpy(proxy_mask(frame_of(t, frame), parse_enum<ProxyShape>(shape, "proxy shape"), width, height));
      },
      py::arg("track"), py::arg("frame"), py::arg("shape"), py::arg("width"), py::arg("height"),
      "The proxy's filled silhouette (H, W, 1).");
  m.def(
      "fit_quadratic_map",
      [](const FloatArray& mask, const FloatArray& ink, std::pair<double, double> centre, double radius,
         const QuadraticFitOptions& options) {
        const ImageView s = py_bridge::view_of(mask, "source mask"), e = py_bridge::view_of(ink, "drawing");
        QuadraticMap D;
        {
          py::gil_scoped_release release;
          D = fit_quadratic_map(s, e, {{centre.first, centre.second}, radius}, options);
        }
        return array_of(D);
      },
      py::arg("mask"), py::arg("ink"), py::arg("centre"), py::arg("radius"), py::arg("options"),
      "D registering a drawn frame to its proxy.");
  m.def(
      "extract_residual",
      [](const FloatArray& drawing, const py::array_t<double, py::array::c_style | py::array::forcecast>& D,
         std::pair<double, double> centre, double radius) {
        const ImageView d = py_bridge::view_of(drawing, "drawing");
        const QuadraticMap map = map_of(D);
        Image out;
        {
          py::gil_scoped_release release;
          out = extract_residual(d, map, {{centre.first, centre.second}, radius});
        }
        return py_bridge::to_numpy(std::move(out));
      },
      py::arg("drawing"), py::arg("map"), py::arg("centre"), py::arg("radius"), "The residual f^r = D^-1(f^e).");
  m.def(
      "rigid_deformations",
      [](const py::list& exemplars, const py::dict& target, const RigidOptions& options) {
        std::vector<RigidExemplar> ex;
        for (const auto& e : exemplars) {
          const py::tuple pair = py::reinterpret_borrow<py::tuple>(e);
          RigidExemplar r;
          r.track = track_of(py::reinterpret_borrow<py::dict>(pair[0]));
          for (const auto& D : py::list(pair[1])) r.maps.push_back(map_of(py::reinterpret_borrow<py::array>(D)));
          ex.push_back(std::move(r));
        }
        const Track t = track_of(target);
        std::vector<RigidFrame> frames;
        {
          py::gil_scoped_release release;
          frames = synthesize_deformations(ex, t, options);
        }
        py::list out;
        for (const RigidFrame& f : frames) {
          py::list refs;
          for (const ResidualRef& r : f.residuals)
            refs.append(py::make_tuple(r.exemplar, r.frame, r.weight, r.augmentation.gamma, r.augmentation.rho,
                                       r.augmentation.flip));
          out.append(py::make_tuple(array_of(f.D), f.xi, refs));
        }
        return out;
      },
      py::arg("exemplars"), py::arg("target"), py::arg("options"),
      "D_hat per target frame with its damping and matched residuals: [(D, xi, [(exemplar, frame, weight, gamma, "
      "rho, flip)])].");
  m.def(
      "rigid_stylize",
      [](const py::list& exemplars, const py::dict& target, const RigidOptions& options, int width, int height,
         const std::function<bool(int)>& progress, std::optional<std::vector<int>> only) {
        // exemplars: [(track, [maps], [residual RGBA arrays])]
        std::vector<RigidExemplar> ex;
        std::vector<std::vector<FloatArray>> residual_arrays;
        for (const auto& e : exemplars) {
          const py::tuple triple = py::reinterpret_borrow<py::tuple>(e);
          RigidExemplar r;
          r.track = track_of(py::reinterpret_borrow<py::dict>(triple[0]));
          for (const auto& D : py::list(triple[1])) r.maps.push_back(map_of(py::reinterpret_borrow<py::array>(D)));
          std::vector<FloatArray> res;
          for (const auto& a : py::list(triple[2])) res.push_back(py::cast<FloatArray>(a));
          if (res.size() != r.track.frames.size())
            throw ValueError(concat("an exemplar has ", res.size(), " residuals for ", r.track.frames.size(), " frames"));
          ex.push_back(std::move(r));
          residual_arrays.push_back(std::move(res));
        }
        std::vector<std::vector<ImageView>> views;
        for (const auto& res : residual_arrays) {
          std::vector<ImageView> v;
          for (const auto& a : res) v.push_back(py_bridge::view_of(a, "residual"));
          views.push_back(std::move(v));
        }
        const ResidualSource source = [&views](int e, int f) { return views[std::size_t(e)][std::size_t(f)]; };
        const Track t = track_of(target);
        py::list frames_out;
        std::vector<RigidFrame> frames;
        std::vector<Vec2> shifts;
        {
          py::gil_scoped_release release;
          frames = synthesize_deformations(ex, t, options);
          shifts = contact_shifts(ex, source, t, frames, width, height, options.contact_fade);
        }
        for (int f = 0; f < int(frames.size()); ++f) {
          if (only && std::find(only->begin(), only->end(), f) == only->end()) {
            frames_out.append(py::none());  // not asked for (already written: a resumed run)
            continue;
          }
          if (progress && !progress(f)) throw CancelledError("rigid-body stylization cancelled");
          Image out;
          {
            py::gil_scoped_release release;
            out = render_rigid_frame(ex, source, t, f, frames[std::size_t(f)], width, height, shifts[std::size_t(f)]);
          }
          frames_out.append(py::make_tuple(py_bridge::to_numpy(std::move(out)), array_of(frames[std::size_t(f)].D),
                                           py::make_tuple(shifts[std::size_t(f)].x, shifts[std::size_t(f)].y)));
        }
        return frames_out;
      },
      py::arg("exemplars"), py::arg("target"), py::arg("options"), py::arg("width"), py::arg("height"),
      py::arg("progress") = nullptr, py::arg("only") = py::none(),
      "Every target frame: [(RGBA, D_hat, contact shift)] (None for frames not in `only`); progress(frame) "
      "returning False cancels.");
  bind_strokes(m);
}

// module.cpp runs it after the core's bindings (py_bridge::method_bindings).
const py_bridge::MethodBinding kBinding("rigid", bind_rigid);

}  // namespace
