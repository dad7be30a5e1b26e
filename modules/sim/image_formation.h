// The renderer's image formation (image_renderer.h, used by RenderDots only): the per-pixel supersample
// masks of all dots -> grey levels -> Gaussian blur -> Gaussian noise -> rounding to [0, 255], on frame
// buffers kept per thread.
//
// Speed without changing the image. Away from the dots' pixel boxes the grey level is the background
// and the blur of a constant is one number (the same terms in the same order as at any other pixel), so
// only the boxes, widened by the blur's radius, are blurred pixel by pixel; every other pixel takes that
// constant. The noise is drawn for every pixel in row-major order.
#pragma once

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
// plus options.noise_std_grey * a standard normal deviate (std::normal_distribution on
// std::mt19937_64 seeded with noise_seed) per pixel in row-major order, rounded and clamped.
// Uses frame->rows and frame->blurred when blurring.
void FormImage(FrameBuffers* frame, const RenderOptions& options, uint64_t noise_seed, vpImage<unsigned char>* image);

}  // namespace selfcal::sim
