#include "external/tracker_identification.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <Eigen/SVD>

#include "base/status.h"

namespace selfcal::external {

namespace {

Rigid3 FromRotation(const Eigen::Matrix3d& r) { return Rigid3::FromRotation(r); }

double WrapAngle(double a) { return std::remainder(a, 2.0 * kPi); }

// Closest points of two non-parallel lines (p + s u, c + t v).
void ClosestPoints(const Eigen::Vector3d& p, const Eigen::Vector3d& u, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& v, Eigen::Vector3d* on_first, Eigen::Vector3d* on_second) {
  const Eigen::Vector3d w = p - c;
  const double a = u.dot(u), b = u.dot(v), cc = v.dot(v), d = u.dot(w), e = v.dot(w);
  const double den = a * cc - b * b;
  const double s = (b * e - cc * d) / den, t = (a * e - b * d) / den;
  *on_first = p + s * u;
  *on_second = c + t * v;
}

Rigid3 Link(double alpha, double a, double beta) {
  return Rigid3(RotX(alpha) * RotY(beta), RotX(alpha) * Eigen::Vector3d(a, 0, 0));
}

ErrorStats Summarise(const std::vector<double>& position, const std::vector<double>& rotation) {
  ErrorStats s;
  s.count = static_cast<int>(position.size());
  if (s.count == 0) return s;
  double sum = 0, sum2 = 0, rot2 = 0;
  for (size_t i = 0; i < position.size(); ++i) {
    sum += position[i];
    sum2 += position[i] * position[i];
    rot2 += rotation[i] * rotation[i];
    s.max_m = std::max(s.max_m, position[i]);
  }
  s.mean_m = sum / s.count;
  s.rms_m = std::sqrt(sum2 / s.count);
  s.rms_rotation_rad = std::sqrt(rot2 / s.count);
  return s;
}

}  // namespace

Rigid3 FrameFromThreePoints(const Eigen::Vector3d& p1, const Eigen::Vector3d& p2, const Eigen::Vector3d& p3) {
  const Eigen::Vector3d e12 = p2 - p1, e13 = p3 - p1;
  const Eigen::Vector3d n = e12.cross(e13);
  SELFCAL_CHECK(e12.norm() > 0 && n.norm() > 1e-6 * e12.norm() * e13.norm(),
                "FrameFromThreePoints: points collinear or coincident");
  Eigen::Matrix3d r;
  r.col(0) = e12.normalized();
  r.col(2) = n.normalized();
  r.col(1) = r.col(2).cross(r.col(0));
  return Rigid3(r, p1);
}

NestDistanceStats NestDistances(const std::vector<SmrTriple>& rows) {
  NestDistanceStats s;
  if (rows.empty()) return s;
  constexpr int kPairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> d;
    for (const SmrTriple& r : rows) d.push_back((r[kPairs[k][0]] - r[kPairs[k][1]]).norm());
    double mean = 0;
    for (double x : d) mean += x;
    mean /= static_cast<double>(d.size());
    double var = 0;
    for (double x : d) var += (x - mean) * (x - mean);
    s.mean_m[k] = mean;
    s.stddev_m[k] = d.size() > 1 ? std::sqrt(var / static_cast<double>(d.size() - 1)) : 0.0;
    const auto [lo, hi] = std::minmax_element(d.begin(), d.end());
    s.range_m[k] = *hi - *lo;
    s.max_stddev_m = std::max(s.max_stddev_m, s.stddev_m[k]);
    s.max_range_m = std::max(s.max_range_m, s.range_m[k]);
  }
  return s;
}

CircleFit FitCircle(const std::vector<Eigen::Vector3d>& points) {
  SELFCAL_CHECK(points.size() >= 3, "FitCircle: " << points.size() << " points, need 3");
  const int n = static_cast<int>(points.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= n;
  Eigen::MatrixXd centred(n, 3);
  for (int i = 0; i < n; ++i) centred.row(i) = (points[i] - mean).transpose();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
  CircleFit fit;
  const Eigen::Vector3d ex = svd.matrixV().col(0), ey = svd.matrixV().col(1);
  fit.normal = svd.matrixV().col(2);
  // Kasa: x^2 + y^2 + D x + E y + F = 0 in the plane coordinates.
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const double x = (points[i] - mean).dot(ex), y = (points[i] - mean).dot(ey);
    a.row(i) << x, y, 1.0;
    b[i] = -(x * x + y * y);
  }
  const Eigen::Vector3d def = a.colPivHouseholderQr().solve(b);
  const double cx = -def[0] / 2, cy = -def[1] / 2;
  fit.radius_m = std::sqrt(std::max(0.0, cx * cx + cy * cy - def[2]));
  fit.centre = mean + cx * ex + cy * ey;
  double radial2 = 0, plane2 = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d v = p - fit.centre;
    const double h = v.dot(fit.normal);
    const double r = (v - h * fit.normal).norm();
    radial2 += (r - fit.radius_m) * (r - fit.radius_m);
    plane2 += h * h;
  }
  fit.rms_radial_m = std::sqrt(radial2 / n);
  fit.rms_out_of_plane_m = std::sqrt(plane2 / n);
  return fit;
}

