#include "sim/image_formation.h"

#include <algorithm>
#include <cmath>

namespace selfcal::sim {

namespace {

// Ziggurat of Doornik (2005), "An Improved Ziggurat Method to Generate Normal Random Samples": 128
// layers of equal area kV, the base layer's tail beyond kR.
constexpr int kLayers = 128;
constexpr double kR = 3.442619855899;
constexpr double kV = 9.91256303526217e-3;

struct ZigguratTables {
  double x[kLayers + 1];  // the layers' right edges, decreasing from x[1] = kR to x[kLayers] = 0
  double ratio[kLayers];  // x[i + 1] / x[i]: the part of layer i wholly under the curve
};

const ZigguratTables& Tables() {
  static const ZigguratTables tables = [] {
    ZigguratTables t{};
    double f = std::exp(-0.5 * kR * kR);
    t.x[0] = kV / f;  // the base layer's rectangle, as wide as its area with the tail
    t.x[1] = kR;
    t.x[kLayers] = 0;
    for (int i = 2; i < kLayers; ++i) {
      t.x[i] = std::sqrt(-2 * std::log(kV / t.x[i - 1] + f));
      f = std::exp(-0.5 * t.x[i] * t.x[i]);
    }
    for (int i = 0; i < kLayers; ++i) t.ratio[i] = t.x[i + 1] / t.x[i];
    return t;
  }();
  return tables;
}

// Columns [lo, hi] of one row, inclusive.
struct Span {
  int lo, hi;
};

// Per row, the columns of the boxes widened by grow_u, on the rows they cover widened by grow_v, clipped
// to the frame; sorted and disjoint.
std::vector<std::vector<Span>> RowSpans(const std::vector<PixelBox>& boxes, int width, int height, int grow_u,
                                        int grow_v) {
  std::vector<std::vector<Span>> spans(static_cast<size_t>(height));
  for (const PixelBox& b : boxes) {
    if (b.i0 > b.i1 || b.j0 > b.j1) continue;
    const Span span{std::max(0, b.i0 - grow_u), std::min(width - 1, b.i1 + grow_u)};
    for (int v = std::max(0, b.j0 - grow_v); v <= std::min(height - 1, b.j1 + grow_v); ++v) {
      spans[static_cast<size_t>(v)].push_back(span);
    }
  }
  for (std::vector<Span>& row : spans) {
    std::sort(row.begin(), row.end(), [](const Span& a, const Span& b) { return a.lo < b.lo; });
    size_t kept = 0;
    for (const Span& s : row) {
      if (kept > 0 && s.lo <= row[kept - 1].hi + 1) {
        row[kept - 1].hi = std::max(row[kept - 1].hi, s.hi);
      } else {
        row[kept++] = s;
      }
    }
    row.resize(kept);
  }
  return spans;
}

// __builtin_popcountll without the library call (no popcnt instruction in the baseline x86-64).
inline int Popcount(uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ULL);
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
  return static_cast<int>((x * 0x0101010101010101ULL) >> 56);
}

// The grey level of pixel k before blur and noise.
struct Coverage {
  const std::vector<uint64_t>& mask;
  double background, contrast, inv_s2;
  double Grey(size_t k) const {
    double g = background;
    if (mask[k] != 0) g -= contrast * Popcount(mask[k]) * inv_s2;
    return g;
  }
};

// Separable Gaussian blur (sigma px, border replicated) of the coverage's grey levels into
// frame->blurred on `spans` (the boxes widened by the radius both ways); returns the value every other
// pixel has, the blur of the background alone. Every pixel's sums run over the same terms in the same
// order (taps ascending; horizontal, then vertical).
double Blur(const Coverage& coverage, double sigma, FrameBuffers* frame, std::vector<std::vector<Span>>* spans) {
  const int width = frame->width, height = frame->height;
  const int radius = static_cast<int>(std::ceil(4.0 * sigma));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& w : kernel) w /= sum;
  const double* weights = kernel.data() + radius;  // weights[k], k in [-radius, radius]
  double background_rows = 0, background_blurred = 0;
  for (int k = -radius; k <= radius; ++k) background_rows += weights[k] * coverage.background;
  for (int k = -radius; k <= radius; ++k) background_blurred += weights[k] * background_rows;

