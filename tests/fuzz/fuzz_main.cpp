// tempera_fuzz: the native entry points on random and mutated inputs, for a
// bounded time (issue 18). Built with the sanitizers by `make fuzz`
// (build-asan), so that any out-of-bounds access, overflow or leak aborts
// with a report; in the normal build ctest runs it briefly as a smoke test.
//
//   tempera_fuzz [--seconds S] [--seed N] [--only TARGET] [--work DIR]
//
// Targets: image (decoding PNG, JPEG, TIFF, EXR bytes), cache (multilayer
// guide-cache EXR read by layer and as a GuideFrame), lpe (the light path
// expression compiler), sidecar (the stylize resume record), options (the
// option and frame-range parsing of every method's command: synth, stylize
// with each --method, noisy, render-guides). tests/fuzz/fuzz_rigid.py runs the
// rigid-body method's whole command on mutated tracks.json, manifests and
// options. Every input must either work or be
// refused with one of Tempera's error types; anything else is a finding and
// the exit status is 1. Each finding's input is saved in the work folder.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "commands.hpp"
#include "tempera/engine/error.hpp"
#include "tempera/app/image_io.hpp"
#include "tempera/tracer/lpe.hpp"
#include "tempera/methods/stylit/stylit.hpp"
#include "tempera/methods/stylit/stylize_job.hpp"

namespace fs = std::filesystem;
using namespace tempera;
using Bytes = std::string;
using FuzzRng = std::mt19937_64;

namespace {

fs::path g_work;
int g_findings = 0;

Bytes read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const fs::path& path, const Bytes& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), std::streamsize(data.size()));
}

std::size_t below(FuzzRng& rng, std::size_t n) { return n ? std::size_t(rng() % n) : 0; }

// The usual byte-level mutations: flips, random bytes, interesting values,
// truncation, duplication, deletion and splicing of ranges.
Bytes mutate(FuzzRng& rng, Bytes data, const std::vector<Bytes>& corpus) {
  const int rounds = 1 + int(below(rng, 8));
  for (int r = 0; r < rounds; ++r) {
    if (data.empty()) data.push_back(char(rng()));
    const std::size_t at = below(rng, data.size());
    switch (below(rng, 9)) {
      case 0: data[at] = char(data[at] ^ (1 << below(rng, 8))); break;
      case 1: data[at] = char(rng()); break;
      case 2: {
        static const unsigned char interesting[] = {0, 1, 0x7f, 0x80, 0xff, 0xfe, 16, 32, 64, 100};
        data[at] = char(interesting[below(rng, sizeof interesting)]);
        break;
      }
      case 3: {  // a 32-bit field set to an extreme: sizes, offsets, counts
        static const std::uint32_t extremes[] = {0u, 1u, 0x7fffffffu, 0x80000000u, 0xffffffffu, 65535u, 12000u};
        const std::uint32_t v = extremes[below(rng, 7)];
        for (int k = 0; k < 4 && at + k < data.size(); ++k) data[at + k] = char(v >> (8 * (rng() % 2 ? k : 3 - k)));
        break;
      }
      case 4: data.resize(at); break;
      case 5: data.insert(at, data.substr(below(rng, data.size()), below(rng, 64))); break;
      case 6: data.erase(at, below(rng, 64)); break;
      case 7:
        if (!corpus.empty()) {
          const Bytes& other = corpus[below(rng, corpus.size())];
          if (!other.empty()) data.insert(at, other.substr(below(rng, other.size()), below(rng, 256)));
        }
        break;
      default: data.insert(at, 1, char(rng())); break;
    }
  }
  return data;
}

// Runs `body` on one input: Tempera's errors are fine, anything else is a finding.
void attempt(const char* target, const Bytes& input, const std::function<void()>& body) {
  try {
    body();
  } catch (const ValueError&) {
  } catch (const IoError&) {
  } catch (const CancelledError&) {
  } catch (const std::bad_alloc&) {
    std::cout << "tempera_fuzz: " << target << ": out of memory on an input (no size limit held)\n";
    ++g_findings;
  } catch (const std::exception& e) {
    const fs::path saved = g_work / concat("finding_", target, "_", g_findings, ".bin");
    write_bytes(saved, input);
    std::cout << "tempera_fuzz: " << target << ": unexpected " << typeid(e).name() << ": " << e.what()
              << " (input saved as " << saved << ")\n";
    ++g_findings;
  }
}

