#include "tracking/blob_window.h"

#include <algorithm>

#include "tracking/disjoint_sets.h"

namespace selfcal::tracking::internal {
namespace {

constexpr std::uint8_t kDark = 3;  // a dark cell not (yet) the blob's

// A dark run of a bbox row, window coordinates, inclusive columns.
struct LabelledRun {
  int y, s, e, label;
};

// The sets of runs, with the span (bounding box) of each set kept at its root.
class RunSets {
 public:
  void Clear() {
    sets_.Clear();
    span_.clear();
  }
  int Add(int y, int s, int e) {
    span_.push_back(PixelBox{s, y, e, y});
    return sets_.Add();
  }
  int Find(int x) { return sets_.Find(x); }
  int Union(int a, int b) {
    const auto [root, absorbed] = sets_.Union(a, b);
    if (absorbed >= 0) Grow(root, span_[static_cast<size_t>(absorbed)]);
    return root;
  }
  // The root's span grows by `box`.
  void Grow(int root, const PixelBox& box) {
    PixelBox& s = span_[static_cast<size_t>(root)];
    s.u_min = std::min(s.u_min, box.u_min);
    s.v_min = std::min(s.v_min, box.v_min);
    s.u_max = std::max(s.u_max, box.u_max);
    s.v_max = std::max(s.v_max, box.v_max);
  }
  const PixelBox& Span(int root) const { return span_[static_cast<size_t>(root)]; }

 private:
  DisjointSets sets_;
  std::vector<PixelBox> span_;
};

// Buffers reused from blob to blob.
struct WindowScratch {
  std::vector<LabelledRun> runs;
  RunSets sets;
  std::vector<std::uint8_t> dark, near;
};

// The dark runs of rows y0..y1 within columns x0..x1, labelled 8-connected, in raster order.
void LabelBoxRuns(const BlobWindow& win, const PixelBox& box, WindowScratch* scratch) {
  std::vector<LabelledRun>& runs = scratch->runs;
  RunSets& sets = scratch->sets;
  runs.clear();
  sets.Clear();
  size_t previous_begin = 0, previous_end = 0;
  for (int y = box.v_min; y <= box.v_max; ++y) {
    const std::uint8_t* row = &win.cells[static_cast<size_t>(y * win.w)];
    const size_t current_begin = runs.size();
    size_t j = previous_begin;
    for (int x = box.u_min; x <= box.u_max;) {
      if (row[x] != kDark) {
        ++x;
        continue;
      }
      const int s = x;
      while (x <= box.u_max && row[x] == kDark) ++x;
      const int e = x - 1;
      while (j < previous_end && runs[j].e < s - 1) ++j;
      int label = -1;
      for (size_t k = j; k < previous_end && runs[k].s <= e + 1; ++k) {
        label = label < 0 ? sets.Find(runs[k].label) : sets.Union(label, runs[k].label);
      }
      if (label < 0) {
        label = sets.Add(y, s, e);
      } else {
        sets.Grow(label, PixelBox{s, y, e, y});
      }
      runs.push_back({y, s, e, label});
    }
    previous_begin = current_begin;
    previous_end = runs.size();
  }
}

// The root of the set spanning `box` that holds the seed (window coordinates) or, without one, a run of
// the box's top row; -1 if none.
int SpanningSet(const PixelBox& box, const std::pair<int, int>* seed, WindowScratch* scratch) {
  for (const LabelledRun& run : scratch->runs) {
    if (seed != nullptr) {
      if (run.y != seed->second || run.s > seed->first || run.e < seed->first) continue;
    } else if (run.y != box.v_min) {
      break;
    }
    const int root = scratch->sets.Find(run.label);
    if (scratch->sets.Span(root) == box) return root;
    if (seed != nullptr) return -1;
  }
  return -1;
}

// Other: the dark cells left (not the blob's) and every non-blob cell 8-adjacent to one.
void MarkOthers(BlobWindow* win, WindowScratch* scratch) {
  // Byte loops over raw pointers and local bounds (a byte store may alias anything else), so that they
  // vectorise.
  const int w = win->w, h = win->h;
  scratch->dark.resize(static_cast<size_t>(w) + 2);
  scratch->near.resize(static_cast<size_t>(w * h));
  std::uint8_t* dark = scratch->dark.data() + 1;  // dark[-1] and dark[w] stay 0
  std::uint8_t* near = scratch->near.data();      // dark left in the cell or its row neighbours
  std::uint8_t* cells = win->cells.data();
  std::uint8_t any = 0;
  for (int i = 0; i < w * h; ++i) any |= cells[i] == kDark ? 1 : 0;
  if (any == 0) return;  // blob and free cells only (an isolated dot)
  dark[-1] = 0;
  dark[w] = 0;
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = cells + y * w;
    std::uint8_t* n = near + y * w;
    for (int x = 0; x < w; ++x) dark[x] = row[x] == kDark ? 1 : 0;
    for (int x = 0; x < w; ++x) n[x] = static_cast<std::uint8_t>(dark[x - 1] | dark[x] | dark[x + 1]);
  }
  for (int y = 0; y < h; ++y) {
    std::uint8_t* row = cells + y * w;
    const std::uint8_t* mid = near + y * w;
    const std::uint8_t* up = y > 0 ? mid - w : mid;
    const std::uint8_t* down = y + 1 < h ? mid + w : mid;
    for (int x = 0; x < w; ++x) {
      const std::uint8_t other = static_cast<std::uint8_t>(up[x] | mid[x] | down[x]);
      row[x] = row[x] == kBlob ? std::uint8_t{kBlob} : (other != 0 ? std::uint8_t{kOther} : std::uint8_t{kFree});
    }
  }
}

}  // namespace