bool FitJointAxis(const std::vector<SmrTriple>& points, const std::vector<Rigid3>& poses, const std::vector<double>& q,
                  AxisFit* fit, std::string* why) {
  SELFCAL_CHECK(points.size() == poses.size() && q.size() == poses.size(), "FitJointAxis: size mismatch");
  // Distinct positions on the circle (q modulo 2 pi).
  std::vector<int> distinct;
  for (size_t i = 0; i < q.size(); ++i) {
    bool seen = false;
    for (int j : distinct) seen = seen || std::abs(WrapAngle(q[i] - q[j])) < 1e-6;
    if (!seen) distinct.push_back(static_cast<int>(i));
  }
  if (distinct.size() < 3) {
    *why = "joint " + std::to_string(fit->joint) + ": " + std::to_string(distinct.size()) +
           " distinct positions in its sweep, need 3";
    return false;
  }
  // Rotation sense (and angle per joint angle) from row pairs with moderate motion.
  Eigen::Vector3d rotation_axis = Eigen::Vector3d::Zero();
  double ratio_sum = 0;
  int ratio_count = 0;
  for (size_t a = 0; a < q.size(); ++a) {
    for (size_t b = a + 1; b < q.size(); ++b) {
      const double dq = WrapAngle(q[b] - q[a]);
      if (std::abs(dq) < 0.05 || std::abs(dq) > 2.8) continue;
      const Eigen::Vector3d w = LogSO3(poses[b].rotation * poses[a].rotation.transpose());
      rotation_axis += (dq > 0 ? 1.0 : -1.0) * w;
      ratio_sum += w.norm() / std::abs(dq);
      ++ratio_count;
    }
  }
  if (ratio_count == 0 || rotation_axis.norm() < 1e-9) {
    *why = "joint " + std::to_string(fit->joint) + ": no pair of sweep rows between 3 and 160 deg apart";
    return false;
  }
  rotation_axis.normalize();
  fit->angle_ratio = ratio_sum / ratio_count;

  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero(), centre_sum = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector3d, 3> centres;
  double radial2 = 0, plane2 = 0;
  for (int k = 0; k < 3; ++k) {
    std::vector<Eigen::Vector3d> pts;
    for (int i : distinct) pts.push_back(points[i][k]);
    const CircleFit c = FitCircle(pts);
    normal_sum += (c.normal.dot(rotation_axis) >= 0 ? 1.0 : -1.0) * c.normal;
    centres[k] = c.centre;
    centre_sum += c.centre;
    radial2 += c.rms_radial_m * c.rms_radial_m;
    plane2 += c.rms_out_of_plane_m * c.rms_out_of_plane_m;
  }
  fit->direction = normal_sum.normalized();
  fit->point = centre_sum / 3.0;
  fit->rms_radial_m = std::sqrt(radial2 / 3);
  fit->rms_out_of_plane_m = std::sqrt(plane2 / 3);
  fit->normal_vs_rotation_rad = std::acos(std::clamp(fit->direction.dot(rotation_axis), -1.0, 1.0));
  fit->max_centre_off_axis_m = 0;
  for (const auto& c : centres) {
    const Eigen::Vector3d v = c - fit->point;
    fit->max_centre_off_axis_m = std::max(fit->max_centre_off_axis_m, (v - v.dot(fit->direction) * fit->direction).norm());
  }
  return true;
}

