// The OpenCV comparison row: findEssentialMat (5-point RANSAC, known focal) + recoverPose. OpenCV types
// stay in this file.
#include <cmath>
#include <sstream>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "base/status.h"
#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview {

using internal::Finish;

namespace internal {
namespace {

// OpenCV's camera has one focal: v is rescaled about c_y by 1/mu so that f_x applies to both axes.
std::vector<cv::Point2d> OpenCvPoints(const CameraIntrinsics& camera, const std::vector<Eigen::Vector2d>& pixels) {
  std::vector<cv::Point2d> out;
  out.reserve(pixels.size());
  for (const Eigen::Vector2d& uv : pixels) {
    out.emplace_back(uv.x(), camera.cy_px + (uv.y() - camera.cy_px) / camera.mu);
  }
  return out;
}

}  // namespace

EssentialChoice ChooseEssentialCandidate(const Eigen::MatrixXd& stacked, const CameraIntrinsics& camera,
                                         const std::vector<Eigen::Vector2d>& pixels1,
                                         const std::vector<Eigen::Vector2d>& pixels2, const std::vector<bool>& mask,
                                         double threshold_px) {
  SELFCAL_CHECK(pixels1.size() == pixels2.size(),
                "ChooseEssentialCandidate: " << pixels1.size() << " vs " << pixels2.size() << " pixels");
  SELFCAL_CHECK(mask.empty() || mask.size() == pixels1.size(),
                "ChooseEssentialCandidate: mask of " << mask.size() << " for " << pixels1.size() << " pixels");
  EssentialChoice choice;
  const int n = static_cast<int>(pixels1.size());
  choice.good.assign(n, false);
  if (stacked.rows() == 0 || stacked.cols() != 3 || stacked.rows() % 3 != 0) {
    std::ostringstream m;
    m << "essential matrix of " << stacked.rows() << " x " << stacked.cols() << " is not 3N x 3";
    choice.message = m.str();
    return choice;
  }
  choice.num_candidates = static_cast<int>(stacked.rows() / 3);
  choice.num_inliers.assign(choice.num_candidates, 0);
  choice.num_good.assign(choice.num_candidates, 0);

  const std::vector<cv::Point2d> p1 = OpenCvPoints(camera, pixels1), p2 = OpenCvPoints(camera, pixels2);
  const cv::Point2d pp(camera.cx_px, camera.cy_px);
  const Eigen::Matrix3d a_inv = Eigen::Vector3d(1 / camera.fx_px, 1 / camera.fx_px, 1).asDiagonal();
  const double gate_sq = threshold_px * threshold_px;
  int skipped = 0;
  for (int c = 0; c < choice.num_candidates; ++c) {
    const Eigen::Matrix3d e = stacked.middleRows<3>(3 * c);
    if (!e.allFinite() || !(e.norm() > 0)) {
      ++skipped;
      continue;
    }
    const Eigen::Matrix3d f_px = FundamentalToPixels(camera, a_inv * e * a_inv);
    cv::Mat candidate_mask(n, 1, CV_8U, cv::Scalar(0));
    for (int i = 0; i < n; ++i) {
      if ((mask.empty() || mask[i]) && SampsonSquared(f_px, pixels1[i], pixels2[i]) <= gate_sq) {
        candidate_mask.at<uchar>(i) = 255;
        ++choice.num_inliers[c];
      }
    }
    if (choice.num_inliers[c] == 0) continue;
    cv::Mat e_cv(3, 3, CV_64F), r_cv, t_cv;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) e_cv.at<double>(i, j) = e(i, j);
    }
    int good = 0;
    try {
      // Only ever a 3 x 3 matrix here (G2).
      good = cv::recoverPose(e_cv, p1, p2, r_cv, t_cv, camera.fx_px, pp, candidate_mask);
    } catch (const cv::Exception&) {
      ++skipped;
      continue;
    }
    choice.num_good[c] = good;
    if (good <= (choice.index < 0 ? 0 : choice.num_good[choice.index])) continue;
    choice.index = c;
    for (int i = 0; i < 3; ++i) {
      choice.translation(i) = t_cv.at<double>(i);
      for (int j = 0; j < 3; ++j) choice.rotation(i, j) = r_cv.at<double>(i, j);
    }
    for (int i = 0; i < n; ++i) choice.good[i] = candidate_mask.at<uchar>(i) != 0;
  }
  std::ostringstream m;
  if (choice.index < 0) {
    m << "none of " << choice.num_candidates << " essential candidate(s) has an inlier in front of both cameras";
  } else {
    m << "candidate " << choice.index + 1 << " of " << choice.num_candidates << ", " << choice.num_good[choice.index]
      << "/" << n << " inliers in front of both cameras";
  }
  if (skipped > 0) m << " (" << skipped << " non-finite or rejected by recoverPose)";
  choice.message = m.str();
  return choice;
}

}  // namespace internal

