// The renderer's image formation (image_renderer.h, used by RenderDots only): the per-pixel supersample
// masks of all dots -> grey levels -> Gaussian blur -> Gaussian noise -> rounding to [0, 255], on frame
// buffers kept per thread, and the seeded Gaussian generator of the noise.
//
// Speed without changing the image. Away from the dots' pixel boxes the grey level is the background
// and the blur of a constant is one number (the same terms in the same order as at any other pixel), so
// only the boxes, widened by the blur's radius, are blurred pixel by pixel; every other pixel takes that
// constant. The noise is drawn for every pixel in row-major order.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <visp3/core/vpImage.h>

#include "sim/image_renderer.h"

namespace selfcal::sim {

// Pixels [i0, i1] x [j0, j1] (columns, rows), inclusive.
struct PixelBox {
  int i0 = 0, i1 = -1, j0 = 0, j1 = -1;
};

// Frame-sized buffers reused from one render to the next on the same thread: a fresh allocation of a
// few megabytes per frame costs more in page faults than the rendering. Between renders `mask` is all
// 0 and `owner` all -1; FrameLease keeps it so.
struct FrameBuffers {
  int width = 0, height = 0;
  std::vector<uint64_t> mask;  // dark supersamples of all dots, one bit each, per pixel
  std::vector<int> owner;      // the last dot that darkened a sample of the pixel, -1 when none
  std::vector<PixelBox> boxes;  // where mask and owner may be set: the dots' pixel boxes
  std::vector<double> rows, blurred;  // the blur's horizontal pass and result
};

// This thread's buffers for a width x height frame, clean; on destruction (also when an exception
// leaves the render) the boxes are cleared again.
class FrameLease {
 public:
  FrameLease(int width, int height);
  ~FrameLease();
  FrameLease(const FrameLease&) = delete;
  FrameLease& operator=(const FrameLease&) = delete;
  FrameBuffers& buffers() { return *buffers_; }

 private:
  FrameBuffers* buffers_;
};

// Grey = background - (background - dot) * coverage, blurred (options.blur_sigma_px, border replicated),
// plus options.noise_std_grey * GaussianNoise(noise_seed) per pixel in row-major order, rounded and
// clamped.
// Uses frame->rows and frame->blurred when blurring.
void FormImage(FrameBuffers* frame, const RenderOptions& options, uint64_t noise_seed, vpImage<unsigned char>* image);

// Standard normal deviates, the same sequence for the same seed (the tables come once from std::exp and
// std::log): SplitMix64
// (Steele, Lea and Flood 2014) for the bits and the ziggurat method (Marsaglia and Tsang 2000, in
// Doornik's 2005 form with 128 layers: the layer from 7 low bits, the uniform from the 53 high bits of
// one 64-bit word). Exact up to the resolution of the 53-bit uniform; about 99 % of the deviates cost
// one word, one multiplication and one comparison.
class GaussianNoise {
 public:
  explicit GaussianNoise(uint64_t seed);
  double Next() {
    double x;
    Fill(&x, 1);
    return x;
  }
  // The next n deviates into out[0..n), the same as n calls of Next. The ziggurat's rectangles inline
  // with the state in a register, the rest out of line.
  void Fill(double* out, size_t n) {
    uint64_t state = state_;
    for (size_t k = 0; k < n; ++k) {
      const uint64_t bits = Mix(state += kGamma);
      const int layer = static_cast<int>(bits & 0x7f);
      const double u = 2 * Unit(bits) - 1;  // [-1, 1)
      if (std::abs(u) < ratio_[layer]) {
        out[k] = u * edge_[layer];
      } else {
        state_ = state;
        out[k] = Edge(layer, u);
        state = state_;
      }
    }
    state_ = state;
  }

 private:
  double Edge(int layer, double u);  // beyond the rectangle: the wedge, or the tail
  static constexpr uint64_t kGamma = 0x9e3779b97f4a7c15ULL;
  static uint64_t Mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  uint64_t Bits() { return Mix(state_ += kGamma); }
  // The 53 high bits as a double in [0, 1) (through int64_t: one conversion instruction).
  static double Unit(uint64_t bits) { return static_cast<double>(static_cast<int64_t>(bits >> 11)) * 0x1.0p-53; }
  double Uniform() { return Unit(Bits()); }
  double Tail(bool negative);

  uint64_t state_;
  const double* edge_;   // the layers' right edges x[0..128], decreasing from x[1] = R to x[128] = 0
  const double* ratio_;  // x[i + 1] / x[i]: the part of layer i wholly under the curve
};

}  // namespace selfcal::sim
