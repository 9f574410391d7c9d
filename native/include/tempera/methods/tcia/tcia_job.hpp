#pragma once
// The coherent method (Bénard et al. 2013, tcia.hpp) as a job over a guide
// cache: `tempera stylize --method tcia` and the Blender panel. The shot is
// always solved as independent segments bounded by consecutive painted keys
// (and the shot's ends), each segment knowing only its bounding keys (§4.1).
// So a farm that runs one segment per machine gets, by construction, what
// one machine gets. Segments are the unit of resume: all frames of a
// segment are written atomically, then a record with the segment's key and
// the files' checksums (OUT/tempera_tcia/segment_A-B.txt); a rerun skips
// segments whose record still matches.
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "tempera/app/segments.hpp"
#include "tempera/app/light_path_guides.hpp"
#include "tempera/app/light_path_shot.hpp"
#include "tempera/app/scratch_images.hpp"
#include "tempera/app/segment_job.hpp"
#include "tempera/methods/tcia/tcia.hpp"

namespace tempera {

// A painted keyframe on disk: the painting (the frame's size) and an
// optional mask (first channel > 0.5 = painted) for a partial key.
struct KeyFile {
  int frame = 0;
  std::string painting, mask;
};

// "12=key.png" or "12=key.png,mask.png" (the CLI's --key); ValueError naming the text.
KeyFile parse_key(const std::string& text);

// A layer (tcia_layers.hpp) of the job: its name (a folder name), the
// guide cache's mask of its object or collection ("mask.CO_Suit") and its
// own painting over the shared exemplar render (empty = the shared one).
// When the exemplar's guide cache has the same mask (covering at least a
// patch's area), the layer's matches come only from there (§4).
// A layer may have keys of its own (§4: each layer painted apart): at its
// key frames they replace the shot's keys for that layer, so the layer's
// pixels of the composite come out as its painting. Segments split at
// every key, the shot's and the layers'.
struct LayerFile {
  std::string name, mask, painting;
  std::vector<KeyFile> keys;
};

// "suit=mask.CO_Suit" or "suit=mask.CO_Suit,suit.png" (the CLI's --layer); ValueError naming the text.
LayerFile parse_layer(const std::string& text);

// "suit:12=key.png[,mask.png]" (the CLI's --layer-key): the layer's name and its key; ValueError naming the text.
std::pair<std::string, KeyFile> parse_layer_key(const std::string& text);

// Adds each (layer name, key) to its layer; ValueError naming a layer that is not given.
void add_layer_keys(std::vector<LayerFile>& layers, const std::vector<std::pair<std::string, KeyFile>>& keys);

// The distance-transform term for line exemplars (eq. 9): one more guide
// pair, D(S) of the painting's ink against the guide cache's line_distance
// D(I), so that ink goes where the frame has lines.
struct TciaLineOptions {
  float weight = 0;    // w_dt; 0 = off
  float d_max = 10;    // must be the guide cache's Line Distance Max
  float ink = 0.5f;    // luminance below which a painting pixel is ink
};

inline const auto& tcia_line_option_table() {
  using T = TciaLineOptions;
  static const auto table = std::make_tuple(
      field(&T::weight, "weight", "lines",
            "w_dt of eq. 9: ink of a line painting goes to the frame's lines (guide cache line_distance); "
            "0 = off, 4 typical", 0, 1e6),
      field(&T::d_max, "d_max", "line-d-max", "d_max of D(S), the guide cache's Line Distance Max (10)", 0.1, 1e6),
      field(&T::ink, "ink", "ink", "luminance below which a painting pixel is ink (0.5)", 0, 1));
  return table;
}

// Orientation (§3.1) from the guide cache: each frame's and the exemplar's
// `tensor` guide (the structure tensor of the render, or of the artist's
// orientation AOV when the cache was rendered with one) gives O(I_t) and
// O(S), so patches are compared rotated and hatching follows the frame.
struct TciaOrientationOptions {
  bool from_cache = false;
};

inline const auto& tcia_orientation_option_table() {
  using T = TciaOrientationOptions;
  static const auto table = std::make_tuple(field(
      &T::from_cache, "from_cache", "orientation",
      "patches turn with the guide cache's orientation (its tensor: the render's structure or the artist's "
      "orientation AOV), so strokes follow the surfaces (off)"));
  return table;
}

// The painting, the guide caches, the frames (consecutive) and the output
// folder as StyLit's (LightPathShotConfig), the light-path guides' weights,
// and the coherent method's own.
struct TciaJobConfig : LightPathShotConfig {
  GuideWeights weights = default_guide_weights();
  std::vector<KeyFile> keys;
  TciaOptions tcia = default_tcia_options();
  TciaLineOptions lines;
  // Layers solved separately and composited (none: the frame as one layer).
  // Each writes its frames, RGBA with the mask as alpha, to
  // OUT/layers/NAME/; the frames are their composite, back to front in
  // `layer_order`: "depth" (per frame, the guide cache's depth) or "given".
  std::vector<LayerFile> layers;
  std::string layer_order = "depth";
  // Only the segment from frame A to B (a farm task): only its guide frames
  // and bounding keys are read. ValueError listing the shot's segments if
  // A-B is not one.
  std::optional<std::pair<int, int>> segment;
  TciaOrientationOptions orientation;
};

// The format line of a segment's and a layer's resume record (app/record.hpp).
inline constexpr const char* kTciaRecordFormat = "tempera-tcia-segment 1";

struct SegmentResult {
  std::string status;  // "stylized" | "skipped"
  double seconds = 0;
};

// Where a segment's sweeps are: SweepProgress with the frame as a frame number.
using SegmentProgress = std::function<bool(const SweepProgress&)>;

class TciaJob : public SegmentJob {
 public:
  // Validates everything up front (files, guides, keys, sizes).
  explicit TciaJob(TciaJobConfig config);

