// TciaJob's layers (tcia_job.hpp, tcia_layers.hpp): each layer of a segment
// is solved alone, written as RGBA (its frame, its mask as alpha) with a
// record of its own, and the segment's frames are the composite of the
// layers' files. Composing from the files (not from the solver's floats)
// makes a run that resumes some layers equal an uninterrupted one.
#include <algorithm>
#include <filesystem>
#include <numeric>
#include <set>

#include "tempera/engine/error.hpp"
#include "tempera/app/file_keys.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/methods/tcia/tcia_job.hpp"
#include "tempera/app/record.hpp"
#include "tempera/methods/tcia/tcia_layers.hpp"

namespace fs = std::filesystem;

namespace tempera {
namespace {

bool has_guide(const ImageFileInfo& info, const std::string& guide) {
  return std::any_of(info.channel_names.begin(), info.channel_names.end(),
                     [&](const std::string& c) { return c == guide || c.rfind(guide + ".", 0) == 0; });
}

void check_name(const std::string& name) {
  const bool ok = !name.empty() && name != "." && name != ".." && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (!ok)
    throw ValueError(concat("layer name '", name, "' must be letters, digits, '_', '-' or '.' (it names a folder)"));
}

// The first channel of a mask guide as coverage in [0, 1].
Image coverage(const Image& mask) {
  Image out = extract_channels(mask.view(), 0, 1);
  for (std::size_t i = 0; i < out.pixel_count(); ++i) out.data()[i] = std::clamp(out.data()[i], 0.0f, 1.0f);
  return out;
}

Image with_alpha(const ImageView& image, const ImageView& alpha) {
  Image out(image.width, image.height, image.channels + 1);
  for (std::size_t p = 0; p < image.pixel_count(); ++p) {
    std::copy_n(image.data + p * std::size_t(image.channels), image.channels, out.data() + p * std::size_t(out.channels()));
    out.data()[p * std::size_t(out.channels()) + std::size_t(image.channels)] = alpha.data[p];
  }
  return out;
}

}  // namespace

LayerFile parse_layer(const std::string& text) {
  const std::size_t eq = text.find('=');
  const std::string usage = concat("--layer expects NAME=MASK_GUIDE[,PAINTING], got '", text, "'");
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) throw ValueError(usage);
  LayerFile l;
  l.name = text.substr(0, eq);
  const std::string rest = text.substr(eq + 1);
  const std::size_t comma = rest.find(',');
  l.mask = rest.substr(0, comma);
  if (comma != std::string::npos) l.painting = rest.substr(comma + 1);
  if (l.mask.empty() || (comma != std::string::npos && l.painting.empty())) throw ValueError(usage);
  check_name(l.name);
  return l;
}

std::pair<std::string, KeyFile> parse_layer_key(const std::string& text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0)
    throw ValueError(concat("--layer-key expects NAME:FRAME=PAINTING[,MASK], got '", text, "'"));
  return {text.substr(0, colon), parse_key(text.substr(colon + 1))};
}

void add_layer_keys(std::vector<LayerFile>& layers, const std::vector<std::pair<std::string, KeyFile>>& keys) {
  for (const auto& [name, key] : keys) {
    auto layer = std::find_if(layers.begin(), layers.end(), [&](const LayerFile& l) { return l.name == name; });
    if (layer == layers.end())
      throw ValueError(concat("--layer-key names layer '", name, "', which no --layer gives"));
    layer->keys.push_back(key);
  }
}

std::string TciaJob::layer_path(std::size_t layer, int frame) const {
  return (fs::path(config_.out) / "layers" / config_.layers.at(layer).name /
          fs::path(shot_.output_path(frame)).filename())
      .string();
}

std::string TciaJob::layer_record_path(std::size_t index, std::size_t layer) const {
  const Segment& s = segments_.at(index);
  return (fs::path(config_.out) / "tempera_tcia" /
          concat("segment_", s.first, "-", s.last, ".layer_", config_.layers.at(layer).name, ".txt"))
      .string();
}

