// Pure epipolar geometry: 8-point, Bougnoux focal, Theorem 1 factorisation, triangulation, cheirality
// (the choice among candidates, G5), distances.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "base/status.h"
#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"

namespace selfcal::twoview {
namespace internal {

// Hartley's normalisation: centroid to the origin, mean distance sqrt(2). Without it the 8-point design
// mixes entries of order 1e5 and 1, and the null vector loses most of its digits.
bool NormalisingTransform(const std::vector<Eigen::Vector2d>& x, const std::vector<int>& indices, Eigen::Matrix3d* t) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int i : indices) centroid += x[i];
  centroid /= static_cast<double>(indices.size());
  double mean_distance = 0;
  for (int i : indices) mean_distance += (x[i] - centroid).norm();
  mean_distance /= static_cast<double>(indices.size());
  if (!(mean_distance > 0) || !std::isfinite(mean_distance)) return false;
  const double s = std::sqrt(2.0) / mean_distance;
  *t << s, 0, -s * centroid.x(), 0, s, -s * centroid.y(), 0, 0, 1;
  return true;
}

Eigen::Vector2d ApplyAffine(const Eigen::Matrix3d& t, const Eigen::Vector2d& x) {
  return Eigen::Vector2d(t(0, 0) * x.x() + t(0, 2), t(1, 1) * x.y() + t(1, 2));
}

bool MinimalNullVector(const Eigen::Matrix<double, 8, 9>& design, Eigen::Matrix<double, 9, 1>* null) {
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 9, 8>> qr(design.transpose());
  const auto& r = qr.matrixQR();
  // Pivoting sorts |R_ii| downwards; the last one plays the role of the 8th singular value.
  if (!(std::abs(r(7, 7)) > kRankTolerance * std::abs(r(0, 0)))) return false;
  // Q e_9: the eight reflectors applied to one vector rather than to the identity.
  *null = Eigen::Matrix<double, 9, 1>::Unit(8);
  null->applyOnTheLeft(qr.householderQ());
  return true;
}

Correspondences MakeCorrespondences(const CameraIntrinsics& camera, const std::vector<Eigen::Vector2d>& pixels1,
                                    const std::vector<Eigen::Vector2d>& pixels2) {
  Correspondences c;
  c.pixels1 = pixels1;
  c.pixels2 = pixels2;
  c.centred1.reserve(pixels1.size());
  c.centred2.reserve(pixels2.size());
  for (size_t i = 0; i < pixels1.size(); ++i) {
    c.centred1.push_back(CenteredPixel(camera, pixels1[i]));
    c.centred2.push_back(CenteredPixel(camera, pixels2[i]));
  }
  return c;
}

Eigen::Matrix3d CentringMatrix(const CameraIntrinsics& camera) {
  Eigen::Matrix3d c;
  c << 1, 0, -camera.cx_px, 0, 1 / camera.mu, -camera.cy_px / camera.mu, 0, 0, 1;
  return c;
}

Eigen::Matrix3d FundamentalToPixels(const CameraIntrinsics& camera, const Eigen::Matrix3d& f_centred) {
  const Eigen::Matrix3d c = CentringMatrix(camera);
  return c.transpose() * f_centred * c;
}

Eigen::Matrix3d HomographyToPixels(const CameraIntrinsics& camera, const Eigen::Matrix3d& h_centred) {
  const Eigen::Matrix3d c = CentringMatrix(camera);
  return c.inverse() * h_centred * c;
}