// Sends stderr (fd 2) to /dev/null while alive; findings are printed on stdout.
struct Quiet {
  int saved = dup(2);
  Quiet() {
    std::fflush(stderr);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 2);
    close(null);
  }
  ~Quiet() {
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
  }
};

Image test_image(int w, int h, int c) {
  Image img(w, h, c);
  for (std::size_t i = 0; i < img.pixel_count() * std::size_t(c); ++i) img.data()[i] = float((i * 37) % 101) / 100.0f;
  return img;
}

// ---------------------------------------------------------------------------- targets

void fuzz_images(FuzzRng& rng, const std::function<bool()>& more) {
  std::vector<Bytes> corpus;
  for (const char* ext : {"png", "jpg", "tif", "exr"}) {
    const fs::path seed = g_work / concat("seed.", ext);
    write_image(seed.string(), test_image(9, 7, 3).view());
    corpus.push_back(read_bytes(seed));
  }
  const char* exts[] = {"png", "jpg", "tif", "exr"};
  while (more()) {
    const std::size_t k = below(rng, corpus.size());
    const Bytes input = mutate(rng, corpus[k], corpus);
    const fs::path path = g_work / concat("input.", exts[k]);
    write_bytes(path, input);
    attempt("image", input, [&] {
      Quiet quiet;  // libpng and libjpeg complain about every damaged file on stderr
      const ImageFileInfo info = inspect_image(path.string());
      (void)info;
      const Image img = read_image(path.string());
      if (img.width() <= 0 || img.height() <= 0) throw std::logic_error("empty image returned");
    });
  }
}

const std::vector<std::string> kCacheGuides = {"FULL", "LDE", "LSE", "LDDE", "velocity_backward"};

std::vector<std::string> cache_channels() {
  std::vector<std::string> names;
  for (const auto& g : kCacheGuides)
    for (const char* c : g == "velocity_backward" ? std::vector<const char*>{"X", "Y"}
                                                 : std::vector<const char*>{"R", "G", "B"})
      names.push_back(g + "." + c);
  return names;
}

void fuzz_cache(FuzzRng& rng, const std::function<bool()>& more) {
  const auto names = cache_channels();
  const fs::path seed = g_work / "frame_0001.exr";
  write_image(seed.string(), test_image(8, 6, int(names.size())).view(), names);
  const std::vector<Bytes> corpus = {read_bytes(seed)};
  const fs::path path = g_work / "cache" / "frame_0001.exr";
  fs::create_directories(path.parent_path());
  while (more()) {
    const Bytes input = mutate(rng, corpus[0], corpus);
    write_bytes(path, input);
    attempt("cache", input, [&] {
      const GuideFrame frame = GuideFrame::read(path.string(), {"FULL", "LDE", "velocity_backward"});
      (void)frame.get("LDE");
      (void)read_image_layer(path.string(), kCacheGuides[below(rng, kCacheGuides.size())]);
    });
  }
}

void fuzz_lpe(FuzzRng& rng, const std::function<bool()>& more) {
  const std::vector<Bytes> corpus = {"L.*E", "LDE", "L.*DDE", "LD{1,2}E", "LS+DE", "L[^D]*E", "L(D|S){0,3}E",
                                     "L[DS]?T*E", "LD{2,}E", "(L)(D)(E)"};
  const std::string alphabet = "LDSGTE.*+?{},0123456789[]^|()x ";
  while (more()) {
    Bytes input;
    if (rng() % 3 == 0) {
      const std::size_t n = below(rng, 40);
      for (std::size_t i = 0; i < n; ++i) input += alphabet[below(rng, alphabet.size())];
    } else {
      input = mutate(rng, corpus[below(rng, corpus.size())], corpus);
    }
    attempt("lpe", input, [&] {
      for (auto order : {LpeOrder::light_to_eye, LpeOrder::eye_to_light}) {
        const LpeDfa dfa = compile_lpe(input, order);
        (void)lpe_can_match(dfa);
        (void)lpe_matches(dfa, "LDDSE");
      }
    });
  }
}

