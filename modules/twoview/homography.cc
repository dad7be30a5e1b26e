// Homography estimation (normalised DLT), transfer errors and Faugeras' decomposition, for the planar
// path (G4) and the pure-rotation check (G3).
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "twoview/two_view_internal.h"

namespace selfcal::twoview::internal {

bool HomographyDlt(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
                   const std::vector<int>& indices, Eigen::Matrix3d* h) {
  const int n = static_cast<int>(indices.size());
  if (n < 4) return false;
  Eigen::Matrix3d t1, t2;
  if (!NormalisingTransform(x1, indices, &t1) || !NormalisingTransform(x2, indices, &t2)) return false;
  // x2 x (H x1) = 0 gives two independent rows per correspondence.
  auto fill = [&](auto* design) {
    for (int r = 0; r < n; ++r) {
      const Eigen::Vector2d a = ApplyAffine(t1, x1[indices[r]]);
      const Eigen::Vector2d b = ApplyAffine(t2, x2[indices[r]]);
      design->row(2 * r) << 0, 0, 0, -a.x(), -a.y(), -1, b.y() * a.x(), b.y() * a.y(), b.y();
      design->row(2 * r + 1) << a.x(), a.y(), 1, 0, 0, 0, -b.x() * a.x(), -b.x() * a.y(), -b.x();
    }
  };
  // Three collinear points of four (or all points on one line) leave a second null direction.
  Eigen::Matrix<double, 9, 1> null;
  if (n == 4) {
    Eigen::Matrix<double, 8, 9> design;
    fill(&design);
    if (!MinimalNullVector(design, &null)) return false;
  } else {
    Eigen::MatrixXd design(2 * n, 9);
    fill(&design);
    if (!DesignNullVector(design, &null)) return false;
  }
  Eigen::Matrix3d hn;
  hn << null(0), null(1), null(2), null(3), null(4), null(5), null(6), null(7), null(8);
  Eigen::Matrix3d result = t2.inverse() * hn * t1;
  const double norm = result.norm();
  if (!(norm > 0) || !result.allFinite()) return false;
  // A homography that maps the plane to a line has no inverse and cannot be a camera-to-camera map.
  if (!(std::abs(result.determinant()) > kRankTolerance * norm * norm * norm)) return false;
  *h = result / norm;
  return true;
}

void TransferErrors(const Eigen::Matrix3d& h, const Eigen::Matrix3d& h_inv, const Eigen::Vector2d& x1,
                    const Eigen::Vector2d& x2, double* e12, double* e21) {
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d p2 = h * Eigen::Vector3d(x1.x(), x1.y(), 1);
  const Eigen::Vector3d p1 = h_inv * Eigen::Vector3d(x2.x(), x2.y(), 1);
  *e12 = p2.z() != 0 ? (p2.head<2>() / p2.z() - x2).squaredNorm() : inf;
  *e21 = p1.z() != 0 ? (p1.head<2>() / p1.z() - x1).squaredNorm() : inf;
}

std::vector<Rigid3> DecomposeHomography(const Eigen::Matrix3d& h_normalised) {
  // Faugeras & Lustman (1988): with H = U diag(d1, d2, d3) V^T and s = det(U) det(V), the normal in the
  // rotated frame is n' = (x1, 0, x3) with x1 = +-sqrt((d1^2 - d2^2)/(d1^2 - d3^2)) and
  // x3 = +-sqrt((d2^2 - d3^2)/(d1^2 - d3^2)); R = s U R' V^T and t = U t'. Two cases by the sign of the
  // plane distance (d' = +d2, d' = -d2), four sign choices each. Which of the eight is physical is left
  // to cheirality; H's own sign and scale do not matter because both cases are enumerated.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(h_normalised, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  const double s = u.determinant() * v.determinant();
  const Eigen::Vector3d d = svd.singularValues();
  const double d1 = d(0), d2 = d(1), d3 = d(2);
  // All singular values equal: H is a scaled rotation (t = 0), the plane and t are undefined.
  if (!(d1 - d3 > 1e-9 * d1)) return {};
  const double a1 = std::sqrt(std::max(0.0, (d1 * d1 - d2 * d2) / (d1 * d1 - d3 * d3)));
  const double a3 = std::sqrt(std::max(0.0, (d2 * d2 - d3 * d3) / (d1 * d1 - d3 * d3)));
  const double root = std::sqrt(std::max(0.0, (d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3)));
  const double x1s[4] = {a1, a1, -a1, -a1};
  const double x3s[4] = {a3, -a3, a3, -a3};
  std::vector<Rigid3> out;
  out.reserve(8);
  // d' = +d2
  const double cos_theta = (d2 * d2 + d1 * d3) / ((d1 + d3) * d2);
  for (int i = 0; i < 4; ++i) {
    const double sin_theta = (x1s[i] * x3s[i] > 0 ? 1.0 : -1.0) * root / ((d1 + d3) * d2);
    Eigen::Matrix3d rp;
    rp << cos_theta, 0, -sin_theta, 0, 1, 0, sin_theta, 0, cos_theta;
    const Eigen::Vector3d tp = (d1 - d3) * Eigen::Vector3d(x1s[i], 0, -x3s[i]);
    out.emplace_back(s * u * rp * v.transpose(), u * tp);
  }
  // d' = -d2
  const double cos_phi = (d1 * d3 - d2 * d2) / ((d1 - d3) * d2);
  for (int i = 0; i < 4; ++i) {
    const double sin_phi = (x1s[i] * x3s[i] > 0 ? 1.0 : -1.0) * root / ((d1 - d3) * d2);
    Eigen::Matrix3d rp;
    rp << cos_phi, 0, sin_phi, 0, -1, 0, sin_phi, 0, -cos_phi;
    const Eigen::Vector3d tp = (d1 + d3) * Eigen::Vector3d(x1s[i], 0, x3s[i]);
    out.emplace_back(s * u * rp * v.transpose(), u * tp);
  }
  for (Rigid3& pose : out) {
    pose.rotation = NearestRotation(pose.rotation);  // removes rounding; the formulas give exact rotations
    const double norm = pose.translation.norm();
    if (norm > 0) pose.translation /= norm;
  }
  return out;
}

bool PlaneOfDecomposition(const Eigen::Matrix3d& h_normalised, const Eigen::Matrix3d& rotation,
                          const Eigen::Vector3d& ref_bearing, Eigen::Vector3d* normal, Eigen::Vector3d* t_over_distance) {
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(h_normalised).singularValues();
  if (!(sv(1) > 0)) return false;
  Eigen::Matrix3d hs = h_normalised / sv(1);
  if (hs.determinant() < 0) hs = -hs;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(hs - rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(0) > 0) || s(1) > 1e-6 * (1 + s(0))) return false;
  *normal = svd.matrixV().col(0);
  *t_over_distance = s(0) * svd.matrixU().col(0);
  if (normal->dot(ref_bearing) < 0) {
    *normal = -*normal;
    *t_over_distance = -*t_over_distance;
  }
  return true;
}

}  // namespace selfcal::twoview::internal