  // The horizontal pass is read on the boxes widened by the radius along rows and twice the radius
  // down the columns (the vertical pass's taps from the widened boxes): the background's value there,
  // then the pass itself where it differs.
  const size_t size = static_cast<size_t>(width) * height;
  frame->rows.resize(size);
  frame->blurred.resize(size);
  for (const PixelBox& b : frame->boxes) {
    const int lo = std::max(0, b.i0 - radius), hi = std::min(width - 1, b.i1 + radius);
    for (int v = std::max(0, b.j0 - 2 * radius); v <= std::min(height - 1, b.j1 + 2 * radius); ++v) {
      const auto row = frame->rows.begin() + static_cast<std::ptrdiff_t>(v) * width;
      std::fill(row + lo, row + hi + 1, background_rows);
    }
  }
  // Both passes run along rows, the taps outermost, so that the inner loops are over columns (the same
  // sum per pixel, taps ascending).
  std::vector<double> line(static_cast<size_t>(width + 2 * radius)), acc(static_cast<size_t>(width));
  const std::vector<std::vector<Span>> row_spans = RowSpans(frame->boxes, width, height, radius, 0);
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    for (const Span& s : row_spans[static_cast<size_t>(v)]) {
      const int n = s.hi - s.lo + 1;
      // line[x] = grey at column s.lo - radius + x, the border replicated.
      for (int x = 0; x < n + 2 * radius; ++x) {
        line[static_cast<size_t>(x)] = coverage.Grey(row + std::clamp(s.lo - radius + x, 0, width - 1));
      }
      std::fill(acc.begin(), acc.begin() + n, 0.0);
      for (int k = -radius; k <= radius; ++k) {
        const double* in = line.data() + radius + k;
        for (int x = 0; x < n; ++x) acc[static_cast<size_t>(x)] += weights[k] * in[x];
      }
      std::copy(acc.begin(), acc.begin() + n, frame->rows.begin() + static_cast<std::ptrdiff_t>(row + s.lo));
    }
  }
  *spans = RowSpans(frame->boxes, width, height, radius, radius);
  for (int v = 0; v < height; ++v) {
    for (const Span& s : (*spans)[static_cast<size_t>(v)]) {
      const int n = s.hi - s.lo + 1;
      std::fill(acc.begin(), acc.begin() + n, 0.0);
      for (int k = -radius; k <= radius; ++k) {
        const double* in = frame->rows.data() + static_cast<size_t>(std::clamp(v + k, 0, height - 1)) * width + s.lo;
        for (int x = 0; x < n; ++x) acc[static_cast<size_t>(x)] += weights[k] * in[x];
      }
      std::copy(acc.begin(), acc.begin() + n,
                frame->blurred.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(v) * width + s.lo));
    }
  }
  return background_blurred;
}

// std::clamp(std::lround(g), 0, 255) without the library call and without branches: lround rounds
// halves away from zero, and g - trunc(g) is exact, so for g in (0, 255) this is the same integer;
// g <= 0 (or NaN) gives 0 and g >= 255 gives 255 either way.
inline unsigned char RoundToGrey(double g) {
  g = g > 0 ? g : 0;
  g = g < 255 ? g : 255;
  const int whole = static_cast<int>(g);
  return static_cast<unsigned char>(whole + (g - whole >= 0.5));
}

}  // namespace

FrameLease::FrameLease(int width, int height) {
  static thread_local FrameBuffers buffers;
  buffers_ = &buffers;
  if (buffers.width != width || buffers.height != height) {
    const size_t size = static_cast<size_t>(width) * height;
    buffers.width = width;
    buffers.height = height;
    buffers.mask.assign(size, 0);
    buffers.owner.assign(size, -1);
    buffers.rows.clear();
    buffers.blurred.clear();
  }
  buffers.boxes.clear();
}

