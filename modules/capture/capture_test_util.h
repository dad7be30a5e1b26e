// Helpers shared by capture's tests: a private temporary directory, whole-file access, and synthetic
// grey images with known content.
#pragma once

#include <cstdint>
#include <random>

#include <gtest/gtest.h>
#include <visp3/core/vpImage.h>

#include "support/temp_files.h"

namespace selfcal::capture::testing {

inline constexpr char kTempDirPrefix[] = "selfcal_capture_test";
using TempDir = selfcal::testing::NamedTempDir<kTempDirPrefix>;
using namespace selfcal::testing;  // ReadFile, WriteFile and the other helpers of temp_files.h

// A light background (level 190) with dark squares (level 40) on a grid shifted by `shift_px`, plus
// uniform noise of +-3 grey levels from `seed`: passes the default frame checks, differs per seed.
inline vpImage<unsigned char> TestImage(int width, int height, int shift_px, uint64_t seed) {
  vpImage<unsigned char> image(static_cast<unsigned>(height), static_cast<unsigned>(width));
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> noise(-3, 3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const bool dark = ((u + shift_px) % 16) < 6 && ((v + shift_px) % 16) < 6;
      image[v][u] = static_cast<unsigned char>((dark ? 40 : 190) + noise(rng));
    }
  }
  return image;
}

inline vpImage<unsigned char> Uniform(int width, int height, unsigned char level) {
  return vpImage<unsigned char>(static_cast<unsigned>(height), static_cast<unsigned>(width), level);
}

inline bool SameImage(const vpImage<unsigned char>& a, const vpImage<unsigned char>& b) {
  if (a.getWidth() != b.getWidth() || a.getHeight() != b.getHeight()) return false;
  for (unsigned i = 0; i < a.getSize(); ++i) {
    if (a.bitmap[i] != b.bitmap[i]) return false;
  }
  return true;
}

inline bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace selfcal::capture::testing