RobotModel ModelFromAxisLines(const std::string& name, const std::vector<Eigen::Vector3d>& directions,
                              const std::vector<Eigen::Vector3d>& points, const Eigen::VectorXd& q_ref,
                              double parallel_tol_rad) {
  const int n = static_cast<int>(directions.size());
  SELFCAL_CHECK(n >= 2 && static_cast<int>(points.size()) == n && q_ref.size() == n,
                "ModelFromAxisLines: " << n << " directions, " << points.size() << " points, " << q_ref.size()
                                       << " joints");
  std::vector<Eigen::Vector3d> z(n);
  for (int i = 0; i < n; ++i) z[i] = directions[i].normalized();

  // frames[i]: tracker_from_frame_{i+1} at q_ref; foot: the point on axis i+1 reached by link i+1's
  // alpha/a/beta (origin of the next frame before its d).
  std::vector<Rigid3> frames(n);
  RobotModel model;
  model.name = name;
  model.links.resize(n);
  model.limits.assign(n, JointLimits{-4 * kPi, 4 * kPi});

  // Origin of frame 1: foot of the common normal with axis 2 (or the projection of the tracker origin).
  Eigen::Vector3d origin = points[0] - points[0].dot(z[0]) * z[0];
  std::vector<double> alpha(n + 1, 0.0), a(n + 1, 0.0), beta(n + 1, 0.0);  // link i+1's, for i = 1..n-1
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d x;
    Eigen::Vector3d next_foot = origin;
    if (i + 1 < n) {
      const Eigen::Vector3d cross = z[i].cross(z[i + 1]);
      if (cross.norm() > std::sin(parallel_tol_rad)) {
        // Common normal: its foot on axis i is this frame's origin.
        Eigen::Vector3d on_i, on_next;
        ClosestPoints(points[i], z[i], points[i + 1], z[i + 1], &on_i, &on_next);
        origin = on_i;
        x = cross.normalized();
        a[i + 1] = (on_next - on_i).dot(x);
        alpha[i + 1] = std::atan2(cross.norm(), z[i].dot(z[i + 1]));
        beta[i + 1] = 0;
        next_foot = on_next;
      } else {
        // Hayati: keep the origin; the next axis meets the plane through it normal to z[i] at the foot.
        const double t = (origin - points[i + 1]).dot(z[i]) / z[i + 1].dot(z[i]);
        next_foot = points[i + 1] + t * z[i + 1];
        const Eigen::Vector3d v = next_foot - origin;
        SELFCAL_CHECK(v.norm() > 1e-9, "ModelFromAxisLines: axes " << i + 1 << " and " << i + 2 << " coincide");
        x = v.normalized();
        a[i + 1] = v.norm();
      }
      Eigen::Matrix3d r;
      r.col(0) = x;
      r.col(2) = z[i];
      r.col(1) = z[i].cross(x);
      frames[i] = Rigid3(r, origin);
      if (beta[i + 1] == 0 && cross.norm() <= std::sin(parallel_tol_rad)) {
        const Eigen::Vector3d zl = r.transpose() * z[i + 1];  // (sin b, -sin a cos b, cos a cos b)
        beta[i + 1] = std::asin(std::clamp(zl.x(), -1.0, 1.0));
        alpha[i + 1] = std::atan2(-zl.y(), zl.z());
      }
    } else {
      // Last frame: origin at the previous foot, x such that theta_n = 0.
      const Rigid3 pre = frames[i - 1] * Link(alpha[i], a[i], beta[i]);
      frames[i] = pre * FromRotation(RotZ(q_ref[i]));
      frames[i].translation = origin;
    }
    origin = next_foot;
  }
  // Base: frame 1 turned back by q_ref[0], so link 1 has alpha = a = beta = theta = d = 0.
  model.base_from_link0 = frames[0] * FromRotation(RotZ(-q_ref[0]));
  for (int i = 0; i < n; ++i) {
    const Rigid3 prev = i == 0 ? model.base_from_link0 : frames[i - 1];
    const Rigid3 g = (prev * Link(alpha[i], a[i], beta[i])).Inverse() * frames[i];  // RotZ(phi) TransZ(d)
    LinkParameters& l = model.links[i];
    l.alpha = alpha[i];
    l.a = a[i];
    l.beta = beta[i];
    l.theta = WrapAngle(std::atan2(g.rotation(1, 0), g.rotation(0, 0)) - q_ref[i]);
    l.d = g.translation.z();
  }
  model.link_n_from_flange = Rigid3::Identity();
  model.flange_from_cam = Rigid3::Identity();
  return model;
}

Eigen::VectorXd ModelJointsFromController(const Eigen::VectorXd& controller_rad, double j3_coupling) {
  Eigen::VectorXd q = controller_rad;
  if (q.size() >= 3) q[2] += j3_coupling * controller_rad[1];
  return q;
}

