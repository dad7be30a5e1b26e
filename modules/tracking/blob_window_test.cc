#include "tracking/blob_window.h"

#include <algorithm>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <visp3/core/vpException.h>

#include "tracking/blob_trace.h"
#include "tracking/tracking_test_util.h"

namespace selfcal::tracking::internal {
namespace {

// The definition, pixel by pixel (the flood fill MeasureBlob used before the run labelling): the window's
// dark pixels; from each seed in turn (the required one, else every pixel of the bbox's top row) an
// 8-connected fill inside the bbox, kept when it spans the bbox exactly; then every other dark pixel and
// its free 8-neighbours become "other".
bool ReferenceWindow(const vpImage<unsigned char>& image, int threshold, const PixelBox& bbox, int margin,
                     const std::pair<int, int>* required_seed, BlobWindow* win) {
  constexpr std::uint8_t kDarkUnassigned = 3;
  const int width = static_cast<int>(image.getWidth()), height = static_cast<int>(image.getHeight());
  win->u0 = std::max(0, bbox.u_min - margin);
  win->v0 = std::max(0, bbox.v_min - margin);
  win->w = std::min(width - 1, bbox.u_max + margin) - win->u0 + 1;
  win->h = std::min(height - 1, bbox.v_max + margin) - win->v0 + 1;
  const int w = win->w;
  std::vector<std::uint8_t>& cells = win->cells;
  cells.assign(static_cast<size_t>(w * win->h), kFree);
  for (int y = 0; y < win->h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (static_cast<int>(image[win->v0 + y][win->u0 + x]) <= threshold) cells[static_cast<size_t>(y * w + x)] = kDarkUnassigned;
    }
  }
  std::vector<std::pair<int, int>> seeds;
  if (required_seed != nullptr) {
    seeds.push_back(*required_seed);
  } else {
    for (int u = bbox.u_min; u <= bbox.u_max; ++u) seeds.emplace_back(u, bbox.v_min);
  }
  const int x0 = bbox.u_min - win->u0, y0 = bbox.v_min - win->v0, x1 = bbox.u_max - win->u0, y1 = bbox.v_max - win->v0;
  bool found = false;
  for (const auto& [seed_u, seed_v] : seeds) {
    const int sx = seed_u - win->u0, sy = seed_v - win->v0;
    if (sx < x0 || sx > x1 || sy < y0 || sy > y1 || cells[static_cast<size_t>(sy * w + sx)] != kDarkUnassigned) continue;
    std::vector<std::pair<int, int>> stack{{sx, sy}}, filled;
    cells[static_cast<size_t>(sy * w + sx)] = kBlob;
    PixelBox span{sx, sy, sx, sy};
    while (!stack.empty()) {
      const auto [x, y] = stack.back();
      stack.pop_back();
      filled.emplace_back(x, y);
      span = PixelBox{std::min(span.u_min, x), std::min(span.v_min, y), std::max(span.u_max, x), std::max(span.v_max, y)};
      for (int ny = std::max(y0, y - 1); ny <= std::min(y1, y + 1); ++ny) {
        for (int nx = std::max(x0, x - 1); nx <= std::min(x1, x + 1); ++nx) {
          if (cells[static_cast<size_t>(ny * w + nx)] != kDarkUnassigned) continue;
          cells[static_cast<size_t>(ny * w + nx)] = kBlob;
          stack.emplace_back(nx, ny);
        }
      }
    }
    if (span == PixelBox{x0, y0, x1, y1}) {
      found = true;
      break;
    }
    for (const auto& [x, y] : filled) cells[static_cast<size_t>(y * w + x)] = kDarkUnassigned;
  }
  if (!found) return false;
  for (int y = 0; y < win->h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (cells[static_cast<size_t>(y * w + x)] != kDarkUnassigned) continue;
      for (int ny = std::max(0, y - 1); ny <= std::min(win->h - 1, y + 1); ++ny) {
        for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx) {
          if (cells[static_cast<size_t>(ny * w + nx)] == kFree) cells[static_cast<size_t>(ny * w + nx)] = kOther;
        }
      }
      cells[static_cast<size_t>(y * w + x)] = kOther;
    }
  }
  return true;
}