bool ClassifyBlobWindow(const vpImage<unsigned char>& image, int threshold, const PixelBox& bbox, int margin,
                        const std::pair<int, int>* required_seed, BlobWindow* window,
                        std::vector<PixelRun>* blob_runs) {
  thread_local WindowScratch scratch;
  BlobWindow& win = *window;
  const int width = static_cast<int>(image.getWidth());
  const int height = static_cast<int>(image.getHeight());
  win.u0 = std::max(0, bbox.u_min - margin);
  win.v0 = std::max(0, bbox.v_min - margin);
  win.w = std::min(width - 1, bbox.u_max + margin) - win.u0 + 1;
  win.h = std::min(height - 1, bbox.v_max + margin) - win.v0 + 1;
  win.cells.resize(static_cast<size_t>(win.w * win.h));
  const unsigned char t = static_cast<unsigned char>(std::clamp(threshold, 0, 255));
  const int w = win.w, h = win.h;  // local: the byte stores below may alias win's fields
  std::uint8_t* cells = win.cells.data();
  for (int y = 0; y < h; ++y) {
    const unsigned char* row = image[win.v0 + y] + win.u0;
    std::uint8_t* out = cells + y * w;
    if (threshold < 0) {
      std::fill(out, out + w, std::uint8_t{kFree});
      continue;
    }
    for (int x = 0; x < w; ++x) out[x] = row[x] <= t ? kDark : std::uint8_t{kFree};
  }
  // Window coordinates from here on.
  const PixelBox box{bbox.u_min - win.u0, bbox.v_min - win.v0, bbox.u_max - win.u0, bbox.v_max - win.v0};
  LabelBoxRuns(win, box, &scratch);
  std::pair<int, int> seed;
  if (required_seed != nullptr) {
    seed = {required_seed->first - win.u0, required_seed->second - win.v0};
    if (seed.first < box.u_min || seed.first > box.u_max || seed.second < box.v_min || seed.second > box.v_max) {
      return false;
    }
  }
  const int blob = SpanningSet(box, required_seed != nullptr ? &seed : nullptr, &scratch);
  if (blob < 0) return false;
  blob_runs->clear();
  for (const LabelledRun& run : scratch.runs) {
    if (scratch.sets.Find(run.label) != blob) continue;
    std::fill(&win.cells[static_cast<size_t>(run.y * win.w + run.s)], &win.cells[static_cast<size_t>(run.y * win.w + run.e)] + 1,
              std::uint8_t{kBlob});
    blob_runs->push_back(PixelRun{run.y + win.v0, run.s + win.u0, run.e + win.u0});
  }
  MarkOthers(&win, &scratch);
  return true;
}

}  // namespace selfcal::tracking::internal
