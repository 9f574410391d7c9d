// Issue 18: bounds that keep hostile input from crashing or exhausting the process.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "tempera/engine/error.hpp"
#include "tempera/tracer/lpe.hpp"
#include "tempera/engine/orientation.hpp"
#include "tempera/engine/parallel.hpp"
#include "tempera/app/paths.hpp"

using namespace tempera;

TEST(Parallel, ThreadCountIsClampedToTheCores) {
  EXPECT_EQ(resolve_threads(100000), hardware_threads());
  EXPECT_EQ(resolve_threads(0), hardware_threads());
  EXPECT_EQ(resolve_threads(1), 1);
}

TEST(Parallel, ThreadsThatCannotStartLeaveTheWorkToTheOthers) {
  if (hardware_threads() < 2) GTEST_SKIP() << "needs two cores to start a worker thread";
  for (int limit : {0, 1}) {
    set_thread_start_limit_for_testing(limit);
    std::vector<std::atomic<int>> done(1000);
    parallel_for(1000, hardware_threads(), [&](int i) { ++done[i]; });  // std::terminate before the fix
    set_thread_start_limit_for_testing(-1);
    for (auto& d : done) EXPECT_EQ(d.load(), 1);
  }
}

TEST(Parallel, ErrorsStillPropagateWhenThreadsFailToStart) {
  set_thread_start_limit_for_testing(0);
  EXPECT_THROW(parallel_for(10, 4, [](int i) {
                 if (i == 5) throw ValueError("five");
               }),
               ValueError);
  set_thread_start_limit_for_testing(-1);
}

TEST(Lpe, LengthDepthAndSizeAreBounded) {
  EXPECT_THROW(compile_lpe(std::string(60000, '(') + "L" + std::string(60000, ')')), ValueError);
  EXPECT_THROW(compile_lpe("L" + std::string(100000, '?')), ValueError);
  EXPECT_THROW(compile_lpe(std::string(65, '(') + "LE" + std::string(65, ')')), ValueError);
  EXPECT_NO_THROW(compile_lpe(std::string(60, '(') + "LE" + std::string(60, ')')));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(compile_lpe("LD{100}{100}{100}E"), ValueError);
  EXPECT_THROW(compile_lpe("L.*D.{20}E"), ValueError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_NO_THROW(compile_lpe("L.*D.{8}E"));
}

TEST(Orientation, SigmaIsValidatedAndTheKernelClamped) {
  Image img(8, 8, 1);
  for (std::size_t i = 0; i < img.pixel_count(); ++i) img.data()[i] = float(i % 7);
  EXPECT_THROW(structure_tensor(img.view(), 1e9f), ValueError);
  EXPECT_THROW(structure_tensor(img.view(), -1.0f), ValueError);
  const float sigma = 1000.0f;
  const Image wide = structure_tensor(img.view(), sigma);  // 6001 taps folded onto 8
  // The unclamped separable blur with replicated borders, tap by tap.
  const Image raw = structure_tensor(img.view(), 0.0f);
  const int r = 3000;
  std::vector<double> k(2 * r + 1);
  double sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[i + r] = std::exp(-0.5 * double(i) * i / (double(sigma) * sigma));
  auto clamp7 = [](int v) { return std::min(std::max(v, 0), 7); };
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 8; y += 7)
      for (int x = 0; x < 8; x += 3) {
        double rows[8] = {};
        for (int yy = 0; yy < 8; ++yy)
          for (int i = -r; i <= r; ++i) rows[yy] += k[i + r] * raw.at(clamp7(x + i), yy, c) / sum;
        double value = 0;
        for (int j = -r; j <= r; ++j) value += k[j + r] * rows[clamp7(y + j)];
        EXPECT_NEAR(wide.at(x, y, c), value / sum, 1e-4 * (std::abs(value / sum) + 1e-3)) << x << "," << y << "," << c;
      }
}

TEST(Paths, SamePathAndOutputOnInput) {
  EXPECT_TRUE(same_path("/tmp/a/../b", "/tmp/b"));
  EXPECT_FALSE(same_path("/tmp/a", "/tmp/b"));
  EXPECT_THROW(refuse_output_on_inputs("/tmp/x.png", {"/tmp/y.png", "/tmp/./x.png"}, "--output"), ValueError);
  EXPECT_THROW(refuse_output_on_inputs("/tmp/x.exr", {"/tmp/x.exr:FULL"}, "--output"), ValueError);
  EXPECT_NO_THROW(refuse_output_on_inputs("/tmp/x.png", {"/tmp/y.png", ""}, "--output"));
}
