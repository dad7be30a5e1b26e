#include "detection/contact_sheet.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace selfcal::detection {

namespace {

constexpr int kTitleHeightPx = 22;
constexpr int kGapPx = 6;
constexpr int kShift = 4;  // sub-pixel bits of OpenCV's drawing
const cv::Scalar kBackground(40, 40, 40), kGreen(0, 220, 0), kRed(0, 0, 255), kBlue(255, 80, 0),
    kYellow(0, 255, 255), kWhite(255, 255, 255), kBlack(0, 0, 0);

cv::Point Fixed(const cv::Point2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift))));
}

// A pixel of the full image (origin at the top-left pixel's centre) on a tile scaled by `s`.
cv::Point2d OnTile(const Eigen::Vector2d& uv, double s) { return {(uv.x() + 0.5) * s - 0.5, (uv.y() + 0.5) * s - 0.5}; }

void Text(cv::Mat* m, const std::string& text, cv::Point at, double scale, const cv::Scalar& colour) {
  cv::putText(*m, text, at, cv::FONT_HERSHEY_PLAIN, scale, kBlack, 3, cv::LINE_AA);
  cv::putText(*m, text, at, cv::FONT_HERSHEY_PLAIN, scale, colour, 1, cv::LINE_AA);
}

void DrawPoints(cv::Mat* tile, const ImagePoints& points, double s, int grid_cols) {
  const auto& px = points.points_px;
  auto arrow = [&](int to, const cv::Scalar& colour) {
    const auto a = px.find(0), b = px.find(to);
    if (a == px.end() || b == px.end()) return;
    cv::arrowedLine(*tile, Fixed(OnTile(a->second, s)), Fixed(OnTile(b->second, s)), colour, 2, cv::LINE_AA, kShift, 0.05);
  };
  if (grid_cols > 0) {
    arrow(1, kRed);
    arrow(grid_cols, kBlue);
  }
  for (const auto& [id, uv] : px) {
    const cv::Point2d p = OnTile(uv, s);
    if (id == 0) cv::circle(*tile, Fixed(p), 7 << kShift, kRed, 2, cv::LINE_AA, kShift);
    cv::circle(*tile, Fixed(p), 3 << kShift, kGreen, 1, cv::LINE_AA, kShift);
  }
  for (const auto& [id, uv] : px) {
    const cv::Point2d p = OnTile(uv, s);
    Text(tile, std::to_string(id), cv::Point(static_cast<int>(p.x) + 4, static_cast<int>(p.y) - 3), 0.7, kYellow);
  }
}

std::string Title(const SheetImage& image, const std::string& failed_label) {
  if (image.points == nullptr) return image.title;
  if (!image.points->ok) return image.title + ": " + failed_label;
  return image.title + ": ok, " + std::to_string(image.points->points_px.size()) + " points";
}

// The words of `text` in lines of at most `width` characters, at most `max_lines` of them (the last one
// ending in "..." when the text is longer); a word longer than a line is cut.
std::vector<std::string> Wrap(const std::string& text, size_t width, size_t max_lines) {
  std::vector<std::string> lines(1);
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find_first_of(" \n", start);
    if (end == std::string::npos) end = text.size();
    std::string word = text.substr(start, end - start).substr(0, width);
    start = end + 1;
    if (word.empty()) continue;
    if (!lines.back().empty() && lines.back().size() + 1 + word.size() > width) lines.emplace_back();
    lines.back() += (lines.back().empty() ? "" : " ") + word;
  }
  if (lines.size() > max_lines) {
    lines.resize(max_lines);
    std::string& last = lines.back();
    last = last.substr(0, std::min(last.size(), width > 3 ? width - 3 : 0)) + "...";
  }
  return lines;
}

// A failed image's outcome and reason on its tile, in red on a darkened band across the tile's top: the
// title line above holds only a few words of a long reason.
void DrawReason(cv::Mat* tile, const std::string& label, const std::string& reason) {
  constexpr int kLinePx = 15;
  const size_t width = static_cast<size_t>(std::max(8, (tile->cols - 8) / 9));
  std::vector<std::string> lines = Wrap(reason.empty() ? "no point found" : reason, width, 5);
  lines.insert(lines.begin(), label);
  const int band = std::min(tile->rows, static_cast<int>(lines.size()) * kLinePx + 8);
  cv::Mat top = (*tile)(cv::Rect(0, 0, tile->cols, band));
  top *= 0.3;
  for (size_t k = 0; k < lines.size(); ++k) {
    const int baseline = 4 + kLinePx * static_cast<int>(k + 1) - 3;
    if (baseline > band) break;
    Text(tile, lines[k], cv::Point(4, baseline), 1.0, kRed);
  }
}

}  // namespace