bool EightPoint(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
                const std::vector<int>& indices, Eigen::Matrix3d* f) {
  const int n = static_cast<int>(indices.size());
  if (n < 8) return false;
  Eigen::Matrix3d t1, t2;
  if (!NormalisingTransform(x1, indices, &t1) || !NormalisingTransform(x2, indices, &t2)) return false;
  auto fill = [&](auto* design) {
    for (int r = 0; r < n; ++r) {
      const Eigen::Vector2d a = ApplyAffine(t1, x1[indices[r]]);
      const Eigen::Vector2d b = ApplyAffine(t2, x2[indices[r]]);
      design->row(r) << b.x() * a.x(), b.x() * a.y(), b.x(), b.y() * a.x(), b.y() * a.y(), b.y(), a.x(), a.y(), 1;
    }
  };
  // A second (near-)null direction: planar or collinear points, identical images, pure rotation. The
  // 8-point solution would then be an arbitrary member of a family of matrices.
  Eigen::Matrix<double, 9, 1> null;
  if (n == 8) {
    Eigen::Matrix<double, 8, 9> design;
    fill(&design);
    if (!MinimalNullVector(design, &null)) return false;
  } else {
    Eigen::MatrixXd design(n, 9);
    fill(&design);
    if (!DesignNullVector(design, &null)) return false;
  }
  Eigen::Matrix3d fn;
  fn << null(0), null(1), null(2), null(3), null(4), null(5), null(6), null(7), null(8);
  Eigen::JacobiSVD<Eigen::Matrix3d> svd_f(fn, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = svd_f.singularValues();
  if (!(s(1) > kRankTolerance * s(0))) return false;  // rank 1: no epipolar geometry
  s(2) = 0;
  const Eigen::Matrix3d rank2 = svd_f.matrixU() * s.asDiagonal() * svd_f.matrixV().transpose();
  Eigen::Matrix3d result = t2.transpose() * rank2 * t1;
  const double norm = result.norm();
  if (!(norm > 0) || !result.allFinite()) return false;
  *f = result / norm;
  return true;
}

double SampsonSquared(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const Eigen::Vector3d h1(x1.x(), x1.y(), 1), h2(x2.x(), x2.y(), 1);
  const Eigen::Vector3d fx1 = f * h1;
  const Eigen::Vector3d ftx2 = f.transpose() * h2;
  const double e = h2.dot(fx1);
  const double denominator = fx1.head<2>().squaredNorm() + ftx2.head<2>().squaredNorm();
  if (!(denominator > 0)) return std::numeric_limits<double>::infinity();
  return e * e / denominator;
}

void EpipolarDistances(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2, double* d1,
                       double* d2) {
  const Eigen::Vector3d h1(x1.x(), x1.y(), 1), h2(x2.x(), x2.y(), 1);
  const Eigen::Vector3d line2 = f * h1;
  const Eigen::Vector3d line1 = f.transpose() * h2;
  const double e = h2.dot(line2);
  const double n2 = line2.head<2>().norm(), n1 = line1.head<2>().norm();
  const double inf = std::numeric_limits<double>::infinity();
  *d2 = n2 > 0 ? e / n2 : inf;
  *d1 = n1 > 0 ? e / n1 : inf;
}

double AxisCoplanaritySine(const Eigen::Matrix3d& f_centred, double fx_px) {
  // In centred coordinates the principal point is p = (0, 0, 1). l = F p is the image in view 2 of the
  // epipolar plane that contains optical axis 1; its distance d from p' (px) over f is the tangent of
  // the angle between axis 2 and that plane. Symmetrically for view 1.
  const Eigen::Vector3d p(0, 0, 1);
  auto sine = [fx_px](const Eigen::Vector3d& line) {
    const double in_plane = line.head<2>().norm();
    if (!(in_plane > 0)) return 1.0;
    const double d = std::abs(line.z()) / in_plane;
    return d / std::hypot(fx_px, d);
  };
  return std::min(sine(f_centred * p), sine(f_centred.transpose() * p));
}

namespace {

// The signs of both depths of TriangulateTwoView's point, when they can be told without it: the same
// least-squares problem solved through its 3x3 normal equations by the adjugate, about ten times
// cheaper than the column-pivoted QR. Its error and the QR's are both below ~eps cond(N) (|x| + |b|)
// (normal equations: eps cond(M)^2 |x|; QR: eps (cond(M) |x| + cond(M)^2 |r| / |M|), |M| >= 1, |r| <= |b|),
// where cond(N) = cond(M)^2 is bounded by |N|_F |adj N|_F / |det N|. A depth further from zero than
// 1e4 times that bound has the same sign in both solutions; otherwise (small parallax, a point near a
// camera centre, non-finite input) the caller asks the QR. Returns false in that case.
bool DepthSignsByNormalEquations(const Rigid3& cam2_from_cam1, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                 bool* in_front1, bool* in_front2) {
  const Eigen::Matrix3d& r = cam2_from_cam1.rotation;
  const Eigen::Vector3d& t = cam2_from_cam1.translation;
  // Rows of TriangulateTwoView's system: (1, 0, -x1), (0, 1, -y1) with right-hand side 0, and a, b below.
  const Eigen::Vector3d a = x2.x() * r.row(2).transpose() - r.row(0).transpose();
  const Eigen::Vector3d b = x2.y() * r.row(2).transpose() - r.row(1).transpose();
  const double rhs_a = t.x() - x2.x() * t.z(), rhs_b = t.y() - x2.y() * t.z();
  Eigen::Matrix3d n = a * a.transpose() + b * b.transpose();
  n(0, 0) += 1;
  n(1, 1) += 1;
  n(0, 2) -= x1.x();
  n(2, 0) -= x1.x();
  n(1, 2) -= x1.y();
  n(2, 1) -= x1.y();
  n(2, 2) += x1.squaredNorm();
  const Eigen::Vector3d g = a * rhs_a + b * rhs_b;
  Eigen::Matrix3d adj;  // symmetric
  adj(0, 0) = n(1, 1) * n(2, 2) - n(1, 2) * n(2, 1);
  adj(0, 1) = n(0, 2) * n(2, 1) - n(0, 1) * n(2, 2);
  adj(0, 2) = n(0, 1) * n(1, 2) - n(0, 2) * n(1, 1);
  adj(1, 1) = n(0, 0) * n(2, 2) - n(0, 2) * n(2, 0);
  adj(1, 2) = n(0, 2) * n(1, 0) - n(0, 0) * n(1, 2);
  adj(2, 2) = n(0, 0) * n(1, 1) - n(0, 1) * n(1, 0);
  adj(1, 0) = adj(0, 1);
  adj(2, 0) = adj(0, 2);
  adj(2, 1) = adj(1, 2);
  const double det = n(0, 0) * adj(0, 0) + n(0, 1) * adj(1, 0) + n(0, 2) * adj(2, 0);
  const Eigen::Vector3d p1 = adj * g / det;
  const double cond_bound = n.norm() * adj.norm() / std::abs(det);
  const double margin =
      1e4 * std::numeric_limits<double>::epsilon() * cond_bound * (p1.norm() + std::hypot(rhs_a, rhs_b) + t.norm());
  const double depth2 = r.row(2).dot(p1) + t.z();
  // NaN anywhere (det = 0, non-finite input) fails these comparisons.
  if (!(std::abs(p1.z()) > margin) || !(std::abs(depth2) > margin)) return false;
  *in_front1 = p1.z() > 0;
  *in_front2 = depth2 > 0;
  return true;
}

}  // namespace

CheiralityCount CountCheirality(const Rigid3& cam2_from_cam1, const std::vector<Eigen::Vector2d>& n1,
                                const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices,
                                double min_parallax_rad) {
  CheiralityCount count;
  const double cos_min = std::cos(min_parallax_rad);
  for (int i : indices) {
    // Only the signs of the depths count; TriangulateTwoView's QR only where a cheaper solve cannot
    // vouch for them.
    bool front1 = false, front2 = false;
    if (!DepthSignsByNormalEquations(cam2_from_cam1, n1[i], n2[i], &front1, &front2)) {
      const Eigen::Vector3d p1 = TriangulateTwoView(cam2_from_cam1, n1[i], n2[i]);
      if (!p1.allFinite()) continue;
      const Eigen::Vector3d p2 = cam2_from_cam1 * p1;
      front1 = p1.z() > 0;
      front2 = p2.z() > 0;
    }
    if (front1 && front2) {
      ++count.in_front;
      continue;
    }
    const Eigen::Vector3d ray1 = cam2_from_cam1.rotation * Eigen::Vector3d(n1[i].x(), n1[i].y(), 1).normalized();
    const Eigen::Vector3d ray2 = Eigen::Vector3d(n2[i].x(), n2[i].y(), 1).normalized();
    if (ray1.dot(ray2) <= cos_min) ++count.behind;
  }
  return count;
}

namespace {

// G5: the winner must hold more than half of the inliers in front of both cameras and leave at most 10 %
// confidently behind (ORB-SLAM2 asks 90 % in front; the slack is for outliers that slipped under the
// threshold). Every other candidate must be out of the running: either it holds clearly fewer points in
// front (below 0.7 of the winner, ORB-SLAM2's rule), or it puts clearly more points confidently behind a
// camera than the winner does: at least max(3, 5 % of the inliers) more. "Confidently" means a
// triangulation angle of at least two threshold-sized pixel errors, where noise flips a depth sign with
// probability well under 1 %. The second test matters for planes: the dual decomposition of a lateral
// motion typically keeps two thirds of the points in front, too many for the ratio, yet puts several
// clearly behind, which no single plane seen by both cameras can do.
constexpr double kSecondBestRatio = 0.7;
constexpr double kMinInFrontFraction = 0.5;
constexpr double kMaxBehindFraction = 0.1;
constexpr double kRefutingBehindFraction = 0.05;
constexpr int kRefutingBehindMin = 3;

}  // namespace

// Candidates that coincide (Faugeras' solutions repeat when two singular values of H are equal) are one
// hypothesis and must not compete. min_parallax_rad: below it the sign of a depth may be noise.
CheiralityChoice ChooseByCheirality(const std::vector<Rigid3>& candidates, const std::vector<Eigen::Vector2d>& n1,
                                    const std::vector<Eigen::Vector2d>& n2, const std::vector<int>& indices,
                                    double min_parallax_rad) {
  CheiralityChoice choice;
  if (candidates.empty()) return choice;
  std::vector<internal::CheiralityCount> counts;
  for (const Rigid3& c : candidates) counts.push_back(internal::CountCheirality(c, n1, n2, indices, min_parallax_rad));
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (choice.best < 0 || counts[c].in_front > counts[choice.best].in_front) choice.best = static_cast<int>(c);
  }
  const double n = static_cast<double>(indices.size());
  const internal::CheiralityCount& best = counts[choice.best];
  choice.best_in_front = best.in_front;
  choice.best_behind = best.behind;
  choice.clear = best.in_front >= kMinInFrontFraction * n && best.behind <= kMaxBehindFraction * n;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const Rigid3& a = candidates[c];
    const Rigid3& b = candidates[choice.best];
    const bool same =
        RotationAngle(a.rotation.transpose() * b.rotation) < 1e-9 && (a.translation - b.translation).norm() < 1e-9;
    if (same) continue;
    const double refuting = std::max<double>(kRefutingBehindMin, kRefutingBehindFraction * n);
    const bool ruled_out =
        counts[c].in_front < kSecondBestRatio * best.in_front || counts[c].behind - best.behind >= refuting;
    if (!ruled_out) {
      choice.clear = false;
      if (counts[c].in_front > choice.runner_up_in_front) {
        choice.runner_up_in_front = counts[c].in_front;
        choice.runner_up_behind = counts[c].behind;
        choice.runner_up = static_cast<int>(c);
      }
    }
  }
  return choice;
}