// The run labelling gives the definition's cells and blob on the boxes vpDot2 traces (with and without
// the seed the detector requires, every margin 0-4) and on random boxes (mostly no blob spans them).
TEST(BlobWindow, RunLabellingEqualsTheFloodFillDefinition) {
  int found = 0, refused = 0;
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> margin_of(0, 4), coordinate(-3, 130);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const vpImage<unsigned char> image = testing::RandomDarkShapes(seed, 128, 96, 45, seed % 2 == 0 ? 3.0 : 0.0);
    for (int threshold : {50, 110, 170}) {
      std::vector<std::pair<PixelBox, std::pair<int, int>>> cases;  // box, seed
      for (int v = 0; v < 96; v += 2) {
        for (int u = (v / 2) % 2; u < 128; u += 2) {
          if (static_cast<int>(image[v][u]) > threshold) continue;
          try {
            const TracedBlob blob = TrackDarkBlob(image, threshold, Eigen::Vector2d(u, v), 0, 0);
            cases.push_back({blob.bbox, {u, v}});
          } catch (const vpException&) {
          }
        }
      }
      for (int k = 0; k < 300; ++k) {
        const int a = coordinate(rng), b = coordinate(rng), c = coordinate(rng), d = coordinate(rng);
        PixelBox box{std::clamp(std::min(a, b), 0, 127), std::clamp(std::min(c, d) % 96, 0, 95),
                     std::clamp(std::max(a, b), 0, 127), std::clamp(std::max(c, d) % 96, 0, 95)};
        if (box.v_max < box.v_min) std::swap(box.v_min, box.v_max);
        cases.push_back({box, {box.u_min + (box.u_max - box.u_min) / 3, box.v_max}});
      }
      for (const auto& [box, pixel] : cases) {
        for (bool with_seed : {true, false}) {
          const int margin = margin_of(rng);
          const std::pair<int, int>* required = with_seed ? &pixel : nullptr;
          BlobWindow expected, got;
          std::vector<PixelRun> runs;
          const bool reference = ReferenceWindow(image, threshold, box, margin, required, &expected);
          const std::string where = "seed " + std::to_string(seed) + " T " + std::to_string(threshold) + " box " +
                                    std::to_string(box.u_min) + "," + std::to_string(box.v_min) + "-" +
                                    std::to_string(box.u_max) + "," + std::to_string(box.v_max);
          ASSERT_EQ(ClassifyBlobWindow(image, threshold, box, margin, required, &got, &runs), reference) << where;
          if (!reference) {
            ++refused;
            continue;
          }
          ++found;
          ASSERT_EQ(got.u0, expected.u0) << where;
          ASSERT_EQ(got.v0, expected.v0) << where;
          ASSERT_EQ(got.w, expected.w) << where;
          ASSERT_EQ(got.h, expected.h) << where;
          ASSERT_EQ(got.cells, expected.cells) << where;
          std::vector<std::pair<int, int>> run_pixels, blob_pixels;
          for (const PixelRun& run : runs) {
            for (int u = run.u_begin; u <= run.u_end; ++u) run_pixels.emplace_back(run.v, u);
          }
          for (int v = got.v0; v < got.v0 + got.h; ++v) {
            for (int u = got.u0; u < got.u0 + got.w; ++u) {
              if (expected.At(u, v) == kBlob) blob_pixels.emplace_back(v, u);
            }
          }
          ASSERT_EQ(run_pixels, blob_pixels) << where;  // raster order
        }
      }
    }
  }
  EXPECT_GT(found, 5000);
  EXPECT_GT(refused, 3000);
  std::cout << "[ blob window ] " << found << " blobs classified, " << refused << " boxes refused\n";
}

}  // namespace
}  // namespace selfcal::tracking::internal