Result<std::string> ContactSheetPng(const std::vector<SheetImage>& images, const ContactSheetOptions& options) {
  if (images.empty()) return Status::Error(ErrorCode::kInvalidInput, "contact sheet: no image");
  int tile_w = 0, tile_h = 0;
  for (const SheetImage& im : images) {
    if (im.image == nullptr || im.image->getSize() == 0) {
      return Status::Error(ErrorCode::kInvalidInput, "contact sheet: " + im.title + " is empty");
    }
    const double s = std::min(1.0, static_cast<double>(options.max_tile_width_px) / im.image->getWidth());
    tile_w = std::max(tile_w, static_cast<int>(std::lround(im.image->getWidth() * s)));
    tile_h = std::max(tile_h, static_cast<int>(std::lround(im.image->getHeight() * s)));
  }
  const int n = static_cast<int>(images.size());
  const int columns = options.columns > 0 ? std::min(options.columns, n)
                                          : static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + columns - 1) / columns;
  const int cell_w = tile_w + kGapPx, cell_h = tile_h + kTitleHeightPx + kGapPx;
  cv::Mat sheet(kTitleHeightPx + rows * cell_h + kGapPx, std::max(columns * cell_w + kGapPx, 600), CV_8UC3, kBackground);
  std::string legend = "green: point and its id (yellow); red circle: point 0";
  if (options.grid_cols > 0) legend += "; red arrow: 0 -> 1 (+col); blue arrow: 0 -> " + std::to_string(options.grid_cols) + " (+row)";
  cv::putText(sheet, legend, cv::Point(kGapPx, 15), cv::FONT_HERSHEY_PLAIN, 1.0, kWhite, 1, cv::LINE_AA);
  for (int k = 0; k < n; ++k) {
    const SheetImage& im = images[static_cast<size_t>(k)];
    const int x0 = kGapPx + (k % columns) * cell_w, y0 = kTitleHeightPx + (k / columns) * cell_h;
    const cv::Mat grey(static_cast<int>(im.image->getHeight()), static_cast<int>(im.image->getWidth()), CV_8UC1,
                       const_cast<unsigned char*>(im.image->bitmap));
    const double s = std::min(1.0, static_cast<double>(options.max_tile_width_px) / im.image->getWidth());
    cv::Mat scaled, tile;
    if (s < 1.0) {
      cv::resize(grey, scaled, cv::Size(), s, s, cv::INTER_AREA);
    } else {
      scaled = grey;
    }
    cv::cvtColor(scaled, tile, cv::COLOR_GRAY2BGR);
    if (im.points != nullptr && im.points->ok) DrawPoints(&tile, *im.points, s, options.grid_cols);
    if (im.points != nullptr && !im.points->ok) DrawReason(&tile, options.failed_label, im.points->message);
    const cv::Rect where(x0, y0 + kTitleHeightPx, std::min(tile.cols, tile_w), std::min(tile.rows, tile_h));
    tile(cv::Rect(0, 0, where.width, where.height)).copyTo(sheet(where));
    const bool failed = im.points != nullptr && !im.points->ok;
    std::string title = Title(im, options.failed_label);
    if (title.size() > static_cast<size_t>(tile_w / 8)) title = title.substr(0, static_cast<size_t>(tile_w / 8 - 3)) + "...";
    cv::putText(sheet, title, cv::Point(x0, y0 + 16), cv::FONT_HERSHEY_PLAIN, 1.0, failed ? kRed : kGreen, 1, cv::LINE_AA);
  }
  std::vector<unsigned char> png;
  try {
    if (!cv::imencode(".png", sheet, png, {cv::IMWRITE_PNG_COMPRESSION, 6})) {
      return Status::Error(ErrorCode::kInvalidInput, "contact sheet: the PNG encoder failed");
    }
  } catch (const cv::Exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, std::string("contact sheet: the PNG encoder failed: ") + e.what());
  }
  return std::string(png.begin(), png.end());
}

}  // namespace selfcal::detection
