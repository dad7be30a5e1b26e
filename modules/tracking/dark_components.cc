#include "tracking/dark_components.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "tracking/disjoint_sets.h"

namespace selfcal::tracking::internal {
namespace {

// The first u' >= u with row[u'] != 0, or w: background runs are skipped 8 bytes at a time.
int NextDark(const std::uint8_t* row, int u, int w) {
  while (u + 8 <= w) {
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, row + u, sizeof bytes);
    if (bytes != 0) break;
    u += 8;
  }
  while (u < w && row[u] == 0) ++u;
  return u;
}

// p[u + 1] = col[0] + ... + col[u], p[0] = 0. With SSE2 (every x86-64), eight sums at a time: the one
// serial loop of the mask, otherwise a third of its time. When every column sum is below 2^14
// (`small_columns`: at most 64 rows), the sums within each group of four columns are taken in the 16-bit
// lanes themselves (below 2^16) before widening. Exact integers either way.
template <typename Column, typename Sum>
void PrefixSums(const Column* col, int w, bool small_columns, Sum* p) {
  p[0] = 0;
  int u = 0;
#if defined(__SSE2__)
  if constexpr (std::is_same_v<Column, std::uint16_t> && std::is_same_v<Sum, std::int32_t>) {
    const __m128i zero = _mm_setzero_si128();
    __m128i carry = zero;  // every lane: the sum so far
    if (small_columns) {
      for (; u + 8 <= w; u += 8) {
        __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(col + u));
        c = _mm_add_epi16(c, _mm_slli_epi64(c, 16));  // within each 64-bit group of four columns
        c = _mm_add_epi16(c, _mm_slli_epi64(c, 32));
        const __m128i lo = _mm_add_epi32(_mm_unpacklo_epi16(c, zero), carry);
        const __m128i hi = _mm_add_epi32(_mm_unpackhi_epi16(c, zero), _mm_shuffle_epi32(lo, _MM_SHUFFLE(3, 3, 3, 3)));
        carry = _mm_shuffle_epi32(hi, _MM_SHUFFLE(3, 3, 3, 3));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p + u + 1), lo);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(p + u + 5), hi);
      }
    }
    for (; u + 8 <= w; u += 8) {
      const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(col + u));
      __m128i lo = _mm_unpacklo_epi16(c, zero), hi = _mm_unpackhi_epi16(c, zero);
      lo = _mm_add_epi32(lo, _mm_slli_si128(lo, 4));
      lo = _mm_add_epi32(lo, _mm_slli_si128(lo, 8));
      hi = _mm_add_epi32(hi, _mm_slli_si128(hi, 4));
      hi = _mm_add_epi32(hi, _mm_slli_si128(hi, 8));
      lo = _mm_add_epi32(lo, carry);
      hi = _mm_add_epi32(hi, _mm_shuffle_epi32(lo, _MM_SHUFFLE(3, 3, 3, 3)));
      carry = _mm_shuffle_epi32(hi, _MM_SHUFFLE(3, 3, 3, 3));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(p + u + 1), lo);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(p + u + 5), hi);
    }
  }
#endif
  Sum running = p[u];
  for (; u < w; ++u) {
    running += static_cast<Sum>(col[u]);
    p[u + 1] = running;
  }
}

// out[u] = n (I[u] + offset) <= p[u + half + 1] - p[u - half] ? 1 : 0 for the u of [begin, end) that
// sixteen at a time reach; returns the first u left. With SSE2, when n < 2^15: I + offset < 2^9 fits a
// 16-bit lane and pmaddwd gives n (I + offset) exactly in 32 bits. Else (and without SSE2) none.
template <typename Sum>
int DarkSixteenAtATime(const unsigned char* pixels, const Sum* p, int half, Sum n, int offset, int begin, int end,
                       std::uint8_t* out) {
  int u = begin;
#if defined(__SSE2__)
  if constexpr (std::is_same_v<Sum, std::int32_t>) {
    if (n >= (1 << 15)) return u;
    const __m128i zero = _mm_setzero_si128(), one = _mm_set1_epi8(1);
    const __m128i n_pairs = _mm_set1_epi32(n);  // (n, 0) in each pair of 16-bit lanes
    const __m128i off = _mm_set1_epi16(static_cast<short>(offset));
    for (; u + 16 <= end; u += 16) {
      const __m128i px = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pixels + u));
      const __m128i level[2] = {_mm_add_epi16(_mm_unpacklo_epi8(px, zero), off),
                                _mm_add_epi16(_mm_unpackhi_epi8(px, zero), off)};
      __m128i light[4];  // n (I + offset) > box sum, four lanes each
      for (int k = 0; k < 4; ++k) {
        const __m128i x = k % 2 == 0 ? _mm_unpacklo_epi16(level[k / 2], zero) : _mm_unpackhi_epi16(level[k / 2], zero);
        const __m128i box = _mm_sub_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p + u + 4 * k + half + 1)),
                                          _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + u + 4 * k - half)));
        light[k] = _mm_cmpgt_epi32(_mm_madd_epi16(x, n_pairs), box);
      }
      const __m128i packed = _mm_packs_epi16(_mm_packs_epi32(light[0], light[1]), _mm_packs_epi32(light[2], light[3]));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + u), _mm_andnot_si128(packed, one));
    }
  }