TwoViewReport EstimateTwoViewOpenCv(const TwoViewOptions& options, const CameraIntrinsics& camera,
                                    const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2) {
  TwoViewReport report;
  // G1 is checked before the call: OpenCV answers too few points with an empty matrix, not an error.
  if (!internal::ScreenInput(options, camera, pixels1, pixels2, &report)) return report;
  const int n = static_cast<int>(pixels1.size());

  const std::vector<cv::Point2d> p1 = internal::OpenCvPoints(camera, pixels1);
  const std::vector<cv::Point2d> p2 = internal::OpenCvPoints(camera, pixels2);
  const cv::Point2d pp(camera.cx_px, camera.cy_px);
  cv::Mat essential, mask;
  try {
    essential = cv::findEssentialMat(p1, p2, camera.fx_px, pp, cv::RANSAC, options.ransac_confidence,
                                     options.ransac_threshold_px, options.ransac_max_iterations, mask);
  } catch (const cv::Exception& e) {
    return Finish(report, Outcome::kDegenerate, std::string("cv::findEssentialMat threw: ") + e.what());
  }
  // G1: an empty result is a failure. G2: a 3N x 3 result stacks N solutions; one is chosen explicitly.
  if (essential.empty()) {
    return Finish(report, Outcome::kDegenerate, "cv::findEssentialMat returned no essential matrix");
  }
  cv::Mat essential_64f;
  essential.convertTo(essential_64f, CV_64F);
  Eigen::MatrixXd stacked(essential_64f.rows, essential_64f.cols);
  for (int i = 0; i < essential_64f.rows; ++i) {
    for (int j = 0; j < essential_64f.cols; ++j) stacked(i, j) = essential_64f.at<double>(i, j);
  }
  std::vector<bool> ransac_mask(n, true);
  if (!mask.empty()) {
    for (int i = 0; i < n; ++i) ransac_mask[i] = mask.at<uchar>(i) != 0;
  }
  const internal::EssentialChoice choice =
      internal::ChooseEssentialCandidate(stacked, camera, pixels1, pixels2, ransac_mask, options.ransac_threshold_px);
  if (choice.index < 0) return Finish(report, Outcome::kDegenerate, choice.message);

  const Eigen::Matrix3d r = choice.rotation;
  const Eigen::Vector3d t = choice.translation;
  if (!r.allFinite() || !t.allFinite() || !(t.norm() > 0)) {
    return Finish(report, Outcome::kDegenerate, "recoverPose returned a non-finite pose");
  }
  std::vector<int> inliers;
  for (int i = 0; i < n; ++i) {
    if (choice.good[i]) {
      report.inliers[i] = true;
      inliers.push_back(i);
    }
  }
  report.num_inliers = static_cast<int>(inliers.size());
  report.rotation = r;
  report.translation_direction = t.normalized();
  report.fx_observable = false;
  const internal::Correspondences data = internal::MakeCorrespondences(camera, pixels1, pixels2);
  report.rms_epipolar_px =
      internal::RmsSymmetricEpipolarPx(camera, camera.fx_px, Rigid3(r, report.translation_direction), data, inliers);
  std::ostringstream m;
  m << "OpenCV: " << choice.message;
  if (report.num_inliers < options.min_inlier_ratio * n) {
    return Finish(report, Outcome::kTooManyOutliers, m.str() + ", below the inlier floor");
  }
  if (report.num_inliers < options.min_points) {
    return Finish(report, Outcome::kTooFewPoints, m.str() + ", too few");
  }
  report.translation_observable = true;
  return Finish(report, Outcome::kSuccess, m.str());
}

}  // namespace selfcal::twoview