void fuzz_sidecar(FuzzRng& rng, const std::function<bool()>& more) {
  // A one-frame job on tiny images; its record is then mutated before each run.
  const fs::path root = g_work / "job";
  fs::create_directories(root / "exemplar");
  fs::create_directories(root / "guides");
  const auto names = cache_channels();
  write_image((root / "exemplar" / "frame_0001.exr").string(), test_image(12, 10, int(names.size())).view(), names);
  write_image((root / "guides" / "frame_0001.exr").string(), test_image(12, 10, int(names.size())).view(), names);
  write_image((root / "paint.png").string(), test_image(12, 10, 3).view());
  StylizeJobConfig config;
  config.exemplar = (root / "paint.png").string();
  config.exemplar_guides = (root / "exemplar").string();
  config.guides = (root / "guides").string();
  config.frames = {1};
  config.out = (root / "out").string();
  config.stylit.quality = Quality::Preview;
  config.stylit.synthesis.threads = 1;
  StylizeJob(config).run_frame(0);
  const fs::path record = root / "out" / "tempera_stylize.json";
  const std::vector<Bytes> corpus = {read_bytes(record)};
  while (more()) {
    const Bytes input = mutate(rng, corpus[0], corpus);
    write_bytes(record, input);
    attempt("sidecar", input, [&] {
      StylizeJob job(config);
      const FrameResult r = job.run_frame(0);
      if (r.status != "stylized" && r.status != "skipped") throw std::logic_error("bad status " + r.status);
    });
    for (const auto& entry : fs::directory_iterator(root / "out"))  // keep the folder small
      if (entry.path().filename().string().find(".corrupt-") != std::string::npos) fs::remove(entry.path());
  }
}

// One command line of a method: its entry point and the words before the options.
struct MethodCommand {
  const char* name;
  std::function<int(const cli::Args&)> run;
  cli::Args prefix;
};

const std::vector<MethodCommand>& method_commands() {
  static const std::vector<MethodCommand> commands = {
      {"synth", cli::run_synth, {}},
      {"stylize", cli::run_stylize, {}},
      {"stylize --method tcia", cli::run_stylize, {"--method", "tcia"}},
      {"stylize --method lazyfluids", cli::run_stylize, {"--method", "lazyfluids"}},
      {"stylize --method fluidymation", cli::run_stylize, {"--method", "fluidymation"}},
      {"noisy", cli::commands().at("noisy").run, {}},  // registered by its method's folder
      {"render-guides", cli::run_render_guides, {}},
  };
  return commands;
}

// Every flag a command's --help names, so that a new option is fuzzed as soon as it is documented.
std::vector<std::string> documented_flags(const MethodCommand& command) {
  cli::Args args = command.prefix;
  args.push_back("--help");
  std::ostringstream help;
  std::streambuf* out = std::cout.rdbuf(help.rdbuf());
  command.run(args);
  std::cout.rdbuf(out);
  std::vector<std::string> flags;
  const std::regex flag("--[a-z][a-z0-9-]*");
  const std::string text = help.str();
  for (auto it = std::sregex_iterator(text.begin(), text.end(), flag); it != std::sregex_iterator(); ++it)
    if (it->str() != "--help" && std::find(flags.begin(), flags.end(), it->str()) == flags.end())
      flags.push_back(it->str());  // --help only prints
  return flags;
}

