#include "tempera/app/light_path_guides.hpp"

#include <algorithm>
#include <cmath>

#include "tempera/engine/error.hpp"
#include "tempera/engine/option_table.hpp"

namespace tempera {
namespace {

bool is_light_path_guide(const std::string& name) {
  const auto& known = light_path_guides();
  return std::any_of(known.begin(), known.end(), [&](const LightPathGuide& g) { return name == g.name; });
}

double srgb_encode(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

}  // namespace

std::string light_path_guide_names() {
  std::string out;
  for (const auto& g : light_path_guides()) out += (out.empty() ? "" : ", ") + std::string(g.name);
  return out;
}

void parse_guide_weights(const std::string& text, GuideWeights& weights) {
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) throw ValueError(concat("--weights expects NAME=W items, got '", item, "'"));
    const std::string name = item.substr(0, eq);
    auto it = std::find_if(weights.begin(), weights.end(), [&](auto& w) { return w.first == name; });
    if (it == weights.end())
      throw ValueError(concat("unknown guide '", name, "' in --weights (", light_path_guide_names(), ")"));
    it->second = parse_number<float>(item.substr(eq + 1), concat("--weights '", item, "'"));
    start = end + 1;
  }
}

GuideWeights active_guides(const GuideWeights& weights) {
  GuideWeights out;
  std::vector<std::string> seen;
  for (const auto& [name, weight] : weights) {
    if (!is_light_path_guide(name))
      throw ValueError(concat("unknown guide '", name, "' (StyLit guides: ", light_path_guide_names(), ")"));
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw ValueError(concat("guide '", name, "' is weighted twice"));
    if (!std::isfinite(weight)) throw ValueError(concat("weight of guide '", name, "' is not finite"));
    seen.push_back(name);
    if (weight > 0) out.emplace_back(name, weight);
  }
  if (out.empty()) throw ValueError("every guide weight is <= 0; at least one light-path guide must be used");
  return out;
}

std::vector<std::string> active_guide_names(const GuideWeights& weights) {
  std::vector<std::string> names;
  for (const auto& [name, weight] : active_guides(weights)) names.push_back(name);
  return names;
}

Image tonemap_guide(const ImageView& linear) {
  require_nonempty(linear, "light-path guide");
  Image out(linear.width, linear.height, linear.channels);
  const std::size_t n = linear.size();
  for (std::size_t i = 0; i < n; ++i) {
    double x = linear.data[i];
    if (std::isnan(x) || x < 0) x = 0;
    if (std::isinf(x)) x = 1e6;
    out.data()[i] = float(srgb_encode(x / (1.0 + x)));
  }
  return out;
}

}  // namespace tempera
