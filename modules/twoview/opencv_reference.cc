// The OpenCV comparison row: findEssentialMat (5-point RANSAC, known focal) + recoverPose. OpenCV types
// stay in this file.
#include <cmath>
#include <sstream>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview {

using internal::Finish;

TwoViewReport EstimateTwoViewOpenCv(const TwoViewOptions& options, const CameraIntrinsics& camera,
                                    const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2) {
  TwoViewReport report;
  // G1 is checked before the call: OpenCV answers too few points with an empty matrix, not an error.
  if (!internal::ScreenInput(options, camera, pixels1, pixels2, &report)) return report;
  const int n = static_cast<int>(pixels1.size());

  // OpenCV's camera has one focal: v is rescaled about c_y by 1/mu so that f_x applies to both axes.
  std::vector<cv::Point2d> p1(n), p2(n);
  for (int i = 0; i < n; ++i) {
    p1[i] = cv::Point2d(pixels1[i].x(), camera.cy_px + (pixels1[i].y() - camera.cy_px) / camera.mu);
    p2[i] = cv::Point2d(pixels2[i].x(), camera.cy_px + (pixels2[i].y() - camera.cy_px) / camera.mu);
  }
  const cv::Point2d pp(camera.cx_px, camera.cy_px);
  cv::Mat essential, mask;
  try {
    essential = cv::findEssentialMat(p1, p2, camera.fx_px, pp, cv::RANSAC, options.ransac_confidence,
                                     options.ransac_threshold_px, options.ransac_max_iterations, mask);
  } catch (const cv::Exception& e) {
    return Finish(report, Outcome::kDegenerate, std::string("cv::findEssentialMat threw: ") + e.what());
  }
  // G1, G2: an empty result is a failure; a 3N x 3 result stacks N solutions of the 5-point solver.
  if (essential.empty() || essential.cols != 3 || essential.rows % 3 != 0) {
    return Finish(report, Outcome::kDegenerate, "cv::findEssentialMat returned no 3x3 essential matrix");
  }

  // G2: score every 3x3 candidate by the points that survive recoverPose's cheirality test and keep the
  // best explicitly; ties keep the first. A non-3x3 matrix never reaches recoverPose.
  int best_good = -1;
  cv::Mat best_r, best_t, best_mask;
  try {
    for (int c = 0; c < essential.rows / 3; ++c) {
      const cv::Mat candidate = essential.rowRange(3 * c, 3 * c + 3).clone();
      cv::Mat r, t, candidate_mask = mask.clone();
      const int good = cv::recoverPose(candidate, p1, p2, r, t, camera.fx_px, pp, candidate_mask);
      if (good > best_good) {
        best_good = good;
        best_r = r;
        best_t = t;
        best_mask = candidate_mask;
      }
    }
  } catch (const cv::Exception& e) {
    return Finish(report, Outcome::kDegenerate, std::string("cv::recoverPose threw: ") + e.what());
  }

  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) {
    t(i) = best_t.at<double>(i);
    for (int j = 0; j < 3; ++j) r(i, j) = best_r.at<double>(i, j);
  }
  if (!r.allFinite() || !t.allFinite() || !(t.norm() > 0)) {
    return Finish(report, Outcome::kDegenerate, "recoverPose returned a non-finite pose (G8)");
  }
  std::vector<int> inliers;
  for (int i = 0; i < n; ++i) {
    if (best_mask.at<uchar>(i) != 0) {
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
  m << "OpenCV: " << essential.rows / 3 << " essential candidate(s), " << report.num_inliers << "/" << n
    << " inliers in front of both cameras";
  if (report.num_inliers < options.min_inlier_ratio * n) {
    return Finish(report, Outcome::kTooManyOutliers, m.str() + ", below the inlier floor (G7)");
  }
  if (report.num_inliers < options.min_points) {
    return Finish(report, Outcome::kTooFewPoints, m.str() + ", too few (G1)");
  }
  report.translation_observable = true;
  return Finish(report, Outcome::kSuccess, m.str());
}

}  // namespace selfcal::twoview