// Option parsing of every method's command (issue 31): random lines of the
// command's documented flags and of awkward values. Nothing may run: the
// current folder is empty, every path given is missing and Blender cannot
// be found, so each line ends in a usage error or a missing file.
void fuzz_options(FuzzRng& rng, const std::function<bool()>& more) {
  const std::vector<std::string> values = {
      "1-24", "1-10,15", "FULL=1,LDE=2", "LDE=", "=3", "0.5", "nan", "-nan", "inf", "1e40", "-1e-40", "4", "-1",
      "0", "18446744073709551616", "100000", "exr", "png", "preview", "budget", "99999", "2147483648", "-5",
      "stylit", "tcia", "lazyfluids", "fluidymation", "rigid", "true", "false", "-", ",", "1-", "-3", "5-1",
      "2147483647", "1048574-1048575", "9999999999", "%s%n", "", "4=key.png,mask.png", "A:4=k.png", "A=m.png",
      "1-4", "0x10", " 3", "3 ", "1,1,1", "3.5", "LDE", "velocity_backward"};
  const std::set<std::string> path_flags = {"--out", "--exemplar", "--guides", "--style", "--output",
                                            "--exemplar-guides", "--exemplar-scene", "--noise-reference",
                                            "--noise-map", "--mask", "--masks", "--key", "--blender"};
  std::vector<std::vector<std::string>> flags;
  for (const auto& command : method_commands()) flags.push_back(documented_flags(command));
  const fs::path cwd = g_work / "empty_cwd";
  fs::create_directories(cwd);
  const fs::path before = fs::current_path();
  fs::current_path(cwd);  // relative paths name nothing
  const char* blender = std::getenv("TEMPERA_BLENDER");
  const std::string saved_blender = blender ? blender : "";
  setenv("TEMPERA_BLENDER", (g_work / "no_blender").c_str(), 1);
  const fs::path missing = g_work / "no_such_dir";
  long usage_errors = 0, file_errors = 0, done = 0;  // how far the lines got: a harness that only
                                                     // ever reached the first usage error tests little
  while (more()) {
    const std::size_t which = below(rng, method_commands().size());
    const MethodCommand& command = method_commands()[which];
    cli::Args args = command.prefix;
    const std::size_t n = below(rng, 16);
    for (std::size_t i = 0; i < n; ++i) {
      const bool flag = rng() % 2 == 0 && !flags[which].empty();
      std::string w = flag ? flags[which][below(rng, flags[which].size())] : values[below(rng, values.size())];
      if (rng() % 6 == 0) w = mutate(rng, w, {});
      if (!w.empty() && w[0] == '/') w[0] = 'x';  // no absolute path to an existing file
      args.push_back(w);
      if (path_flags.count(w)) args.push_back((missing / concat("p", i)).string());
    }
    Bytes input = concat(command.name, "\n");
    for (const auto& a : args) input += a + '\n';
    attempt("options", input, [&] { (void)cli::parse_frames(args.empty() ? "" : args.back()); });
    const std::int64_t cap = max_image_pixels();
    std::streambuf* out = std::cout.rdbuf(nullptr);  // help texts are not findings
    attempt("options", input, [&] {
      Quiet quiet;
      try {
        (void)command.run(args);
        ++done;
      } catch (const ValueError&) {
        ++usage_errors;
        throw;
      } catch (const IoError&) {
        ++file_errors;
        throw;
      }
    });
    std::cout.rdbuf(out);
    if (max_image_pixels() != cap) set_max_image_pixels(cap);
  }
  std::cout << "tempera_fuzz: options: " << usage_errors << " usage errors, " << file_errors
            << " missing files, " << done << " returned\n";
  fs::current_path(before);
  if (blender) setenv("TEMPERA_BLENDER", saved_blender.c_str(), 1);
  else unsetenv("TEMPERA_BLENDER");
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10;
  std::uint64_t seed = 1;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) seconds = std::atof(argv[++i]);
    else if (a == "--seed" && i + 1 < argc) seed = std::strtoull(argv[++i], nullptr, 10);
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (a == "--work" && i + 1 < argc) g_work = argv[++i];
    else {
      std::cerr << "usage: tempera_fuzz [--seconds S] [--seed N] [--only image|cache|lpe|sidecar|options] "
                   "[--work DIR]\n";
      return 2;
    }
  }
  const bool own_work = g_work.empty();
  if (own_work) g_work = fs::temp_directory_path() / concat("tempera-fuzz-", getpid());
  fs::create_directories(g_work);
  const std::vector<std::pair<const char*, void (*)(FuzzRng&, const std::function<bool()>&)>> targets = {
      {"image", fuzz_images}, {"cache", fuzz_cache}, {"lpe", fuzz_lpe}, {"sidecar", fuzz_sidecar},
      {"options", fuzz_options}};
  const double each = only.empty() ? seconds / double(targets.size()) : seconds;
  for (const auto& [name, fn] : targets) {
    if (!only.empty() && only != name) continue;
    FuzzRng rng(seed);
    long runs = 0;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(each);
    fn(rng, [&] { return ++runs, std::chrono::steady_clock::now() < end; });
    std::cout << "tempera_fuzz: " << name << ": " << runs - 1 << " inputs in " << each << " s\n" << std::flush;
  }
  if (own_work && g_findings == 0) fs::remove_all(g_work);
  std::cout << "tempera_fuzz: " << g_findings << " finding(s)" << (g_findings ? concat(" (inputs in ", g_work.string(), ")") : "") << "\n";
  return g_findings ? 1 : 0;
}
