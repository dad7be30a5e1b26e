#include "calibration/heldout_reprojection.h"

#include <algorithm>
#include <array>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "bundle/error_model.h"
#include "calibration/heldout_chi_square.h"
#include "calibration/heldout_dot_groups.h"
#include "calibration/heldout_gross_errors.h"
#include "geometry/rigid3.h"
#include "identification/triangulation.h"
#include "kinematics/joint_motion.h"

namespace selfcal::calibration {

namespace {

constexpr double kStepRho = 1e-6;  // m or rad
constexpr double kStepDot = 1e-6;  // m
// Per intrinsic (fx, mu, cx, cy, k1, k2, p1, p2, k3): 1e-3 px for the pixel-valued ones, 1e-6 otherwise.
constexpr double kStepIntrinsic[kNumIntrinsics] = {1e-3, 1e-6, 1e-3, 1e-3, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6};

using Matrix23 = Eigen::Matrix<double, 2, 3>;

// The camera pose of one robot configuration and its neighbours for the rho differences.
struct PoseFrames {
  Rigid3 cam_from_base;
  std::vector<Rigid3> plus, minus;  // per free rho entry
  std::vector<Rigid3> held_plus, held_minus;  // per PredictionModel::held_prior entry
};

// Projections of the model and their derivatives by central differences.
class Projector {
 public:
  explicit Projector(const PredictionModel& model)
      : model_(model), intrinsics_(IntrinsicsOf(model.camera)), estimated_(EstimatedIntrinsics(model.intrinsics_estimated)) {
    const int n = static_cast<int>(model.free_indices.size() + estimated_.size());
    with_parameters_ = model.covariance.size() > 0 && model.covariance.rows() == n && model.covariance.cols() == n;
    num_theta_ = with_parameters_ ? n : 0;
  }
  bool with_parameters() const { return with_parameters_; }
  int num_theta() const { return num_theta_; }

  PoseFrames Frames(const PoseObservation& q) const {
    PoseFrames f;
    f.cam_from_base = PointsFromCamAt(model_.robot, model_.rho, q).Inverse();
    for (const auto& [index, sd] : model_.held_prior) {
      Eigen::VectorXd rho = model_.rho;
      rho[index] += kStepRho;
      f.held_plus.push_back(PointsFromCamAt(model_.robot, rho, q).Inverse());
      rho[index] -= 2 * kStepRho;
      f.held_minus.push_back(PointsFromCamAt(model_.robot, rho, q).Inverse());
    }
    if (!with_parameters_) return f;
    for (int index : model_.free_indices) {
      Eigen::VectorXd rho = model_.rho;
      rho[index] += kStepRho;
      f.plus.push_back(PointsFromCamAt(model_.robot, rho, q).Inverse());
      rho[index] -= 2 * kStepRho;
      f.minus.push_back(PointsFromCamAt(model_.robot, rho, q).Inverse());
    }
    return f;
  }

  // The pixel of p_in_base, d(pixel)/d(p), d(pixel)/d(theta) and d(pixel)/d(held prior entry), each by its
  // sd (jh); false when behind the camera at any step.
  bool Project(const PoseFrames& f, const Eigen::Vector3d& p, Eigen::Vector2d* uv, Matrix23* jd, Eigen::MatrixXd* jt,
               Eigen::MatrixXd* jh) const {
    const IntrinsicsVector& in = intrinsics_;
    if (!Pixel(f.cam_from_base, in, p, uv)) return false;
    Eigen::Vector2d a, b;
    jh->resize(2, static_cast<Eigen::Index>(f.held_plus.size()));
    for (size_t k = 0; k < f.held_plus.size(); ++k) {
      if (!Pixel(f.held_plus[k], in, p, &a) || !Pixel(f.held_minus[k], in, p, &b)) return false;
      jh->col(static_cast<Eigen::Index>(k)) = (a - b) / (2 * kStepRho) * model_.held_prior[k].second;
    }
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d h = Eigen::Vector3d::Unit(k) * kStepDot;
      if (!Pixel(f.cam_from_base, in, p + h, &a) || !Pixel(f.cam_from_base, in, p - h, &b)) return false;
      jd->col(k) = (a - b) / (2 * kStepDot);
    }
    jt->resize(2, num_theta_);
    if (!with_parameters_) return true;
    int column = 0;
    for (size_t k = 0; k < f.plus.size(); ++k, ++column) {
      if (!Pixel(f.plus[k], in, p, &a) || !Pixel(f.minus[k], in, p, &b)) return false;
      jt->col(column) = (a - b) / (2 * kStepRho);
    }
    for (int i : estimated_) {
      IntrinsicsVector plus = in, minus = in;
      plus[i] += kStepIntrinsic[i];
      minus[i] -= kStepIntrinsic[i];
      if (!Pixel(f.cam_from_base, plus, p, &a) || !Pixel(f.cam_from_base, minus, p, &b)) return false;
      jt->col(column++) = (a - b) / (2 * kStepIntrinsic[i]);
    }
    return true;
  }