std::string TrackerIdentificationOptions::Validate() const {
  std::string problems;
  if (holdout_every < 0 || holdout_every == 1) problems += "holdout_every must be 0 or >= 2\n";
  if (!(parallel_tol_rad > 0 && parallel_tol_rad < 0.5)) problems += "parallel_tol_rad must be in (0, 0.5)\n";
  problems += identification.Validate();
  return problems;
}

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kNotRun: return "not_run";
    case Outcome::kSuccess: return "success";
    case Outcome::kInvalidInput: return "invalid_input";
    case Outcome::kDegenerate: return "degenerate";
    case Outcome::kNoConvergence: return "no_convergence";
    case Outcome::kFailure: return "failure";
  }
  return "unknown";
}

ErrorStats RelativePoseErrors(const RobotModel& model, const Eigen::VectorXd& rho, const std::vector<Eigen::VectorXd>& q,
                              const std::vector<Rigid3>& tracker_from_nest, int reference_row,
                              const std::vector<int>& rows) {
  const Rigid3 model_ref = BaseFromCam(model, rho, q[reference_row]);
  std::vector<double> position, rotation;
  for (int i : rows) {
    if (i == reference_row) continue;
    const Rigid3 predicted = model_ref.Inverse() * BaseFromCam(model, rho, q[i]);
    const Rigid3 measured = tracker_from_nest[reference_row].Inverse() * tracker_from_nest[i];
    const PoseDifference d = ComparePoses(predicted, measured);
    position.push_back(d.position_m);
    rotation.push_back(d.rotation_rad);
  }
  return Summarise(position, rotation);
}