  const std::vector<Segment>& segments() const override { return segments_; }
  // The indices of the segments to run: all, or the one of config.segment.
  const std::vector<std::size_t>& selected() const override { return selected_; }
  bool whole_shot() const override { return !config_.segment; }
  // The painting, the exemplar's guides, the shot's frames (those read) and the outputs' names.
  const LightPathShot& shot() const { return shot_; }
  const JobInputs& inputs() const override { return shot_.inputs(); }
  std::string output_path(int frame) const { return shot_.output_path(frame); }
  const std::vector<std::string>& warnings() const override { return warnings_; }
  void write_contact_sheet(const std::string& path, int columns = 0) const override {
    shot_.write_contact_sheet(path, columns);
  }
  std::string record_path(std::size_t index) const;
  // Layer `layer`'s frame (OUT/layers/NAME/frame_0001.png) and its record for segment `index`.
  std::string layer_path(std::size_t layer, int frame) const;
  std::string layer_record_path(std::size_t index, std::size_t layer) const;

  // Solves segment `index` (one of selected()) (or skips it when its record is current) and
  // writes its frames. `progress` returning false cancels: CancelledError,
  // nothing written.
  SegmentResult run_segment(std::size_t index, const SegmentProgress& progress = {});
  // run_segment for the job core: a stage is a finished sweep.
  FrameResult run_unit(std::size_t index, const StageProgress& progress = {}) override;

 private:
  std::string segment_key(const Segment& segment) const;
  bool is_current(std::size_t index) const;
  Shot load_shot(const Segment& segment, std::deque<Image>& keep, ScratchImages& frame_inputs) const;
  std::string composite_key(const Segment& segment) const;  // segment_key and the layers
  std::string layer_key(const Segment& segment, std::size_t layer) const;

  // Layers (tcia_job_layers.cpp): checked up front; each solved (or skipped
  // when its record is current) and written, then composited from the files.
  void check_layers();
  Image exemplar_mask(const LayerFile& layer) const;
  std::vector<Image> run_layers(std::size_t index, const Shot& shot, const SweepCallback& sweeps);

  void refuse_writing_on_keys() const;
  static TciaJobConfig checked(TciaJobConfig config);  // frames consecutive, keys sorted and in the shot
  bool is_read(int frame) const;                       // in the frames this job reads
  // Each key's painting and mask (empty outside the frames read, and for a whole key).
  void read_keys(const std::vector<KeyFile>& keys, std::vector<Image>& paintings, std::vector<Image>& masks) const;

  TciaJobConfig config_;
  std::vector<Segment> segments_;
  std::vector<std::size_t> selected_;
  std::vector<std::string> warnings_;  // a resampled painting
  LightPathShot shot_;  // the per-frame inputs of the frames read, the outputs' names, the contact sheet
  std::vector<Image> paintings_, masks_;  // per key (masks_ empty for a whole key)
  std::vector<Image> layer_paintings_;    // per layer (empty: the shared painting)
  std::vector<Image> layer_style_masks_;  // per layer: its part of the exemplar (empty: all of it)
  std::vector<std::vector<Image>> layer_key_paintings_, layer_key_masks_;  // per layer, per own key
  Shot with_layer_keys(const Shot& shot, const Segment& segment, std::size_t layer) const;
  std::string settings_;
};

}  // namespace tempera
