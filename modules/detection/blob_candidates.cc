#include "detection/blob_candidates.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace selfcal::detection {

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
  return m;
}

// Robust standard deviation: 1.4826 times the median absolute deviation from `centre`.
double RobustSigma(const std::vector<double>& v, double centre) {
  std::vector<double> d;
  d.reserve(v.size());
  for (double x : v) d.push_back(std::abs(x - centre));
  return 1.4826 * Median(std::move(d));
}

// The seed's window: a factor 2 in area, 1.65 in contrast (natural logs).
constexpr double kSeedLogArea = 0.6931;
constexpr double kSeedLogContrast = 0.5;

}  // namespace

const char* PolarityName(Polarity polarity) {
  switch (polarity) {
    case Polarity::kDark: return "dark";
    case Polarity::kLight: return "light";
    case Polarity::kAuto: return "auto";
  }
  return "unknown";
}

Result<Polarity> ParsePolarity(const std::string& name) {
  if (name == "dark") return Polarity::kDark;
  if (name == "light") return Polarity::kLight;
  if (name == "auto") return Polarity::kAuto;
  return Status::Error(ErrorCode::kInvalidInput, "unknown polarity `" + name + "`: dark, light or auto");
}

Status BlobFilterOptions::Validate() const {
  std::ostringstream s;
  if (!(max_deviations > 0)) s << "blob filter: max_deviations must be positive\n";
  if (!(min_log_area_sigma > 0) || !(min_log_contrast_sigma > 0)) s << "blob filter: the sigma floors must be positive\n";
  if (min_blobs < 3) s << "blob filter: min_blobs must be at least 3\n";
  return s.str().empty() ? Status::Ok() : Status::Error(ErrorCode::kInvalidInput, s.str());
}

tracking::DetectionReport DetectDotsOfPolarity(const vpImage<unsigned char>& image,
                                               const tracking::DotDetectorOptions& options, Polarity polarity) {
  SELFCAL_CHECK(polarity != Polarity::kAuto, "DetectDotsOfPolarity: choose dark or light");
  if (polarity == Polarity::kDark) return tracking::DetectDots(image, options);
  vpImage<unsigned char> inverted(image.getHeight(), image.getWidth());
  const unsigned n = image.getSize();
  const unsigned char* in = image.bitmap;
  unsigned char* out = inverted.bitmap;
  for (unsigned k = 0; k < n; ++k) out[k] = static_cast<unsigned char>(255 - in[k]);
  return tracking::DetectDots(inverted, options);
}

std::vector<size_t> ConsistentBlobs(const std::vector<tracking::DotDetection>& dots, const BlobFilterOptions& options) {
  std::vector<size_t> all(dots.size());
  for (size_t k = 0; k < dots.size(); ++k) all[k] = k;
  if (!options.enabled || dots.size() < static_cast<size_t>(options.min_blobs)) return all;
  std::vector<double> la, lc;
  for (const tracking::DotDetection& d : dots) {
    la.push_back(std::log(std::max(d.area_px2, 1.0)));
    lc.push_back(std::log(std::max(d.contrast, 1.0)));
  }
  // The seed: the blob with the most others in its window (ties: the first, raster order).
  size_t seed = 0, best = 0;
  for (size_t k = 0; k < dots.size(); ++k) {
    size_t n = 0;
    for (size_t j = 0; j < dots.size(); ++j) {
      n += (std::abs(la[j] - la[k]) <= kSeedLogArea && std::abs(lc[j] - lc[k]) <= kSeedLogContrast) ? 1 : 0;
    }
    if (n > best) best = n, seed = k;
  }
  std::vector<double> ca, cc;
  for (size_t j = 0; j < dots.size(); ++j) {
    if (std::abs(la[j] - la[seed]) <= kSeedLogArea && std::abs(lc[j] - lc[seed]) <= kSeedLogContrast) {
      ca.push_back(la[j]);
      cc.push_back(lc[j]);
    }
  }
  const double ma = Median(ca), mc = Median(cc);
  const double sa = std::max(RobustSigma(ca, ma), options.min_log_area_sigma);
  const double sc = std::max(RobustSigma(cc, mc), options.min_log_contrast_sigma);
  std::vector<size_t> kept;
  for (size_t k = 0; k < dots.size(); ++k) {
    if (std::abs(la[k] - ma) <= options.max_deviations * sa && std::abs(lc[k] - mc) <= options.max_deviations * sc) {
      kept.push_back(k);
    }
  }
  return kept;
}

FilteredDots FilterTexture(tracking::DetectionReport report, const BlobFilterOptions& options) {
  FilteredDots out;
  const std::vector<size_t> kept = ConsistentBlobs(report.dots, options);
  out.texture_blobs = static_cast<int>(report.dots.size() - kept.size());
  std::vector<tracking::DotDetection> dots;
  dots.reserve(kept.size());
  for (size_t k : kept) dots.push_back(report.dots[k]);
  report.dots = std::move(dots);
  out.report = std::move(report);
  return out;
}

double ContrastScore(const std::vector<tracking::DotDetection>& dots) {
  std::vector<double> c;
  for (const tracking::DotDetection& d : dots) c.push_back(d.contrast);
  return static_cast<double>(dots.size()) * Median(std::move(c));
}

}  // namespace selfcal::detection