#else
  (void)pixels, (void)p, (void)half, (void)n, (void)offset, (void)end, (void)out;
#endif
  return u;
}

// Any dark pixel in the row's mask (a byte OR; the labeller skips rows without one).
bool AnyDark(const std::uint8_t* out, int w) {
  std::uint8_t any = 0;
  for (int u = 0; u < w; ++u) any |= out[u];
  return any != 0;
}

// from's pixels join to's; the darkest pixel stays the first in raster order.
void Merge(const Component& from, Component* to) {
  to->count += from.count;
  to->bbox.u_min = std::min(to->bbox.u_min, from.bbox.u_min);
  to->bbox.v_min = std::min(to->bbox.v_min, from.bbox.v_min);
  to->bbox.u_max = std::max(to->bbox.u_max, from.bbox.u_max);
  to->bbox.v_max = std::max(to->bbox.v_max, from.bbox.v_max);
  const bool earlier = from.darkest_v < to->darkest_v || (from.darkest_v == to->darkest_v && from.darkest_u < to->darkest_u);
  if (from.darkest < to->darkest || (from.darkest == to->darkest && earlier)) {
    to->darkest = from.darkest;
    to->darkest_u = from.darkest_u;
    to->darkest_v = from.darkest_v;
  }
}

// 8-connected labelling of runs of dark pixels, one row at a time. Labels are made in raster order of the
// runs' first pixels and a set's root is its smallest label, so the roots in label order are the
// components in raster order of their first pixel.
class RunLabeller {
 public:
  explicit RunLabeller(int width) : w_(width) {}

  // dark[u] != 0 marks the dark pixels of row v; pixels are its grey levels.
  void AddRow(int v, const std::uint8_t* dark, const unsigned char* pixels) {
    current_.clear();
    if (!AnyDark(dark, w_)) {
      std::swap(previous_, current_);
      return;
    }
    size_t j = 0;
    for (int u = NextDark(dark, 0, w_); u < w_; u = NextDark(dark, u, w_)) {
      const int s = u;
      while (u < w_ && dark[u] != 0) ++u;
      const int e = u - 1;
      while (j < previous_.size() && previous_[j].e < s - 1) ++j;
      int label = -1;
      for (size_t k = j; k < previous_.size() && previous_[k].s <= e + 1; ++k) {
        label = label < 0 ? sets_.Find(previous_[k].label) : sets_.Union(label, previous_[k].label).first;
      }
      if (label < 0) {
        label = sets_.Add();
        stats_.emplace_back();
      }
      Component& c = stats_[static_cast<size_t>(label)];
      for (int x = s; x <= e; ++x) {
        if (static_cast<int>(pixels[x]) < c.darkest) {
          c.darkest = pixels[x];
          c.darkest_u = x;
          c.darkest_v = v;
        }
      }
      c.count += e - s + 1;
      c.bbox.u_min = std::min(c.bbox.u_min, s);
      c.bbox.v_min = std::min(c.bbox.v_min, v);
      c.bbox.u_max = std::max(c.bbox.u_max, e);
      c.bbox.v_max = std::max(c.bbox.v_max, v);
      current_.push_back({s, e, label});
    }
    std::swap(previous_, current_);
  }

  std::vector<Component> Finish() {
    std::vector<int> index(sets_.size(), -1);
    std::vector<Component> components;
    for (size_t l = 0; l < sets_.size(); ++l) {
      if (sets_.Find(static_cast<int>(l)) == static_cast<int>(l)) {
        index[l] = static_cast<int>(components.size());
        components.emplace_back();
      }
    }
    for (size_t l = 0; l < sets_.size(); ++l) {
      Merge(stats_[l], &components[static_cast<size_t>(index[static_cast<size_t>(sets_.Find(static_cast<int>(l)))])]);
    }
    return components;
  }

 private:
  struct Run {
    int s, e, label;  // inclusive columns
  };

  int w_;
  DisjointSets sets_;
  std::vector<Component> stats_;  // per label, merged into the roots by Finish
  std::vector<Run> previous_, current_;
};