 private:
  static bool Pixel(const Rigid3& cam_from_base, const IntrinsicsVector& in, const Eigen::Vector3d& p,
                    Eigen::Vector2d* uv) {
    return ProjectWithIntrinsics<double>(in.data(), cam_from_base * p, &uv->x(), &uv->y());
  }

  const PredictionModel& model_;
  IntrinsicsVector intrinsics_;
  std::vector<int> estimated_;
  bool with_parameters_ = false;
  int num_theta_ = 0;
};

// The rows of one dot's prediction error in the 6 columns of its image's camera motion (v, omega in the
// camera frame): d uv / d p_cam = jd R^T (jd = d uv / d p_base, p_cam = R p_base + t), d p_cam / d v = I,
// d p_cam / d omega = -[p_cam]x.
Eigen::Matrix<double, 2, 6> PoseErrorRows(const Rigid3& cam_from_base, const Eigen::Vector3d& p_base, const Matrix23& jd) {
  return jd * cam_from_base.rotation.transpose() * SmallMotionJacobian(cam_from_base * p_base);
}

// The recorded flange pose's noise (base_from_flange * Exp(delta), per axis s_t, s_r in the flange frame) as
// the camera motion of PoseErrorRows: e = A diag(s_t, s_r) z with, for flange_from_cam = (R, t), the rotation
// R^T w and the translation R^T (v + w x t) (up to a sign that the covariance does not see).
Eigen::Matrix<double, 6, 6> FlangePoseMotion(const Rigid3& flange_from_cam, double translation_sd, double rotation_sd) {
  const Eigen::Matrix3d rt = flange_from_cam.rotation.transpose();
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
  a.topLeftCorner<3, 3>() = rt * translation_sd;
  a.topRightCorner<3, 3>() = -rt * Skew<double>(flange_from_cam.translation) * rotation_sd;
  a.bottomRightCorner<3, 3>() = rt * rotation_sd;
  return a;
}

// The camera in the frame of the flange whose recorded pose carries the noise: points_from_cam of the flange's
// points (eye-to-hand), or base_from_flange^-1 * base_from_cam (eye-in-hand).
Rigid3 FlangeFromCamAt(const PredictionModel& model, const PoseFrames& frames, const PoseObservation& pose) {
  const Rigid3 points_from_cam = frames.cam_from_base.Inverse();
  if (model.robot.mount == CameraMount::kEyeToHand || !pose.base_from_flange) return points_from_cam;
  return pose.base_from_flange->Inverse() * points_from_cam;
}

bool HasPoseError(const PredictionModel& model) {
  return model.pose_translation_m > 0 || model.pose_rotation_rad > 0 || model.joint_rad > 0;
}

// The bundle's pixel-only estimate with an estimated pose error (not the pose-noise solve, whose estimator
// weighs the pose errors itself): the identification images' pose errors moved its parameters and dots, and
// the prediction carries that (CarriedEffects).
bool CarriesIdentificationPoseErrors(const PredictionModel& model) {
  return HasPoseError(model) && !model.pose_error_at_flange;
}

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Theta_k, the covariance of `pose`'s camera motion from each pose-error component under `model`
// (translation, rotation, joint reading; bundle/error_model.h): a joint set's joint-reading noise through the
// pose's CameraMotionPerJoint, or the flange pose noise carried to the camera. Their sum is Theta.
std::array<Matrix6d, 3> PoseErrorComponents(const PredictionModel& model, const PoseFrames& frames,
                                            const PoseObservation& pose) {
  if (model.pose_error_at_flange) {
    const Rigid3 flange_from_cam = FlangeFromCamAt(model, frames, pose);
    const Matrix6d t = FlangePoseMotion(flange_from_cam, model.pose_translation_m, 0);
    const Matrix6d r = FlangePoseMotion(flange_from_cam, 0, model.pose_rotation_rad);
    return {t * t.transpose(), r * r.transpose(), Matrix6d::Zero()};
  }
  const bool joints = model.joint_rad > 0 && !pose.base_from_flange && pose.joints_rad.size() > 0;
  return {bundle::PoseErrorCovariance(model.pose_translation_m, 0, 0, Eigen::MatrixXd()),
          bundle::PoseErrorCovariance(0, model.pose_rotation_rad, 0, Eigen::MatrixXd()),
          joints ? bundle::PoseErrorCovariance(0, 0, model.joint_rad,
                                               CameraMotionPerJoint(model.robot, model.rho, pose.joints_rad))
                 : Matrix6d::Zero()};
}

// M with M M^T = theta (symmetric, semi-definite).
Matrix6d SymmetricRoot(const Matrix6d& theta) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(theta);
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

Matrix6d SumOf(const std::array<Matrix6d, 3>& theta) { return theta[0] + theta[1] + theta[2]; }

// M with e = M z, z ~ N(0, I): the camera motion of `pose`'s pose error under `model` (Theta = M M^T, the
// sum of PoseErrorComponents; at the flange, the noise's own axes carried to the camera).
Matrix6d PoseErrorRootAt(const PredictionModel& model, const PoseFrames& frames, const PoseObservation& pose) {
  if (model.pose_error_at_flange) {
    return FlangePoseMotion(FlangeFromCamAt(model, frames, pose), model.pose_translation_m, model.pose_rotation_rad);
  }
  return SymmetricRoot(SumOf(PoseErrorComponents(model, frames, pose)));
}

// One image's pose-error columns (root R from `column`) split by component: E_k = R^+ Theta_k R^+T
// (heldout_chi_square.h).
VarianceBlock VarianceBlockAt(const std::array<Matrix6d, 3>& theta, const Matrix6d& root, int column) {
  VarianceBlock b;
  b.column = column;
  Eigen::CompleteOrthogonalDecomposition<Matrix6d> decomposition;
  decomposition.setThreshold(1e-9);
  decomposition.compute(root);
  const Matrix6d inverse = decomposition.pseudoInverse();
  for (int k = 0; k < 3; ++k) b.e[k] = inverse * theta[k] * inverse.transpose();
  return b;
}

// The identification images' carried pose-error columns (6 each from first_column, in their order) by
// component; carried errors are the camera frame's, which do not look at the frames.
void AddIdentificationBlocks(const ObservationSet& obs, const PredictionModel& model, int first_column,
                             VarianceParts* parts) {
  const std::vector<int> identification = obs.PosesWithRole(PoseRole::kIdentification);
  for (size_t index = 0; index < identification.size(); ++index) {
    const std::array<Matrix6d, 3> theta = PoseErrorComponents(model, PoseFrames(), obs.poses[identification[index]]);
    parts->blocks.push_back(VarianceBlockAt(theta, SymmetricRoot(SumOf(theta)), first_column + 6 * static_cast<int>(index)));
  }
}

// What the identification images say about one dot: H_dd and H_dtheta (sigma = 1), and from them the
// square root of H_dd^-1 and K = H_dd^-1 H_dtheta.
struct DotInformation {
  Eigen::Matrix3d hdd = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd hdt;
  int views = 0;
  bool usable = false;
  Eigen::Matrix3d sqrt_inverse = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd k;
  int column = -1;  // index of its block among the usable dots
  // With a pose error: J_d^T J_e M (3 x 6 per identification image, in the order of the identification
  // poses; zero for an image that does not see it), and from it the dot's error per unit of those images' pose
  // errors, with the parameters' share (CarriedEffects).
  Eigen::MatrixXd hde, pose_effect;
  // With a prior on held parameters: J_d^T J_h (3 x held), and the dot's error per unit of their errors.
  Eigen::MatrixXd hdh, held_effect;
  bool grouped = false;  // joined by a yardstick to another dot: solved in its DotGroup (heldout_dot_groups.h)
};
using DotInformationMap = std::map<int, DotInformation>;

// out_j = (H^-1 X)_j for every usable dot j: H_dd^-1 X_j for a dot solved alone, the rows of H_GG^-1 X_G of
// a group of dots joined by yardsticks (the fit solved them together).
void SolveDots(const std::vector<DotGroup>& groups, Eigen::MatrixXd DotInformation::*x,
               Eigen::MatrixXd DotInformation::*out, DotInformationMap* info) {
  for (auto& [id, d] : *info) {
    if (d.usable && !d.grouped) d.*out = d.sqrt_inverse * d.sqrt_inverse.transpose() * (d.*x);
  }
  for (const DotGroup& g : groups) {
    const Eigen::Index cols = (info->at(g.ids[0]).*x).cols();
    Eigen::MatrixXd stacked(3 * static_cast<Eigen::Index>(g.ids.size()), cols);
    for (size_t j = 0; j < g.ids.size(); ++j) stacked.middleRows<3>(3 * static_cast<Eigen::Index>(j)) = info->at(g.ids[j]).*x;
    const Eigen::MatrixXd solved = g.inverse * stacked;
    for (size_t j = 0; j < g.ids.size(); ++j) info->at(g.ids[j]).*out = solved.middleRows<3>(3 * static_cast<Eigen::Index>(j));
  }
}

// hte (with a pose error): J_theta^T J_e M (theta x 6 per identification image); hth: J_theta^T J_h of the
// held parameters with a prior (theta x held).
std::map<int, DotInformation> IdentificationInformation(const ObservationSet& obs, const PredictionModel& model,
                                                        const Projector& projector,
                                                        const std::map<int, Eigen::Vector3d>& dots,
                                                        const ExcludedObservations& excluded, Eigen::MatrixXd* hte,
                                                        Eigen::MatrixXd* hth, std::vector<DotGroup>* groups) {
  std::map<int, DotInformation> info;
  const std::vector<int> identification = obs.PosesWithRole(PoseRole::kIdentification);
  const bool pose_error = CarriesIdentificationPoseErrors(model);
  const Eigen::Index nt = projector.num_theta(), nh = static_cast<Eigen::Index>(model.held_prior.size());
  const Eigen::Index ne = pose_error ? 6 * static_cast<Eigen::Index>(identification.size()) : 0;
  for (const auto& [id, p] : dots) {
    info[id].hdt = Eigen::MatrixXd::Zero(3, nt);
    info[id].hdh = Eigen::MatrixXd::Zero(3, nh);
    info[id].hde = Eigen::MatrixXd::Zero(3, ne);
  }
  *hte = Eigen::MatrixXd::Zero(nt, ne);
  *hth = Eigen::MatrixXd::Zero(nt, nh);
  for (size_t index = 0; index < identification.size(); ++index) {
    const PoseObservation& pose = obs.poses[identification[index]];
    const PoseFrames frames = projector.Frames(pose);
    const Eigen::Matrix<double, 6, 6> root =
        pose_error ? PoseErrorRootAt(model, frames, pose) : Eigen::Matrix<double, 6, 6>::Zero();
    const Eigen::Index column = 6 * static_cast<Eigen::Index>(index);
    for (const auto& [id, pixel] : pose.dots_px) {
      const auto dot = dots.find(id);
      if (dot == dots.end() || excluded.count({pose.id, id}) > 0) continue;
      Eigen::Vector2d uv;
      Matrix23 jd;
      Eigen::MatrixXd jt, jh;
      if (!projector.Project(frames, dot->second, &uv, &jd, &jt, &jh)) continue;
      DotInformation& d = info[id];
      d.hdd += jd.transpose() * jd;
      d.hdt += jd.transpose() * jt;
      if (nh > 0) {
        d.hdh.noalias() += jd.transpose() * jh;
        hth->noalias() += jt.transpose() * jh;
      }
      ++d.views;
      if (pose_error) {
        const Eigen::Matrix<double, 2, 6> je = PoseErrorRows(frames.cam_from_base, dot->second, jd) * root;
        d.hde.middleCols<6>(column).noalias() += jd.transpose() * je;
        hte->middleCols<6>(column).noalias() += jt.transpose() * je;
      }
    }
  }
  for (auto& [id, d] : info) {
    if (d.views < 2) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(d.hdd);
    if (eigen.info() != Eigen::Success || !(eigen.eigenvalues().minCoeff() > 1e-12 * eigen.eigenvalues().maxCoeff())) continue;
    d.usable = true;
    d.sqrt_inverse = eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().cwiseSqrt().asDiagonal();
  }
  std::map<int, Eigen::Matrix3d> usable_hdd;
  for (const auto& [id, d] : info) {
    if (d.usable) usable_hdd[id] = d.hdd;
  }
  *groups = YardstickDotGroups(obs.yardsticks, model.yardstick_sigma_m, obs.pixel_noise_px, usable_hdd, dots);
  for (const DotGroup& g : *groups) {
    for (int id : g.ids) info[id].grouped = true;
  }
  SolveDots(*groups, &DotInformation::hdt, &DotInformation::k, &info);
  return info;
}

// The parameters' covariance without its pose part (PredictionModel::covariance_pose_part): the fit's own
// S^-1 times noise_px^2.
Eigen::MatrixXd PixelPart(const PredictionModel& model) {
  const Eigen::Index nt = model.covariance.rows();
  const bool split = model.covariance_pose_part.rows() == nt && model.covariance_pose_part.cols() == nt;
  return split ? Eigen::MatrixXd(model.covariance - model.covariance_pose_part) : model.covariance;
}

// An error source the least-squares fit absorbed, carried into the estimates: with h_theta = J_theta^T J_E and
// each dot's h_dot = J_d^T J_E (per unit of the source's columns), the parameters' error
// dtheta = S^-1 (h_theta - sum_j K_j^T h_dot_j) (S^-1 = PixelPart / noise_px^2, the dots eliminated) and each
// dot's H_dd^-1 h_dot_j - K_j dtheta (into its `effect`). Returns dtheta (theta x the source's columns). The
// sources: the identification images' pose errors (hde, pose_effect) and the held parameters' errors about
// the description (hdh, held_effect).
Eigen::MatrixXd CarriedEffects(const PredictionModel& model, double noise_px, int nt, const Eigen::MatrixXd& h_theta,
                               Eigen::MatrixXd DotInformation::*h_dot, Eigen::MatrixXd DotInformation::*effect,
                               const std::vector<DotGroup>& groups, DotInformationMap* info) {
  Eigen::MatrixXd dtheta = Eigen::MatrixXd::Zero(nt, h_theta.cols());
  if (nt > 0) {
    Eigen::MatrixXd c = h_theta;
    for (const auto& [id, d] : *info) {
      if (d.usable) c.noalias() -= d.k.transpose() * (d.*h_dot);
    }
    dtheta = PixelPart(model) / (noise_px * noise_px) * c;
  }
  SolveDots(groups, h_dot, effect, info);
  for (auto& [id, d] : *info) {
    if (d.usable && nt > 0) (d.*effect).noalias() -= d.k * dtheta;
  }
  return dtheta;
}

HeldOutFigure FigureOf(const std::string& pose_id, int begin, int end, const Residuals& residuals, int num_dots,
                       double sigma, int noise_dof, const PredictionModel& model, const VarianceParts& parts) {
  HeldOutFigure f;
  f.pose_id = pose_id;
  f.noise_dof = noise_dof;
  f.num_residuals = end - begin;
  f.dof = 2 * f.num_residuals;
  if (begin >= end) return f;
  double sum2 = 0, worst = 0;
  for (int k = begin; k < end; ++k) {
    sum2 += residuals.rows[k].r.squaredNorm();
    worst = std::max(worst, residuals.rows[k].r.norm());
  }
  f.rms_px = std::sqrt(sum2 / f.dof);
  f.max_px = worst;
  const bool estimated = !model.relative_variance_covariance.isZero(0);
  const ChiSquare chi_square = ChiSquareOf(begin, end, residuals, num_dots, sigma, estimated ? &parts : nullptr);
  if (estimated) {
    const int pixel_dof = DegreesOfFreedomOf(model.relative_variance_covariance(0, 0));
    if (pixel_dof > 0) f.noise_dof = pixel_dof;
    f.pose_share = chi_square.share[0] + chi_square.share[1] + chi_square.share[2];
    f.pose_noise_dof = PoseNoiseDof(chi_square, model.relative_variance_covariance);
  }
  f.chi_square = chi_square.value;
  f.chi_square_limit = ChiSquareQuantile(kHeldOutTestLevel, f.dof, f.noise_dof, f.pose_share, f.pose_noise_dof);
  f.p_value = ChiSquareUpperTail(f.chi_square, f.dof, f.noise_dof, f.pose_share, f.pose_noise_dof);
  f.test_passed = f.chi_square <= f.chi_square_limit;
  return f;
}

// The square root of the parameters' covariance (Sigma = L L^T; semi-definite allowed).
Eigen::MatrixXd CovarianceRoot(const Eigen::MatrixXd& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (covariance + covariance.transpose()));
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

}  // namespace

