#include "acquisition/dot_naming.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <visp3/core/vpImageConvert.h>

namespace selfcal::acquisition {

namespace {

bool Named(const NamingResult& naming, int id) {
  return std::any_of(naming.named.begin(), naming.named.end(),
                     [&](const tracking::PreviousDot& d) { return d.id == id; });
}

}  // namespace

NamingResult NameDots(const capture::Frame& frame, DotIdentifier* identifier,
                      const tracking::DotDetectorOptions& detector) {
  NamingResult r;
  r.detections = tracking::DetectDots(frame.image, detector);
  r.id_of_detection.assign(r.detections.dots.size(), -1);
  Result<std::vector<tracking::PreviousDot>> named = identifier->Identify(frame, r.detections);
  if (!named.ok()) {
    r.identifier_message = named.status().message();
    return r;
  }
  r.named = std::move(named).value();
  std::sort(r.named.begin(), r.named.end(),
            [](const tracking::PreviousDot& a, const tracking::PreviousDot& b) { return a.id < b.id; });
  // Identifiers return PreviousDots made from the detections: the same centroid marks the detection.
  for (const tracking::PreviousDot& d : r.named) {
    for (size_t k = 0; k < r.detections.dots.size(); ++k) {
      if ((r.detections.dots[k].centroid_px - d.centroid_px).norm() < 1e-9) r.id_of_detection[k] = d.id;
    }
  }
  return r;
}

vpImage<vpRGBa> AnnotateDots(const vpImage<unsigned char>& image, const NamingResult& naming) {
  cv::Mat grey;
  vpImageConvert::convert(image, grey);
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  const double scale = std::max(0.35, image.getWidth() / 1600.0);  // legible on 640 px and on 4k
  for (size_t k = 0; k < naming.detections.dots.size(); ++k) {
    const tracking::DotDetection& d = naming.detections.dots[k];
    const int id = naming.id_of_detection[k];
    const cv::Scalar colour = id >= 0 ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 0, 255);
    const cv::Point centre(static_cast<int>(std::lround(d.centroid_px.x())),
                           static_cast<int>(std::lround(d.centroid_px.y())));
    const int radius = std::max(3, static_cast<int>(std::lround(d.semi_major_px)) + 2);
    cv::circle(bgr, centre, radius, colour, 1, cv::LINE_AA);
    const std::string text = id >= 0 ? std::to_string(id) : "?";
    cv::putText(bgr, text, centre + cv::Point(radius + 1, -radius), cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1,
                cv::LINE_AA);
  }
  vpImage<vpRGBa> out;
  vpImageConvert::convert(bgr, out);
  return out;
}

Result<std::string> EncodeColourPng(const vpImage<vpRGBa>& image) {
  if (image.getSize() == 0) return Status::Error(ErrorCode::kInvalidInput, "cannot encode an empty image");
  cv::Mat bgr;
  vpImageConvert::convert(image, bgr);
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", bgr, bytes)) return Status::Error(ErrorCode::kInvalidInput, "the PNG encoder failed");
  return std::string(bytes.begin(), bytes.end());
}

Status ApplyNaming(const NamingResult& naming, const YardstickChoice* yardstick, const std::string& source,
                   ObservationSet* setup, session::SetupNaming* setup_naming, std::vector<std::string>* warnings) {
  if (yardstick != nullptr) {
    for (int id : {yardstick->dot_a, yardstick->dot_b}) {
      if (!Named(naming, id)) {
        return Status::Error(ErrorCode::kInvalidInput, "--yardstick: dot " + std::to_string(id) +
                                                           " is not a named dot of this frame (" +
                                                           std::to_string(naming.named.size()) + " named)");
      }
    }
    if (yardstick->dot_a == yardstick->dot_b) {
      return Status::Error(ErrorCode::kInvalidInput, "--yardstick: its two ends must be different dots (both are " +
                                                         std::to_string(yardstick->dot_a) + ")");
    }
    if (!(yardstick->length_m > 0) || !std::isfinite(yardstick->length_m)) {
      return Status::Error(ErrorCode::kInvalidInput, "--length-mm: the yardstick's length must be positive");
    }
    setup->yardsticks = {{yardstick->dot_a, yardstick->dot_b, yardstick->length_m}};
  }
  setup_naming->reference_dots.clear();
  for (const tracking::PreviousDot& d : naming.named) {
    setup_naming->reference_dots.push_back({d.id, d.centroid_px.x(), d.centroid_px.y(), d.area_px2});
  }
  setup_naming->reference_image = source;
  for (const auto* list : {&setup->yardsticks, &setup->check_distances}) {
    const char* what = list == &setup->yardsticks ? "yardstick" : "check distance";
    for (const KnownDistance& k : *list) {
      for (int id : {k.dot_a, k.dot_b}) {
        if (!Named(naming, id))
          warnings->push_back(std::string(what) + " dot " + std::to_string(id) + " is not named in this frame");
      }
    }
  }
  return Status::Ok();
}

}  // namespace selfcal::acquisition