// The column sums over the box's rows are slid down the image and their prefix taken along each row;
// boxes not clipped left or right share one n. Column holds a column sum, Sum a prefix and n (I + offset).
template <typename Column, typename Sum>
std::vector<Component> AdaptiveComponents(const vpImage<unsigned char>& image, int window, int offset) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  const int half = window / 2;
  std::vector<Column> column(static_cast<size_t>(w), 0);
  std::vector<Sum> prefix(static_cast<size_t>(w) + 1, 0);
  std::vector<std::uint8_t> dark(static_cast<size_t>(w), 0);
  RunLabeller labeller(w);
  std::vector<int> box_begin(static_cast<size_t>(w)), box_end(static_cast<size_t>(w));  // columns [begin, end)
  for (int u = 0; u < w; ++u) {
    box_begin[static_cast<size_t>(u)] = std::max(0, u - half);
    box_end[static_cast<size_t>(u)] = std::min(w, u + half + 1);
  }
  const int inner_begin = std::min(w, half), inner_end = std::max(inner_begin, w - half - 1);
  int top = 0, bottom = 0;  // the column sums hold rows [top, bottom)
  for (int v = 0; v < h; ++v) {
    const int v0 = std::max(0, v - half), v1 = std::min(h, v + half + 1);
    Column* col = column.data();
    if (bottom + 1 == v1 && top + 1 == v0) {  // the usual step: one row in, one out, in one pass
      const unsigned char* in = image[bottom];
      const unsigned char* gone = image[top];
      for (int u = 0; u < w; ++u) col[u] = static_cast<Column>(col[u] + in[u] - gone[u]);
      ++bottom;
      ++top;
    }
    for (; bottom < v1; ++bottom) {
      const unsigned char* row = image[bottom];
      for (int u = 0; u < w; ++u) col[u] = static_cast<Column>(col[u] + row[u]);
    }
    for (; top < v0; ++top) {
      const unsigned char* row = image[top];
      for (int u = 0; u < w; ++u) col[u] = static_cast<Column>(col[u] - row[u]);
    }
    Sum* p = prefix.data();
    PrefixSums(col, w, v1 - v0 <= 64, p);
    const unsigned char* pixels = image[v];
    std::uint8_t* out = dark.data();
    const Sum rows = static_cast<Sum>(v1 - v0);
    auto test = [&](int u) {  // boxes clipped left or right
      const int u0 = box_begin[static_cast<size_t>(u)], u1 = box_end[static_cast<size_t>(u)];
      out[u] = static_cast<Sum>(u1 - u0) * rows * static_cast<Sum>(pixels[u] + offset) <= p[u1] - p[u0] ? 1 : 0;
    };
    for (int u = 0; u < inner_begin; ++u) test(u);
    const Sum n = static_cast<Sum>(2 * half + 1) * rows;
    const Sum off = static_cast<Sum>(offset);
    for (int u = DarkSixteenAtATime(pixels, p, half, n, offset, inner_begin, inner_end, out); u < inner_end; ++u) {
      out[u] = n * (static_cast<Sum>(pixels[u]) + off) <= p[u + half + 1] - p[u - half] ? 1 : 0;
    }
    for (int u = inner_end; u < w; ++u) test(u);
    labeller.AddRow(v, out, pixels);
  }
  return labeller.Finish();
}

}  // namespace

std::vector<Component> GlobalDarkComponents(const vpImage<unsigned char>& image, int threshold) {
  const int w = static_cast<int>(image.getWidth()), h = static_cast<int>(image.getHeight());
  std::vector<std::uint8_t> dark(static_cast<size_t>(w), 0);
  RunLabeller labeller(w);
  std::uint8_t* out = dark.data();
  const unsigned char t = static_cast<unsigned char>(std::clamp(threshold, 0, 255));
  for (int v = 0; v < h; ++v) {
    const unsigned char* pixels = image[v];
    if (threshold >= 0) {
      for (int u = 0; u < w; ++u) out[u] = pixels[u] <= t ? 1 : 0;
    }
    labeller.AddRow(v, out, pixels);
  }
  return labeller.Finish();
}

std::vector<Component> AdaptiveDarkComponents(const vpImage<unsigned char>& image, int window, int offset) {
  // Bounds: a column sum <= 255 rows; a prefix, and n (I + offset), <= 510 w rows (offset <= 255).
  const std::int64_t rows = std::min<std::int64_t>(window, image.getHeight());
  const std::int64_t largest_sum = 510 * static_cast<std::int64_t>(image.getWidth()) * rows;
  if (largest_sum <= std::numeric_limits<std::int32_t>::max()) {
    if (255 * rows <= std::numeric_limits<std::uint16_t>::max()) {
      return AdaptiveComponents<std::uint16_t, std::int32_t>(image, window, offset);
    }
    return AdaptiveComponents<std::int32_t, std::int32_t>(image, window, offset);
  }
  return AdaptiveDarkComponentsWide(image, window, offset);
}

std::vector<Component> AdaptiveDarkComponentsWide(const vpImage<unsigned char>& image, int window, int offset) {
  return AdaptiveComponents<std::int64_t, std::int64_t>(image, window, offset);
}

}  // namespace selfcal::tracking::internal