HeldOutReprojection HeldOutReprojectionOf(const ObservationSet& obs, const PredictionModel& model,
                                          const std::map<int, Eigen::Vector3d>& dots_in_base,
                                          const ExcludedObservations& excluded, double noise_px, int noise_dof) {
  HeldOutReprojection report;
  report.noise_px = noise_px;
  if (!(noise_px > 0) || !std::isfinite(noise_px)) {
    report.message = "no pixel noise to normalise with";
    return report;
  }
  const Projector projector(model);
  report.prediction_uncertainty = projector.with_parameters();
  Eigen::MatrixXd hte, hth;
  std::vector<DotGroup> groups;
  std::map<int, DotInformation> info =
      IdentificationInformation(obs, model, projector, dots_in_base, excluded, &hte, &hth, &groups);
  const int nt = projector.num_theta();
  // U's columns: the parameters' (their pixel part when the identification images' pose errors enter
  // explicitly), 6 per verification image (its own pose error, zero outside its rows), 6 per identification
  // image (its pose error as carried into the parameters and dots), one per held parameter with a prior (its
  // error, directly and as carried into the parameters and dots).
  const bool carried = CarriesIdentificationPoseErrors(model);
  const Eigen::MatrixXd dtheta = CarriedEffects(model, noise_px, nt, hte, &DotInformation::hde,
                                                &DotInformation::pose_effect, groups, &info);
  const Eigen::MatrixXd dtheta_held = CarriedEffects(model, noise_px, nt, hth, &DotInformation::hdh,
                                                     &DotInformation::held_effect, groups, &info);
  const int nh = static_cast<int>(model.held_prior.size());
  const Eigen::MatrixXd theta_root =
      nt > 0 ? CovarianceRoot(carried ? PixelPart(model) : model.covariance) : Eigen::MatrixXd();
  int num_dots = 0;
  for (auto& [id, d] : info) {
    if (d.usable) d.column = num_dots++;
  }
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  const bool pose_error = HasPoseError(model);
  const int identification_column = nt + (pose_error ? 6 * static_cast<int>(verification.size()) : 0);
  const int held_column = identification_column + static_cast<int>(dtheta.cols());
  const int width = held_column + nh;
  VarianceParts parts;
  const bool variances = pose_error && !model.relative_variance_covariance.isZero(0);
  if (variances && carried) AddIdentificationBlocks(obs, model, identification_column, &parts);
  Residuals residuals;
  residuals.num_theta = width;
  std::vector<int> first_row_of_pose;  // per report.poses entry, and one past the end
  Eigen::Matrix<double, 2, Eigen::Dynamic> g(2, width);
  for (size_t index = 0; index < verification.size(); ++index) {
    const PoseObservation& pose = obs.poses[verification[index]];
    const PoseFrames frames = projector.Frames(pose);
    const Eigen::Matrix<double, 6, 6> pose_root =
        pose_error ? PoseErrorRootAt(model, frames, pose) : Eigen::Matrix<double, 6, 6>::Zero();
    if (variances) {
      parts.blocks.push_back(
          VarianceBlockAt(PoseErrorComponents(model, frames, pose), pose_root, nt + 6 * static_cast<int>(index)));
    }
    const int first = static_cast<int>(residuals.rows.size());
    for (const auto& [id, pixel] : pose.dots_px) {
      const auto d = info.find(id);
      Eigen::Vector2d uv;
      Matrix23 jd;
      Eigen::MatrixXd jt, jh;
      if (d == info.end() || !d->second.usable || !projector.Project(frames, dots_in_base.at(id), &uv, &jd, &jt, &jh)) {
        ++report.num_not_predicted;
        continue;
      }
      Residual e;
      e.slot = static_cast<int>(report.poses.size());
      e.r = pixel - uv;
      if (width > 0) {
        g.setZero();
        if (nt > 0) g.leftCols(nt).noalias() = (jt - jd * d->second.k) * theta_root;
        if (pose_error) {
          g.middleCols<6>(nt + 6 * static_cast<int>(index)) =
              PoseErrorRows(frames.cam_from_base, dots_in_base.at(id), jd) * pose_root;
        }
        if (dtheta.cols() > 0) {
          g.middleCols(identification_column, dtheta.cols()).noalias() = jd * d->second.pose_effect;
          if (nt > 0) g.middleCols(identification_column, dtheta.cols()).noalias() += jt * dtheta;
        }
        if (nh > 0) {
          g.rightCols(nh) = jh - jd * d->second.held_effect;
          if (nt > 0) g.rightCols(nh).noalias() -= jt * dtheta_held;
        }
        for (int i = 0; i < 2; ++i) {
          for (int c = 0; c < width; ++c) residuals.g.push_back(g(i, c));
        }
      }
      e.d = jd * d->second.sqrt_inverse * noise_px;
      e.dot = d->second.column;
      residuals.rows.push_back(e);
      report.residuals.push_back({pose.id, id, pixel, pixel - uv});
    }
    if (static_cast<int>(residuals.rows.size()) > first) {
      report.poses.push_back({pose.id});
      first_row_of_pose.push_back(first);
    } else if (!pose.dots_px.empty()) {
      report.unused_poses.push_back(pose.id);
    }
  }
  if (residuals.rows.empty()) {
    report.message = obs.PosesWithRole(PoseRole::kVerification).empty()
                         ? "the set names no verification pose"
                         : "no verification image sees a dot that the identification images place";
    return report;
  }
  first_row_of_pose.push_back(static_cast<int>(residuals.rows.size()));
  internal::ScreenGrossErrors(noise_px, &residuals, &first_row_of_pose, &report.residuals, &report.gross_errors);
  for (size_t s = 0; s < report.poses.size(); ++s) {
    report.poses[s] = FigureOf(report.poses[s].pose_id, first_row_of_pose[s], first_row_of_pose[s + 1], residuals,
                               num_dots, noise_px, noise_dof, model, parts);
  }
  report.overall = FigureOf("", 0, static_cast<int>(residuals.rows.size()), residuals, num_dots, noise_px, noise_dof,
                            model, parts);
  report.ok = true;
  return report;
}