namespace {

// Most common value per joint: the configuration every sweep starts from.
Eigen::VectorXd MostCommonJoints(const std::vector<Eigen::VectorXd>& q, int n) {
  Eigen::VectorXd q_ref(n);
  for (int j = 0; j < n; ++j) {
    std::map<double, int> counts;
    for (const auto& qi : q) ++counts[qi[j]];
    q_ref[j] = std::max_element(counts.begin(), counts.end(), [](const auto& l, const auto& r) {
                 return l.second < r.second;
               })->first;
  }
  return q_ref;
}

// Identification and holdout rows (every holdout_every-th from row 1), and the reference: the
// identification row closest to q_ref (modulo 2 pi).
void SplitRows(const std::vector<Eigen::VectorXd>& q, int holdout_every, TrackerIdentificationReport* report) {
  const int num_rows = static_cast<int>(q.size());
  const int n = static_cast<int>(report->q_ref.size());
  for (int i = 0; i < num_rows; ++i) {
    const bool held = holdout_every >= 2 && i % holdout_every == 1;
    (held ? report->holdout_rows : report->identification_rows).push_back(i);
  }
  double best = 1e300;
  for (int i : report->identification_rows) {
    double dist = 0;
    for (int j = 0; j < n; ++j) dist += std::abs(WrapAngle(q[i][j] - report->q_ref[j]));
    if (dist < best - 1e-12) {
      best = dist;
      report->reference_row = i;
    }
  }
}

// Rows at q_ref (modulo 2 pi, e.g. J4 = +-360 deg): the same pose measured again; their count and the
// largest distance between their nest positions (m).
void MeasureRepeats(const std::vector<Eigen::VectorXd>& q, const std::vector<Rigid3>& tracker_from_nest,
                    TrackerIdentificationReport* report) {
  const int num_rows = static_cast<int>(q.size());
  const int n = static_cast<int>(report->q_ref.size());
  std::vector<int> repeats;
  for (int i = 0; i < num_rows; ++i) {
    bool same = true;
    for (int j = 0; j < n; ++j) same = same && std::abs(WrapAngle(q[i][j] - report->q_ref[j])) < 1e-9;
    if (same) repeats.push_back(i);
  }
  report->repeat_rows = static_cast<int>(repeats.size());
  for (size_t a = 0; a < repeats.size(); ++a) {
    for (size_t b = a + 1; b < repeats.size(); ++b) {
      report->repeat_max_m = std::max(
          report->repeat_max_m, (tracker_from_nest[repeats[a]].translation - tracker_from_nest[repeats[b]].translation).norm());
    }
  }
}

// Axis fits from the identification rows only: for joint j, the rows where every other joint is at
// q_ref. False, with the reason in *why, when a joint's sweep does not determine its axis.
bool FitAxes(const std::vector<SmrTriple>& points, const std::vector<Rigid3>& tracker_from_nest,
             const std::vector<Eigen::VectorXd>& q, TrackerIdentificationReport* report, std::string* why) {
  const int n = static_cast<int>(report->q_ref.size());
  for (int j = 0; j < n; ++j) {
    AxisFit fit;
    fit.joint = j + 1;
    std::vector<SmrTriple> sweep_points;
    std::vector<Rigid3> sweep_poses;
    std::vector<double> sweep_q;
    for (int i : report->identification_rows) {
      bool others_at_ref = true;
      for (int k = 0; k < n; ++k) others_at_ref = others_at_ref && (k == j || q[i][k] == report->q_ref[k]);
      if (!others_at_ref) continue;
      fit.rows.push_back(i);
      sweep_points.push_back(points[i]);
      sweep_poses.push_back(tracker_from_nest[i]);
      sweep_q.push_back(q[i][j]);
    }
    if (!FitJointAxis(sweep_points, sweep_poses, sweep_q, &fit, why)) return false;
    report->axes.push_back(fit);
  }
  return true;
}

// Identification over the identifiable set, from the identification rows' nest poses relative to the
// reference row's.
void IdentifyFromRows(const std::vector<Eigen::VectorXd>& q, const std::vector<Rigid3>& tracker_from_nest,
                      const TrackerIdentificationOptions& options, TrackerIdentificationReport* report) {
  std::vector<Eigen::VectorXd> id_q;
  int id_reference = -1;
  std::vector<identification::RelativePoseMeasurement> measurements;
  const Rigid3 nest_ref_from_tracker = tracker_from_nest[report->reference_row].Inverse();
  for (int i : report->identification_rows) {
    if (i == report->reference_row) id_reference = static_cast<int>(id_q.size());
    else {
      identification::RelativePoseMeasurement m;
      m.pose_index = static_cast<int>(id_q.size());
      m.cam_ref_from_cam_i = nest_ref_from_tracker * tracker_from_nest[i];
      measurements.push_back(m);
    }
    id_q.push_back(q[i]);
  }
  identification::IdentifiabilityOptions id_options;
  id_options.scale_known = true;
  id_options.sigma_position_m = options.identification.sigma_position_m;
  id_options.sigma_rotation_rad = options.identification.sigma_rotation_rad;
  report->identifiability =
      identification::AnalyzeIdentifiability(report->nominal, report->rho_nominal, id_q, id_reference, id_options);
  report->identification = identification::IdentifyFromRelativePoses(
      report->nominal, report->rho_nominal, report->identifiability.free_indices, id_q, id_reference, measurements,
      options.identification);
  report->rho_identified = report->identification.rho;
}

// The first row whose SMRs give no nest frame (collinear or coincident) or whose SMR distances differ from
// the median over all rows by more than kMaxNestDistanceChangeM (the row of the largest difference), with
// *why; else -1.
int RowOfAPlacelessNest(const std::vector<SmrTriple>& points, std::string* why) {
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d e12 = points[i][1] - points[i][0], e13 = points[i][2] - points[i][0];
    if (!(e12.norm() > 0 && e12.cross(e13).norm() > 1e-6 * e12.norm() * e13.norm())) {
      *why = "row " + std::to_string(i + 1) + ": the three SMRs are collinear or coincident: they give the nest no frame";
      return static_cast<int>(i);
    }
  }
  constexpr int kPairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  double worst = 0;
  int worst_row = -1;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> d;
    for (const SmrTriple& r : points) d.push_back((r[kPairs[k][0]] - r[kPairs[k][1]]).norm());
    std::vector<double> sorted = d;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    for (size_t i = 0; i < d.size(); ++i) {
      if (std::abs(d[i] - median) > worst) {
        worst = std::abs(d[i] - median);
        worst_row = static_cast<int>(i);
      }
    }
  }
  if (worst <= kMaxNestDistanceChangeM) return -1;
  std::ostringstream out;
  out << "row " << worst_row + 1 << ": an SMR distance differs from the median over all rows by " << worst * 1e3
      << " mm, more than the " << kMaxNestDistanceChangeM * 1e3 << " mm a rigid nest allows: a wrong value";
  *why = out.str();
  return worst_row;
}

