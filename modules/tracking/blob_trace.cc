#include "tracking/blob_trace.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include <visp3/core/vpImagePoint.h>
#include <visp3/core/vpRect.h>

namespace selfcal::tracking::internal {
namespace {

// Freeman directions as vpDot2::updateFreemanPosition: 0 (+u), 1 (+u, +v), 2 (+v), 3 (-u, +v), 4 (-u),
// 5 (-u, -v), 6 (-v), 7 (+u, -v).
constexpr int kDu[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kDv[8] = {0, 1, 1, 1, 0, -1, -1, -1};
// vpDot2::computeFreemanChainElement's order of the next direction, relative to the current one.
constexpr int kTurns[8] = {2, 1, 0, 7, 6, 5, 4, 3};

// vpDot2::hasGoodLevel with the whole image as its area and grey levels [0, threshold].
class DarkPixels {
 public:
  DarkPixels(const vpImage<unsigned char>& image, int threshold)
      : image_(image), w_(static_cast<int>(image.getWidth())), h_(static_cast<int>(image.getHeight())),
        threshold_(std::clamp(threshold, 0, 255)) {
    for (int d = 0; d < 8; ++d) step_[d] = kDu[d] + kDv[d] * static_cast<std::ptrdiff_t>(w_);
  }
  bool InImage(int u, int v) const { return u >= 0 && v >= 0 && u < w_ && v < h_; }
  bool Dark(int u, int v) const { return InImage(u, v) && static_cast<int>(image_[v][u]) <= threshold_; }
  int width() const { return w_; }
  int height() const { return h_; }

  // vpDot2::computeFreemanChainElement: false (element unchanged) when (u, v) is not dark or has no dark
  // neighbour.
  bool NextElement(int u, int v, int* element) const {
    if (u > 0 && v > 0 && u < w_ - 1 && v < h_ - 1) {  // every neighbour inside: no bounds to test
      const unsigned char* pixel = image_.bitmap + static_cast<std::ptrdiff_t>(v) * w_ + u;
      if (static_cast<int>(*pixel) > threshold_) return false;
      for (int turn : kTurns) {
        const int d = (*element + turn) % 8;
        if (static_cast<int>(pixel[step_[d]]) <= threshold_) {
          *element = d;
          return true;
        }
      }
      return false;
    }
    if (!Dark(u, v)) return false;
    for (int turn : kTurns) {
      const int d = (*element + turn) % 8;
      if (Dark(u + kDu[d], v + kDv[d])) {
        *element = d;
        return true;
      }
    }
    return false;
  }

 private:
  const vpImage<unsigned char>& image_;
  int w_, h_, threshold_;
  std::ptrdiff_t step_[8];  // the neighbour along each direction in the bitmap
};

// vpDot2::computeFreemanParameters' area and first-moment increments of one step from (u_p, v_p) along
// `element`: the same expressions, rounded to float as there.
void FreemanIncrements(int u_p, int v_p, int element, float* dS, float* dMu, float* dMv) {
  switch (element) {
    case 0:
      *dS = static_cast<float>(v_p);
      *dMu = 0.0;
      *dMv = static_cast<float>(0.5 * v_p * v_p);
      break;
    case 1:
      *dS = static_cast<float>(v_p + 0.5);
      *dMu = -static_cast<float>(0.5 * u_p * (u_p + 1) + 1.0 / 6.0);
      *dMv = static_cast<float>(0.5 * v_p * (v_p + 1) + 1.0 / 6.0);
      break;
    case 2:
      *dS = 0.0;
      *dMu = static_cast<float>(-0.5 * u_p * u_p);
      *dMv = 0.0;
      break;
    case 3:
      *dS = static_cast<float>(-v_p - 0.5);
      *dMu = -static_cast<float>(0.5 * u_p * (u_p - 1) + 1.0 / 6.0);
      *dMv = -static_cast<float>(0.5 * v_p * (v_p + 1) + 1.0 / 6.0);
      break;
    case 4:
      *dS = static_cast<float>(-v_p);
      *dMv = static_cast<float>(-0.5 * v_p * v_p);
      *dMu = 0.0;
      break;
    case 5:
      *dS = static_cast<float>(-v_p + 0.5);
      *dMu = static_cast<float>(0.5 * u_p * (u_p - 1) + 1.0 / 6.0);
      *dMv = static_cast<float>(-(0.5 * v_p * (v_p - 1) + 1.0 / 6.0));
      break;
    case 6:
      *dS = 0.0;
      *dMu = static_cast<float>(0.5 * u_p * u_p);
      *dMv = 0.0;
      break;
    default:  // 7
      *dS = static_cast<float>(v_p - 0.5);
      *dMu = static_cast<float>(0.5 * u_p * (u_p + 1) + 1.0 / 6.0);
      *dMv = static_cast<float>(0.5 * v_p * (v_p - 1) + 1.0 / 6.0);
      break;
  }
}

// vpDot2::findFirstBorder: the last dark pixel of the run to the right of (u, v); false when the run
// goes further than width / (0.65 + 0.001) (width > 0; 0.65 is vpDot2's maxSizeSearchDistancePrecision).
bool FirstBorder(const DarkPixels& dark, int u, int v, double width, int* border_u) {
  const double max_run = width / (0.65 + 0.001);
  int b = u;
  while (dark.Dark(b + 1, v) && b < dark.width() - 1) {
    if (width > 0 && static_cast<double>(b - u) > max_run) return false;
    ++b;
  }
  *border_u = b;
  return true;
}

// vpDot2::computeMeanGrayLevel throws unless a dark pixel lies on the centre's row or column within the
// bounding box (or, with fewer than 10 there, on its diagonals; the diagonals are not looked at here: a
// blob without one on its row or column goes to vpDot2).
bool DarkOnCentreCross(const vpImage<unsigned char>& image, int threshold, const PixelBox& box, const Eigen::Vector2d& cog) {
  const int cu = static_cast<int>(cog.x()), cv = static_cast<int>(cog.y());
  const unsigned char* row = image[cv];
  for (int u = box.u_min; u <= box.u_max; ++u) {
    if (static_cast<int>(row[u]) <= threshold) return true;
  }
  for (int v = box.v_min; v <= box.v_max; ++v) {
    if (static_cast<int>(image[v][cu]) <= threshold) return true;
  }
  return false;
}

PixelBox BoxOf(const vpDot2& dot) {
  const vpRect rect = dot.getBBox();
  PixelBox box;
  box.u_min = static_cast<int>(std::lround(rect.getLeft()));
  box.v_min = static_cast<int>(std::lround(rect.getTop()));
  box.u_max = static_cast<int>(std::lround(rect.getRight()));
  box.v_max = static_cast<int>(std::lround(rect.getBottom()));
  return box;
}

}  // namespace

bool FollowBorder(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start, double width,
                  TracedBlob* out) {
  const DarkPixels dark(image, threshold);
  // The start pixel, truncated as vpDot2 does (a start outside the image is left to vpDot2).
  if (!(start.x() >= 0 && start.y() >= 0 && start.x() < dark.width() && start.y() < dark.height())) return false;
  const int su = static_cast<int>(start.x()), sv = static_cast<int>(start.y());
  if (!dark.Dark(su, sv)) return false;
  int first_u = 0;
  if (!FirstBorder(dark, su, sv, width, &first_u)) return false;
  const int first_v = sv;
  int dir = 6;
  dark.NextElement(first_u, first_v, &dir);  // vpDot2 ignores a failure here: the walk below then fails
  const int first_dir = dir;
  int u = first_u, v = first_v;
  double m00 = 0.0, m10 = 0.0, m01 = 0.0;
  PixelBox box{dark.width(), dark.height(), 0, 0};  // vpDot2's initial bounds
  do {
    float dS = 0, dMu = 0, dMv = 0;
    FreemanIncrements(u, v, dir, &dS, &dMu, &dMv);
    u += kDu[dir];
    v += kDv[dir];
    m00 += dS;
    m10 += dMu;
    m01 += dMv;
    if (!dark.InImage(u, v)) return false;
    box.v_min = std::min(box.v_min, v);
    box.v_max = std::max(box.v_max, v);
    box.u_min = std::min(box.u_min, u);
    box.u_max = std::max(box.u_max, u);
    if (!dark.NextElement(u, v, &dir)) return false;
  } while (first_u != u || first_v != v || first_dir != dir);
  const double eps = std::numeric_limits<double>::epsilon();
  if (std::fabs(m00) <= eps || std::fabs(m00 - 1.) <= std::max(std::fabs(m00), 1.) * eps) return false;
  const Eigen::Vector2d cog(m10 / m00, m01 / m00);
  // vpDot2::track refuses a centre outside the image; computeMeanGrayLevel may throw.
  if (!(cog.x() >= 0 && cog.x() < dark.width() && cog.y() >= 0 && cog.y() < dark.height())) return false;
  if (!DarkOnCentreCross(image, std::clamp(threshold, 0, 255), box, cog)) return false;
  out->bbox = box;
  out->cog_px = cog;
  out->polygon_area_px2 = std::fabs(m00);
  return true;
}

TracedBlob TrackDarkBlob(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start,
                         double width, double height) {
  TracedBlob blob;
  if (FollowBorder(image, threshold, start, width, &blob)) return blob;
  return TrackDarkBlobWithVpDot2(image, threshold, start, width, height);
}

TracedBlob TrackDarkBlobWithVpDot2(const vpImage<unsigned char>& image, int threshold, const Eigen::Vector2d& start,
                                   double width, double height) {
  vpDot2 dot = MakeDarkDot(threshold);
  vpImagePoint cog;
  cog.set_uv(start.x(), start.y());
  dot.setCog(cog);
  dot.setWidth(width);
  dot.setHeight(height);
  dot.track(image);
  TracedBlob blob;
  blob.bbox = BoxOf(dot);
  blob.cog_px = Eigen::Vector2d(dot.getCog().get_u(), dot.getCog().get_v());
  blob.polygon_area_px2 = dot.getArea();
  return blob;
}

vpDot2 MakeDarkDot(int threshold) {
  vpDot2 dot;
  dot.setGraphics(false);
  dot.setComputeMoments(true);
  dot.setGrayLevelMin(0);
  dot.setGrayLevelMax(static_cast<unsigned int>(std::clamp(threshold, 0, 255)));
  dot.setSizePrecision(0.0);
  dot.setEllipsoidShapePrecision(0.0);
  dot.setEllipsoidBadPointsPercentage(1.0);
  return dot;
}

}  // namespace selfcal::tracking::internal