HeldOutReprojection NominalHeldOutReprojection(const ObservationSet& obs, double noise_px, int noise_dof) {
  PredictionModel nominal;
  nominal.robot = obs.robot;
  nominal.rho = KinematicParameters::Nominal(obs.robot);
  nominal.camera = obs.camera;
  return HeldOutReprojectionOf(obs, nominal, TriangulateIdentificationDots(obs, nominal), {}, noise_px, noise_dof);
}

std::map<int, Eigen::Vector3d> TriangulateIdentificationDots(const ObservationSet& obs, const PredictionModel& model) {
  std::map<int, identification::PointTrack> tracks;
  for (int i : obs.PosesWithRole(PoseRole::kIdentification)) {
    const PoseObservation& pose = obs.poses[i];
    const Rigid3 base_from_cam = PointsFromCamAt(model.robot, model.rho, pose);
    for (const auto& [id, pixel] : pose.dots_px) {
      tracks[id].base_from_cam.push_back(base_from_cam);
      tracks[id].pixels.push_back(pixel);
    }
  }
  std::map<int, Eigen::Vector3d> dots;
  for (const auto& [id, track] : tracks) {
    if (track.pixels.size() < 2) continue;
    const identification::TriangulationResult t =
        identification::TriangulatePoint(model.camera, model.camera.fx_px, track, 1.0);
    if (t.ok) dots[id] = t.point;
  }
  return dots;
}

}  // namespace selfcal::calibration