// What one layer's frames depend on: the segment's inputs, its mask guide,
// its painting and its own keys at the segment's bounds.
std::string TciaJob::layer_key(const Segment& segment, std::size_t layer) const {
  const LayerFile& l = config_.layers[layer];
  std::string text = concat(segment_key(segment), "\nlayer ", l.name, " ", l.mask, " ",
                            l.painting.empty() ? "shared" : file_stamp(l.painting));
  for (const KeyFile& k : l.keys)
    if (k.frame == segment.first || k.frame == segment.last)
      text += concat("\nkey ", k.frame, " ", file_stamp(k.painting), " ", k.mask.empty() ? "" : file_stamp(k.mask));
  return hash_hex(text);
}

// The segment's shot with the layer's own keys in place of the shot's at their frames.
Shot TciaJob::with_layer_keys(const Shot& shot, const Segment& segment, std::size_t layer) const {
  const LayerFile& l = config_.layers[layer];
  Shot out = shot;
  for (std::size_t k = 0; k < l.keys.size(); ++k) {
    const int f = l.keys[k].frame;
    if (f != segment.first && f != segment.last) continue;
    const int t = f - segment.first;
    out.keys.erase(std::remove_if(out.keys.begin(), out.keys.end(), [&](const ShotKey& s) { return s.frame == t; }),
                   out.keys.end());
    out.keys.push_back(ShotKey{t, layer_key_paintings_[layer][k].view(), layer_key_masks_[layer][k].view()});
  }
  std::sort(out.keys.begin(), out.keys.end(), [](const ShotKey& a, const ShotKey& b) { return a.frame < b.frame; });
  return out;
}

// The layer's part of the exemplar render: its mask guide in the exemplar's
// cache, if there and covering at least a patch's area; else empty (the whole exemplar).
Image TciaJob::exemplar_mask(const LayerFile& l) const {
  const std::string path = shot_.exemplar_path();
  if (!has_guide(inspect_image(path), l.mask)) return {};
  const Image& style = shot_.style();
  Image m = pick_resize(coverage(GuideFrame::read(path, {l.mask}).get(l.mask)).view(), style.width(), style.height());
  const int patch = config_.tcia.synthesis.patch_size;
  const auto inside = std::count_if(m.data(), m.data() + m.pixel_count(), [](float v) { return v > 0.5f; });
  return inside >= patch * patch ? m : Image{};
}

void TciaJob::check_layers() {
  std::set<std::string> names;
  for (const LayerFile& l : config_.layers) {
    check_name(l.name);
    if (!names.insert(l.name).second) throw ValueError(concat("layer '", l.name, "' is given twice"));
    layer_style_masks_.push_back(exemplar_mask(l));
    layer_paintings_.emplace_back();
    if (l.painting.empty()) continue;
    std::error_code ec;
    if (!fs::is_regular_file(l.painting, ec))
      throw FileNotFoundError(concat("painting of layer '", l.name, "' not found: '", l.painting, "'"));
    Image p = read_image(l.painting);
    require_finite(p.view(), concat("the painting of layer '", l.name, "'"));
    const Image& style = shot_.style();
    if (p.width() != style.width() || p.height() != style.height() || p.channels() < style.channels())
      throw ValueError(concat("the painting of layer '", l.name, "' '", l.painting, "' is ", p.width(), "x",
                              p.height(), "x", p.channels(), " but the shared painting is ", style.width(), "x",
                              style.height(), "x", style.channels(), " (paint it over the same exemplar render)"));
    layer_paintings_.back() = p.channels() == style.channels() ? std::move(p) : extract_channels(p.view(), 0, style.channels());
  }
  if (config_.layers.empty()) return;
  for (std::size_t i : selected_)
    for (int f = segments_[i].first; f <= segments_[i].last; ++f) {
      const std::string path = shot_.target_path(f);
      const ImageFileInfo info = inspect_image(path);
      for (const LayerFile& l : config_.layers)
        if (!has_guide(info, l.mask))
          throw ValueError(concat("layer '", l.name, "' needs the mask '", l.mask, "' in '", path,
                                  "' (render the guides with object or collection masks)"));
      if (config_.layer_order == "depth" && !has_guide(info, "depth"))
        throw ValueError(concat("layers composited by depth need 'depth' in '", path, "' (or --layer-order given)"));
    }
}