// "" when every link of the model from the axis lines is within 10 m (RobotModel::Validate's bound), else
// the first link that is not, with the rows of the two sweeps its axis lines were fitted to.
std::string FarAxisLines(const TrackerIdentificationReport& report) {
  for (int j = 0; j < report.nominal.num_joints(); ++j) {
    const LinkParameters& l = report.nominal.links[j];
    if (std::abs(l.a) <= 10 && std::abs(l.d) <= 10) continue;
    std::string rows;
    for (int k = std::max(0, j - 1); k <= j && k < static_cast<int>(report.axes.size()); ++k) {
      rows += std::string(rows.empty() ? "" : "; ") + "joint " + std::to_string(k + 1) + ":";
      for (int r : report.axes[k].rows) rows += " " + std::to_string(r + 1);
    }
    return "joint " + std::to_string(j + 1) + ": |a| or |d| above 10 m between the axis lines fitted to the rows (" +
           rows + "): a wrong value in one of them";
  }
  return "";
}

}  // namespace

TrackerIdentificationReport RunTrackerIdentification(const std::vector<SmrTriple>& points,
                                                     const std::vector<Eigen::VectorXd>& controller_joints,
                                                     const TrackerIdentificationOptions& options) {
  TrackerIdentificationReport report;
  auto fail = [&report](Outcome outcome, const std::string& message) {
    report.outcome = outcome;
    report.message = message;
    return report;
  };
  if (const std::string problems = options.Validate(); !problems.empty()) return fail(Outcome::kInvalidInput, problems);
  const int num_rows = static_cast<int>(points.size());
  if (num_rows < 4 || static_cast<int>(controller_joints.size()) != num_rows) {
    return fail(Outcome::kInvalidInput, std::to_string(num_rows) + " SMR rows and " +
                                            std::to_string(controller_joints.size()) + " joint rows");
  }
  const int n = static_cast<int>(controller_joints[0].size());
  for (const auto& j : controller_joints) {
    if (j.size() != n || !j.allFinite()) return fail(Outcome::kInvalidInput, "joint rows of different sizes or non-finite");
  }

  report.distances = NestDistances(points);
  std::string why;
  if (const int row = RowOfAPlacelessNest(points, &why); row >= 0) {
    report.problem_row = row;
    return fail(Outcome::kDegenerate, why);
  }
  std::vector<Rigid3> tracker_from_nest;
  std::vector<Eigen::VectorXd> q;
  for (int i = 0; i < num_rows; ++i) {
    tracker_from_nest.push_back(FrameFromThreePoints(points[i][0], points[i][1], points[i][2]));
    q.push_back(ModelJointsFromController(controller_joints[i], options.j3_coupling));
  }
  report.q_ref = MostCommonJoints(q, n);
  SplitRows(q, options.holdout_every, &report);
  MeasureRepeats(q, tracker_from_nest, &report);

  if (!FitAxes(points, tracker_from_nest, q, &report, &why)) return fail(Outcome::kDegenerate, why);
  std::vector<Eigen::Vector3d> directions, axis_points;
  for (const AxisFit& fit : report.axes) {
    directions.push_back(fit.direction);
    axis_points.push_back(fit.point);
  }
  report.nominal = ModelFromAxisLines("axis-fit", directions, axis_points, report.q_ref, options.parallel_tol_rad);
  if (const std::string far = FarAxisLines(report); !far.empty()) return fail(Outcome::kDegenerate, far);
  const Eigen::VectorXd rho0 = KinematicParameters::Nominal(report.nominal);
  report.nominal.flange_from_cam =
      BaseFromFlange(report.nominal, rho0, q[report.reference_row]).Inverse() * tracker_from_nest[report.reference_row];
  report.rho_nominal = KinematicParameters::Nominal(report.nominal);
  IdentifyFromRows(q, tracker_from_nest, options, &report);

  report.insample_before = RelativePoseErrors(report.nominal, report.rho_nominal, q, tracker_from_nest,
                                              report.reference_row, report.identification_rows);
  report.holdout_before = RelativePoseErrors(report.nominal, report.rho_nominal, q, tracker_from_nest,
                                             report.reference_row, report.holdout_rows);
  switch (report.identification.outcome) {
    case identification::Outcome::kConverged: break;
    case identification::Outcome::kNoConvergence:
      return fail(Outcome::kNoConvergence, "identification: " + report.identification.message);
    default: return fail(Outcome::kFailure, "identification: " + report.identification.message);
  }
  report.insample_after = RelativePoseErrors(report.nominal, report.rho_identified, q, tracker_from_nest,
                                             report.reference_row, report.identification_rows);
  report.holdout_after = RelativePoseErrors(report.nominal, report.rho_identified, q, tracker_from_nest,
                                            report.reference_row, report.holdout_rows);
  report.outcome = Outcome::kSuccess;
  return report;
}

}  // namespace selfcal::external