FrameLease::~FrameLease() {
  FrameBuffers& f = *buffers_;
  for (const PixelBox& b : f.boxes) {
    for (int j = b.j0; j <= b.j1; ++j) {
      const size_t row = static_cast<size_t>(j) * f.width;
      std::fill(f.mask.begin() + static_cast<std::ptrdiff_t>(row + b.i0),
                f.mask.begin() + static_cast<std::ptrdiff_t>(row + b.i1 + 1), 0);
      std::fill(f.owner.begin() + static_cast<std::ptrdiff_t>(row + b.i0),
                f.owner.begin() + static_cast<std::ptrdiff_t>(row + b.i1 + 1), -1);
    }
  }
  f.boxes.clear();
}

void FormImage(FrameBuffers* frame, const RenderOptions& options, uint64_t noise_seed, vpImage<unsigned char>* image) {
  const int width = frame->width, height = frame->height;
  const int s = options.supersampling;
  const Coverage coverage{frame->mask, options.background_grey, options.background_grey - options.dot_grey,
                          1.0 / (s * s)};
  std::vector<std::vector<Span>> spans;
  double elsewhere = options.background_grey;  // the grey level off the spans
  const bool blurred = options.blur_sigma_px > 0;
  if (blurred) {
    elsewhere = Blur(coverage, options.blur_sigma_px, frame, &spans);
  } else {
    spans = RowSpans(frame->boxes, width, height, 0, 0);
  }
  image->resize(static_cast<unsigned>(height), static_cast<unsigned>(width));
  unsigned char* out = image->bitmap;
  const bool noisy = options.noise_std_grey > 0;
  const double sigma = options.noise_std_grey;
  GaussianNoise noise(noise_seed);
  std::vector<double> deviates(static_cast<size_t>(width));  // one row's, drawn in pixel order
  const unsigned char plain = RoundToGrey(elsewhere);
  for (int v = 0; v < height; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    if (noisy) {
      noise.Fill(deviates.data(), deviates.size());
    }
    int u = 0;
    auto fill_to = [&](int end) {  // columns [u, end): the constant grey level
      if (noisy) {
        for (; u < end; ++u) out[row + u] = RoundToGrey(elsewhere + sigma * deviates[static_cast<size_t>(u)]);
      } else {
        std::fill(out + row + u, out + row + end, plain);
        u = end;
      }
    };
    for (const Span& span : spans[static_cast<size_t>(v)]) {
      fill_to(span.lo);
      for (; u <= span.hi; ++u) {
        double g = blurred ? frame->blurred[row + u] : coverage.Grey(row + u);
        if (noisy) g += sigma * deviates[static_cast<size_t>(u)];
        out[row + u] = RoundToGrey(g);
      }
    }
    fill_to(width);
  }
}

GaussianNoise::GaussianNoise(uint64_t seed) : state_(seed), edge_(Tables().x), ratio_(Tables().ratio) {
  state_ = Bits();  // nearby seeds, distant states
}

double GaussianNoise::Edge(int layer, double u) {
  const ZigguratTables& t = Tables();
  for (int i = layer;;) {
    if (std::abs(u) < t.ratio[i]) return u * t.x[i];
    if (i == 0) return Tail(u < 0);
    const double x = u * t.x[i];
    const double f0 = std::exp(-0.5 * (t.x[i] * t.x[i] - x * x));          // f(x) / f(x[i])
    const double f1 = std::exp(-0.5 * (t.x[i + 1] * t.x[i + 1] - x * x));  // f(x) / f(x[i + 1])
    if (f1 + Uniform() * (f0 - f1) < 1.0) return x;
    const uint64_t bits = Bits();  // rejected: a new layer and uniform
    i = static_cast<int>(bits & 0x7f);
    u = 2 * Unit(bits) - 1;
  }
}

// Marsaglia's (1964) tail beyond kR.
double GaussianNoise::Tail(bool negative) {
  double x, y;
  do {
    x = std::log(1 - Uniform()) / kR;  // 1 - [0, 1) = (0, 1]: finite logarithms
    y = std::log(1 - Uniform());
  } while (-2 * y < x * x);
  return negative ? x - kR : kR - x;
}

}  // namespace selfcal::sim