Eigen::Matrix3d FundamentalFromPose(double fx_px, const Rigid3& cam2_from_cam1) {
  const Eigen::Matrix3d a_inv = Eigen::Vector3d(1 / fx_px, 1 / fx_px, 1).asDiagonal();
  return a_inv * Skew<double>(cam2_from_cam1.translation) * cam2_from_cam1.rotation * a_inv;
}

double RmsSymmetricEpipolarPx(const CameraIntrinsics& camera, double fx_px, const Rigid3& cam2_from_cam1,
                              const Correspondences& data, const std::vector<int>& indices) {
  if (indices.empty()) return -1;
  const Eigen::Matrix3d f_px = FundamentalToPixels(camera, FundamentalFromPose(fx_px, cam2_from_cam1));
  double sum = 0;
  for (int i : indices) {
    const double d = SymmetricEpipolarDistance(f_px, data.pixels1[i], data.pixels2[i]);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(indices.size()));
}

}  // namespace internal

Eigen::Matrix3d EightPointFundamental(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2) {
  SELFCAL_CHECK(x1.size() == x2.size(), "EightPointFundamental: " << x1.size() << " vs " << x2.size() << " points");
  SELFCAL_CHECK(x1.size() >= 8, "EightPointFundamental needs >= 8 correspondences, got " << x1.size());
  std::vector<int> all(x1.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  Eigen::Matrix3d f = Eigen::Matrix3d::Zero();
  // A degenerate configuration returns the zero matrix: the caller sees rank 0 rather than a random
  // member of the solution family.
  internal::EightPoint(x1, x2, all, &f);
  return f;
}

bool FocalFromFundamental(const Eigen::Matrix3d& f_centered, double min_observability, double* fx_px,
                          double* observability) {
  // Bougnoux (1998) with both principal points at the origin of the centred coordinates:
  //   f1^2 = -(p2^T [e2]x I3 F p1)(p1^T F^T p2) / (p2^T [e2]x I3 F I3 F^T p2),  I3 = diag(1, 1, 0),
  // and f2^2 by swapping the views (F -> F^T). Equal focal lengths: both estimate the same f^2, so
  // their mean is used. Both numerator and denominator vanish when p2^T F p1 = 0, i.e. when the
  // principal rays are coplanar (the optical axes intersect): f is then unobservable from the pair.
  const Eigen::Vector3d p(0, 0, 1);
  const Eigen::Matrix3d i3 = Eigen::Vector3d(1, 1, 0).asDiagonal();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(f_centered, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d e2 = svd.matrixU().col(2);  // F^T e2 = 0
  const Eigen::Vector3d e1 = svd.matrixV().col(2);  // F e1 = 0
  auto bougnoux = [&](const Eigen::Matrix3d& f, const Eigen::Vector3d& e_other) {
    const Eigen::RowVector3d left = p.transpose() * Skew<double>(e_other) * i3;
    const double numerator = (left * f * p).value() * (p.transpose() * f.transpose() * p).value();
    const double denominator = (left * f * i3 * f.transpose() * p).value();
    return -numerator / denominator;
  };
  const double f1_squared = bougnoux(f_centered, e2);
  const double f2_squared = bougnoux(f_centered.transpose(), e1);
  const double f_squared = 0.5 * (f1_squared + f2_squared);
  const bool positive = std::isfinite(f_squared) && f1_squared > 0 && f2_squared > 0;
  const double f = positive ? std::sqrt(f_squared) : 0.0;
  const double measure = positive ? internal::AxisCoplanaritySine(f_centered, f) : 0.0;
  if (observability != nullptr) *observability = measure;
  if (!positive || !(measure >= min_observability)) return false;
  *fx_px = f;
  return true;
}

std::vector<Rigid3> FactorEssential(const Eigen::Matrix3d& essential) {
  // Theorem 1: Q = U D V^T, [t]x ~ U Z U^T, R ~ U E V^T or U E^T V^T. U and V are made proper rotations
  // (flipping a singular vector only flips the sign of Q, which is defined up to scale anyway) so that
  // both R candidates have det +1; t = +-u3, the null vector of Q^T.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(essential, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  if (u.determinant() < 0) u = -u;
  if (v.determinant() < 0) v = -v;
  Eigen::Matrix3d w;
  w << 0, 1, 0, -1, 0, 0, 0, 0, 1;
  const Eigen::Matrix3d ra = u * w * v.transpose();
  const Eigen::Matrix3d rb = u * w.transpose() * v.transpose();
  const Eigen::Vector3d t = u.col(2);
  return {Rigid3(ra, t), Rigid3(ra, -t), Rigid3(rb, t), Rigid3(rb, -t)};
}

Eigen::Vector3d TriangulateTwoView(const Rigid3& cam2_from_cam1, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  // DLT rows x * P_3 - P_1 and y * P_3 - P_2 for P1 = [I | 0], P2 = [R | t], solved for the inhomogeneous
  // point: four equations, three unknowns, Householder QR.
  Eigen::Matrix<double, 4, 4> a;
  a.row(0) << 1, 0, -x1.x(), 0;
  a.row(1) << 0, 1, -x1.y(), 0;
  const Eigen::Matrix3d& r = cam2_from_cam1.rotation;
  const Eigen::Vector3d& t = cam2_from_cam1.translation;
  a.row(2) << (x2.x() * r.row(2) - r.row(0)), x2.x() * t.z() - t.x();
  a.row(3) << (x2.y() * r.row(2) - r.row(1)), x2.y() * t.z() - t.y();
  const Eigen::Matrix<double, 4, 3> m = a.leftCols<3>();
  const Eigen::Vector4d rhs = -a.col(3);
  return m.colPivHouseholderQr().solve(rhs);
}

double SymmetricEpipolarDistance(const Eigen::Matrix3d& f, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  double d1 = 0, d2 = 0;
  internal::EpipolarDistances(f, x1, x2, &d1, &d2);
  return std::hypot(d1, d2);
}

}  // namespace selfcal::twoview