std::vector<Image> TciaJob::run_layers(std::size_t index, const Shot& shot, const SweepCallback& sweeps) {
  const Segment& segment = segments_[index];
  const std::size_t n = config_.layers.size();
  std::vector<std::string> wanted;
  for (const LayerFile& l : config_.layers) wanted.push_back(l.mask);
  if (config_.layer_order == "depth") wanted.push_back("depth");
  // Held through the segment and read now and then, like the shot's inputs:
  // where the kernel can page them out (scratch_images.hpp).
  ScratchImages per_frame(config_.out);
  std::vector<std::vector<ImageView>> masks(n);  // per layer, per frame of the segment
  std::vector<ImageView> depths;
  for (int f = segment.first; f <= segment.last; ++f) {
    const GuideFrame g = GuideFrame::read(shot_.target_path(f), wanted);
    for (std::size_t l = 0; l < n; ++l) masks[l].push_back(per_frame.add(coverage(g.get(config_.layers[l].mask))));
    if (config_.layer_order == "depth") depths.push_back(per_frame.add(extract_channels(g.get("depth").view(), 0, 1)));
  }
  for (std::size_t l = 0; l < n; ++l) {
    std::vector<std::string> files;
    for (int f : segment.writes) files.push_back(layer_path(l, f));
    if (config_.resume &&
        record_current(layer_record_path(index, l), kTciaRecordFormat, layer_key(segment, l), files))
      continue;
    ShotLayer layer{config_.layers[l].name, masks[l], layer_paintings_[l].view(), layer_style_masks_[l].view()};
    ScratchImages layer_inputs(config_.out);  // the layer's own guides and motion, freed with the layer
    SweepCallback progress;
    if (sweeps)
      progress = [&](const SweepProgress& p) {
        SweepProgress here = p;
        here.fraction = (double(l) + p.fraction) / double(n);
        return sweeps(here);
      };
    const Shot own = with_layer_keys(shot, segment, l);
    const Shot layered = layer_shot(own, layer, [&](Image&& image) { return layer_inputs.add(image); });
    const std::vector<Image> images = stylize_shot_sweeps(layered, config_.tcia, progress);
    std::error_code ec;
    fs::create_directories(fs::path(files.front()).parent_path(), ec);
    for (std::size_t i = 0; i < files.size(); ++i) {
      const std::size_t t = std::size_t(segment.writes[i] - segment.first);
      write_image(files[i], with_alpha(images[t].view(), masks[l][t]).view());  // atomic
    }
    write_record(layer_record_path(index, l), kTciaRecordFormat, layer_key(segment, l), files);
  }
  // The composite, from the layers' files.
  std::vector<Image> out(std::size_t(segment.last - segment.first + 1));
  const int c = shot.style.channels;
  for (int f : segment.writes) {
    const std::size_t t = std::size_t(f - segment.first);
    std::vector<Image> colour, alpha;
    for (std::size_t l = 0; l < n; ++l) {
      const Image rgba = read_image(layer_path(l, f));
      if (rgba.channels() != c + 1)
        throw ValueError(concat("the layer file '", layer_path(l, f), "' has ", rgba.channels(), " channels, not ", c + 1));
      colour.push_back(extract_channels(rgba.view(), 0, c));
      alpha.push_back(extract_channels(rgba.view(), c, 1));
    }
    std::vector<ImageView> colours, alphas;
    for (std::size_t l = 0; l < n; ++l) colours.push_back(colour[l].view()), alphas.push_back(alpha[l].view());
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    if (config_.layer_order == "depth") order = depth_order(depths[t], alphas);
    out[t] = composite_layers(colours, alphas, order);
  }
  return out;
}

}  // namespace tempera
