#include "planning/fisher_design.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "base/status.h"
#include "planning/exchange_kernels.h"
#include "planning/pose_twists.h"

namespace selfcal::planning {

namespace {

// Lower triangle of s += sign w w^T for a w of few columns (Eigen's rankUpdate goes through its blocked
// matrix product, several times slower at these sizes).
template <typename Matrix>
void AddOuterLower(double sign, const Matrix& w, Eigen::MatrixXd* s) {
  const int n = static_cast<int>(w.rows());
  for (int c = 0; c < n; ++c) {
    const int len = n - c;
    for (int k = 0; k < w.cols(); ++k) s->col(c).tail(len).noalias() += (sign * w(c, k)) * w.col(k).tail(len);
  }
}

// s[r] -= f l[r] for r in [from, n): one column of a factor against another (they never overlap).
void SubtractScaled(double f, const double* __restrict l, int from, int n, double* __restrict s) {
  for (int r = from; r < n; ++r) s[r] -= f * l[r];
}

// Cholesky factor of the lower triangle of s, in place (the strict upper triangle is not read); false when s is
// not positive definite.
bool CholeskyLower(Eigen::MatrixXd* s) {
  const int n = static_cast<int>(s->rows());
  for (int c = 0; c < n; ++c) {
    double* col = s->col(c).data();
    for (int k = 0; k < c; ++k) SubtractScaled(s->col(k)[c], s->col(k).data(), c, n, col);
    if (!(col[c] > 0)) return false;
    const double d = std::sqrt(col[c]);
    col[c] = d;
    const double inv = 1.0 / d;
    for (int r = c + 1; r < n; ++r) col[r] *= inv;
  }
  return true;
}

// The inverse of the Cholesky factor of a 3 x 3 information block (as Eigen's LLT, then its inverse by
// forward substitution); false when the block is not positive definite or a pivot falls below 1e-12 of its
// trace (a dot seen from fewer than two poses).
bool InverseCholesky3(const Eigen::Matrix3d& h, Eigen::Matrix3d* li) {
  if (!(h(0, 0) > 0)) return false;
  const double l00 = std::sqrt(h(0, 0));
  const double l10 = h(1, 0) / l00, l20 = h(2, 0) / l00;
  const double d1 = h(1, 1) - l10 * l10;
  if (!(d1 > 0)) return false;
  const double l11 = std::sqrt(d1);
  const double l21 = (h(2, 1) - l20 * l10) / l11;
  const double d2 = h(2, 2) - (l20 * l20 + l21 * l21);
  if (!(d2 > 0)) return false;
  const double l22 = std::sqrt(d2);
  if (!(std::min(std::min(h(0, 0), d1), d2) > 1e-12 * h.trace())) return false;
  const double i00 = 1.0 / l00, i11 = 1.0 / l11, i22 = 1.0 / l22;
  const double i10 = -l10 * i00 / l11;
  *li << i00, 0, 0, i10, i11, 0, (-l20 * i00 - l21 * i10) / l22, -l21 * i11 / l22, i22;
  return true;
}

// to[r] += a0[r] b0 + a1[r] b1 (a dot's two pixel rows times one column of its b: a block of a^T b).
void AddTimes(const double* __restrict a0, const double* __restrict a1, double b0, double b1, double* __restrict to,
              int n) {
  for (int r = 0; r < n; ++r) to[r] += a0[r] * b0 + a1[r] * b1;
}

// The columns (w0 w1 w2) times L^-T for the inverse li of a lower triangular L, in place.
void TimesLowerTransposed(const Eigen::Matrix3d& li, double* __restrict w0, double* __restrict w1,
                          double* __restrict w2, int n) {
  const double i00 = li(0, 0), i10 = li(1, 0), i11 = li(1, 1), i20 = li(2, 0), i21 = li(2, 1), i22 = li(2, 2);
  for (int r = 0; r < n; ++r) {
    const double x0 = w0[r], x1 = w1[r], x2 = w2[r];
    w0[r] = x0 * i00;
    w1[r] = x0 * i10 + x1 * i11;
    w2[r] = x0 * i20 + x1 * i21 + x2 * i22;
  }
}

// A dot's two pixel rows' derivatives with respect to (free rho, f_x), a = f zt^T, into a0 and a1.
void PixelRows(const Eigen::Matrix<double, 2, 7>& f, const Eigen::MatrixXd& zt, double* __restrict a0,
               double* __restrict a1) {
  const int n = static_cast<int>(zt.rows());
  const double* __restrict z = zt.data();
  const double f00 = f(0, 0), f01 = f(0, 1), f02 = f(0, 2), f03 = f(0, 3), f04 = f(0, 4), f05 = f(0, 5), f06 = f(0, 6);
  const double f10 = f(1, 0), f11 = f(1, 1), f12 = f(1, 2), f13 = f(1, 3), f14 = f(1, 4), f15 = f(1, 5), f16 = f(1, 6);
  for (int r = 0; r < n; ++r) {
    const double z0 = z[r], z1 = z[n + r], z2 = z[2 * n + r], z3 = z[3 * n + r], z4 = z[4 * n + r], z5 = z[5 * n + r],
                 z6 = z[6 * n + r];
    a0[r] = f00 * z0 + f01 * z1 + f02 * z2 + f03 * z3 + f04 * z4 + f05 * z5 + f06 * z6;
    a1[r] = f10 * z0 + f11 * z1 + f12 * z2 + f13 * z3 + f14 * z4 + f15 * z5 + f16 * z6;
  }
}

// Columns of a rank update of the lower triangle of s (s += sign W W^T), gathered a few dots at a time and
// added by internal::AddGramLower (rows beyond `rows` of each column stay zero).
class DotColumns {
 public:
  DotColumns(int rows, int columns_per_dot, double sign, Eigen::MatrixXd* s)
      : rows_(rows), ld_((rows + 3) / 4 * 4), capacity_(16 * columns_per_dot), sign_(sign), s_(s),
        w_(static_cast<size_t>(ld_) * capacity_, 0.0) {}
  int ld() const { return ld_; }
  bool Full(int n) const { return count_ + n > capacity_; }
  // Room for n more columns (the ones gathered added to s first when full): the first one's rows.
  double* Take(int n) {
    if (count_ + n > capacity_) Flush();
    double* first = w_.data() + static_cast<size_t>(count_) * ld_;
    count_ += n;
    return first;
  }
  void Flush() {
    if (count_ > 0) internal::AddGramLower(sign_, w_.data(), ld_, rows_, count_, s_->data(), rows_);
    count_ = 0;
  }

 private:
  int rows_, ld_, capacity_;
  double sign_;
  Eigen::MatrixXd* s_;
  std::vector<double> w_;
  int count_ = 0;
};

}  // namespace

FisherDesign::FisherDesign(const PlanningProblem& problem, const std::vector<int>& free_columns,
                           const FisherDesignOptions& options)
    : problem_(problem), free_columns_(free_columns), options_(options) {
  SELFCAL_CHECK(problem.scene.dots_in_base.size() >= 3, "the scene needs at least 3 dots");
  SELFCAL_CHECK(options.pixel_noise_px > 0 && options.yardstick_sigma_m > 0, "noise and yardstick sigma must be > 0");
  num_global_ = static_cast<int>(free_columns.size()) + 1 + 6;
}

FisherDesign::Sums FisherDesign::ZeroSums() const {
  const int nf = static_cast<int>(free_columns_.size());
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Sums zero;
  zero.h_gg = Eigen::MatrixXd::Zero(num_global_, num_global_);
  zero.h_jj.assign(dots - 2, Eigen::Matrix3d::Zero());
  zero.h_gj = Eigen::MatrixXd::Zero(nf + 1, 3 * (dots - 2));
  return zero;
}

// A dot's pixel derivative with respect to the free parameters is -dpi R^T (omega_k x x + v_k) =
// dpi ([y]x omega'_k - v'_k) with y = R^T x, omega' = R^T omega, v' = R^T v: a 2 x 6 matrix of the dot, f below,
// times the 6 x free matrix of the pose's twists in its camera frame. The (free, f_x) block of the information
// is then zt (sum f^T f) zt^T: one 7 x 7 sum per pose instead of a free x free update per dot.
void FisherDesign::DotRows(const Candidate& c, int j, Eigen::Matrix<double, 2, 7>* f,
                           Eigen::Matrix<double, 2, 3>* b) const {
  const CameraIntrinsics& cam = problem_.camera;
  const Eigen::Vector3d& p = c.p[j];
  const double xn = p.x() / p.z(), yn = p.y() / p.z();
  Eigen::Matrix<double, 2, 3> dpi;
  dpi << cam.fx_px / p.z(), 0, -cam.fx_px * xn / p.z(), 0, cam.fx_px * cam.mu / p.z(), -cam.fx_px * cam.mu * yn / p.z();
  const Eigen::Vector3d y = c.rt * problem_.scene.dots_in_base[j];
  Eigen::Matrix3d y_cross;
  y_cross << 0, -y.z(), y.y(), y.z(), 0, -y.x(), -y.y(), y.x(), 0;
  f->leftCols<3>().noalias() = dpi * y_cross;
  f->middleCols<3>(3) = -dpi;
  f->col(6) << xn, cam.mu * yn;
  b->noalias() = dpi * c.rt;
}

int FisherDesign::AddCandidate(const Eigen::VectorXd& q) {
  SELFCAL_CHECK(q.size() == problem_.robot.num_joints(), "candidate has " << q.size() << " joints");
  const internal::CameraTwists<double> tw = internal::ComputeCameraTwists<double>(problem_.robot, q.data());
  const CameraIntrinsics& cam = problem_.camera;
  const int nf = static_cast<int>(free_columns_.size()), g = nf + 1;
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  Candidate out;
  out.rt = tw.base_from_cam.rotation.transpose();
  out.zt = Eigen::MatrixXd::Zero(g, 7);
  for (int k = 0; k < nf; ++k) {
    out.zt.row(k).head<3>() = (out.rt * tw.omega[free_columns_[k]]).transpose();
    out.zt.row(k).segment<3>(3) = (out.rt * tw.v[free_columns_[k]]).transpose();
  }
  out.zt(nf, 6) = 1.0;
  out.p.resize(dots);
  out.seen.assign(dots, 0);
  out.ff.setZero();
  out.yard = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, num_global_);
  Eigen::Matrix<double, 2, 7> f;
  Eigen::Matrix<double, 2, 3> b;
  Eigen::Matrix<double, Eigen::Dynamic, 2> a(g, 2);
  for (int j = 0; j < dots; ++j) {
    const Eigen::Vector3d p = out.rt * (problem_.scene.dots_in_base[j] - tw.base_from_cam.translation);
    out.p[j] = p;
    if (!(p.z() > 0)) continue;
    const double u = cam.cx_px + cam.fx_px * p.x() / p.z(), v = cam.cy_px + cam.fx_px * cam.mu * p.y() / p.z();
    if (u < 0 || v < 0 || u > cam.width_px - 1 || v > cam.height_px - 1) continue;  // not seen
    out.seen[j] = 1;
    DotRows(out, j, &f, &b);
    out.ff.noalias() += f.transpose() * f;
    if (j < 2) {  // a yardstick dot: one of the globals
      PixelRows(f, out.zt, a.col(0).data(), a.col(1).data());
      out.yard.block(3 * j, 0, 3, g).noalias() = b.transpose() * a.transpose();
      out.yard.block<3, 3>(3 * j, g + 3 * j).noalias() = b.transpose() * b;
    }
  }
  candidates_.push_back(std::move(out));
  return static_cast<int>(candidates_.size()) - 1;
}

void FisherDesign::AddInformation(const Candidate& c, Eigen::MatrixXd* h) const {
  const int g = static_cast<int>(free_columns_.size()) + 1;
  const Eigen::MatrixXd zf = c.zt * c.ff;
  h->topLeftCorner(g, g).noalias() += zf * c.zt.transpose();
  h->bottomRows<6>() += c.yard;
  h->topRightCorner(g, 6) += c.yard.leftCols(g).transpose();
}

FisherDesign::Sums FisherDesign::Sum(const std::vector<int>& design, int skip_position) const {
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  const int g = static_cast<int>(free_columns_.size()) + 1;
  Sums sums = ZeroSums();
  Eigen::Matrix<double, 2, 7> f;
  Eigen::Matrix<double, 2, 3> b;
  Eigen::Matrix<double, Eigen::Dynamic, 2> a(g, 2);
  for (size_t k = 0; k < design.size(); ++k) {
    if (static_cast<int>(k) == skip_position) continue;
    const Candidate& c = candidates_.at(design[k]);
    AddInformation(c, &sums.h_gg);
    for (int j = 2; j < dots; ++j) {
      if (!c.seen[j]) continue;
      DotRows(c, j, &f, &b);
      PixelRows(f, c.zt, a.col(0).data(), a.col(1).data());
      sums.h_jj[j - 2].noalias() += b.transpose() * b;
      for (int m = 0; m < 3; ++m) {
        AddTimes(a.col(0).data(), a.col(1).data(), b(0, m), b(1, m), sums.h_gj.col(3 * (j - 2) + m).data(), g);
      }
    }
  }
  return sums;
}

FisherValue FisherDesign::Evaluate(const std::vector<int>& design) const {
  return EvaluateSums(Sum(design), -1, true);
}

Eigen::Matrix<double, 6, 6> FisherDesign::YardstickInformation() const {
  // (|X0 - X1| - L) / sigma_y, in units where the pixel residuals have unit variance.
  const Eigen::Vector3d d = (problem_.scene.dots_in_base[0] - problem_.scene.dots_in_base[1]).normalized();
  Eigen::Matrix<double, 6, 1> y;
  y << d, -d;
  const double w = options_.pixel_noise_px / options_.yardstick_sigma_m;
  return (w * w) * y * y.transpose();
}

void FisherDesign::SubtractDots(const Sums& sums, const Candidate* add, Eigen::MatrixXd* s) const {
  const int g = static_cast<int>(free_columns_.size()) + 1;
  const int eliminated = static_cast<int>(problem_.scene.dots_in_base.size()) - 2;
  // sum_j h_gj h_jj^-1 h_gj^T = W W^T, W's 3 columns per dot h_gj L_j^-T (h_jj = L_j L_j^T), a chunk of
  // dots at a time.
  DotColumns w(g, 3, -1.0, s);
  Eigen::Matrix<double, 2, 7> f;
  Eigen::Matrix<double, 2, 3> b;
  Eigen::Matrix<double, Eigen::Dynamic, 2> a(g, 2);
  for (int j = 0; j < eliminated; ++j) {
    const bool seen = add != nullptr && add->seen[j + 2];
    Eigen::Matrix3d h = sums.h_jj[j];
    if (seen) {
      DotRows(*add, j + 2, &f, &b);
      PixelRows(f, add->zt, a.col(0).data(), a.col(1).data());
      h.noalias() += b.transpose() * b;
    }
    Eigen::Matrix3d li;  // L_j^-1
    if (!InverseCholesky3(h, &li)) continue;  // a dot seen from fewer than two poses: no information on the globals
    double* w0 = w.Take(3);
    double* w1 = w0 + w.ld();
    double* w2 = w1 + w.ld();
    // The dot's (free rho, f_x) x 3 block of sums plus add's a^T b, then times L_j^-T.
    for (int k = 0; k < 3; ++k) {
      double* wk = w0 + static_cast<size_t>(k) * w.ld();
      std::copy_n(sums.h_gj.col(3 * j + k).data(), g, wk);
      if (seen) AddTimes(a.col(0).data(), a.col(1).data(), b(0, k), b(1, k), wk, g);
    }
    TimesLowerTransposed(li, w0, w1, w2, g);
  }
  w.Flush();
}

FisherValue FisherDesign::EvaluateSums(const Sums& sums, int extra, bool with_variances) const {
  const int g = static_cast<int>(free_columns_.size()) + 1;
  const Candidate* add = extra >= 0 ? &candidates_.at(extra) : nullptr;
  // s: the information of (free rho, f_x) with every dot eliminated (lower triangle), the yardstick dots last.
  Eigen::MatrixXd h = sums.h_gg;
  if (add != nullptr) AddInformation(*add, &h);
  Eigen::MatrixXd s = h.topLeftCorner(g, g);
  SubtractDots(sums, add, &s);
  return Finish(h.block(0, g, g, 6), h.bottomRightCorner<6, 6>() + YardstickInformation(), with_variances, &s);
}

FisherDesign::Rest FisherDesign::PrepareRest(Sums sums) const {
  const int g = static_cast<int>(free_columns_.size()) + 1;
  const int eliminated = static_cast<int>(problem_.scene.dots_in_base.size()) - 2;
  Rest rest;
  rest.sums = std::move(sums);
  rest.k.resize(eliminated);
  rest.p.resize(g, 3 * eliminated);
  for (int j = 0; j < eliminated; ++j) {
    Eigen::Matrix3d li;
    if (!InverseCholesky3(rest.sums.h_jj[j], &li)) return rest;  // a dot the rest does not determine
    rest.k[j].noalias() = li.transpose() * li;
    rest.p.middleCols<3>(3 * j).noalias() = rest.sums.h_gj.middleCols<3>(3 * j) * rest.k[j];
  }
  rest.every_dot_determined = true;
  rest.s = rest.sums.h_gg.topLeftCorner(g, g);
  SubtractDots(rest.sums, nullptr, &rest.s);
  return rest;
}

// A new pose's rows (a, b) for dot j, under the rest's information on the dot (its inverse k, and p = k h_gj^T),
// add the marginal information atilde^T (I + b k b^T)^-1 atilde with atilde = a - b p: two columns
// w = L^-1 atilde of the rank update (I + b k b^T = L L^T).
FisherValue FisherDesign::EvaluateWithRest(const Rest& rest, int extra, bool with_variances) const {
  if (!rest.every_dot_determined || extra < 0) return EvaluateSums(rest.sums, extra, with_variances);
  const int g = static_cast<int>(free_columns_.size()) + 1;
  const int dots = static_cast<int>(problem_.scene.dots_in_base.size());
  const Candidate& c = candidates_.at(extra);
  Eigen::MatrixXd s = rest.s;
  DotColumns w(g, 2, 1.0, &s);
  Eigen::Matrix<double, 2, 7> f;
  Eigen::Matrix<double, 2, 3> b;
  for (int j = 0; j < 2; ++j) {  // the yardstick dots are globals: their rows as they are
    if (!c.seen[j]) continue;
    DotRows(c, j, &f, &b);
    double* w0 = w.Take(2);
    PixelRows(f, c.zt, w0, w0 + w.ld());
  }
  // The other dots' columns, computed a chunk at a time by internal::MarginalColumns before they are added.
  std::vector<internal::MarginalDot> pending;
  auto add_pending = [&]() {
    internal::MarginalColumns(pending.data(), static_cast<int>(pending.size()), c.zt.data(), g);
    pending.clear();
    w.Flush();
  };
  for (int j = 2; j < dots; ++j) {
    if (!c.seen[j]) continue;
    DotRows(c, j, &f, &b);
    const Eigen::Matrix<double, 2, 3> t = b * rest.k[j - 2];
    internal::MarginalDot d;
    d.l00 = std::sqrt(1.0 + t.row(0).dot(b.row(0)));
    d.l10 = t.row(1).dot(b.row(0)) / d.l00;
    d.l11 = std::sqrt(1.0 + t.row(1).dot(b.row(1)) - d.l10 * d.l10);
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>>(&d.f[0][0]) = f;
    Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>>(&d.b[0][0]) = b;
    d.p = rest.p.col(3 * (j - 2)).data();
    if (w.Full(2)) add_pending();
    d.w0 = w.Take(2);
    d.w1 = d.w0 + w.ld();
    pending.push_back(d);
  }
  add_pending();
  const Eigen::MatrixXd h_gy = rest.sums.h_gg.block(0, g, g, 6) + c.yard.leftCols(g).transpose();
  const Eigen::Matrix<double, 6, 6> h_yy =
      rest.sums.h_gg.bottomRightCorner<6, 6>() + c.yard.rightCols<6>() + YardstickInformation();
  return Finish(h_gy, h_yy, with_variances, &s);
}

FisherValue FisherDesign::Finish(const Eigen::Ref<const Eigen::MatrixXd>& h_gy, const Eigen::Matrix<double, 6, 6>& h_yy,
                                 bool with_variances, Eigen::MatrixXd* s) const {
  FisherValue value;
  const int nf = static_cast<int>(free_columns_.size()), g = nf + 1;
  // The yardstick dots: the Schur complement of their 6 x 6 block.
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> yard(h_yy);
  if (yard.info() != Eigen::Success) return value;
  const Eigen::Matrix<double, 6, 6> l = yard.matrixL();
  Eigen::Matrix<double, Eigen::Dynamic, 6> w_y(g, 6);  // h_gy L^-T, row by row by forward substitution
  for (int r = 0; r < g; ++r) {
    for (int m = 0; m < 6; ++m) {
      double x = h_gy(r, m);
      for (int k = 0; k < m; ++k) x -= l(m, k) * w_y(r, k);
      w_y(r, m) = x / l(m, m);
    }
  }
  AddOuterLower(-1.0, w_y, s);
  if (!CholeskyLower(s)) return value;  // s's lower triangle is now L, s = L L^T
  const double sigma2 = options_.pixel_noise_px * options_.pixel_noise_px;
  // cov = sigma^2 s^-1: log det(cov^-1) = log det s - (nf + 1) log sigma^2.
  value.ok = true;
  value.log_det = 2.0 * s->diagonal().array().log().sum() - g * std::log(sigma2);
  if (!with_variances) return value;
  // diag(s^-1)_k = |L^-1 e_k|^2: column k of L^-1 by forward substitution.
  Eigen::VectorXd variance(g), x(g);
  for (int k = 0; k < g; ++k) {
    x.setZero();
    x[k] = 1.0;
    for (int m = k; m < g; ++m) {
      x[m] /= (*s)(m, m);
      x.segment(m + 1, g - m - 1).noalias() -= x[m] * s->col(m).segment(m + 1, g - m - 1);
    }
    variance[k] = sigma2 * x.segment(k, g - k).squaredNorm();
  }
  value.stddev = variance.cwiseSqrt();
  const KinematicParameters params(problem_.robot.num_joints());
  value.a_value = 0;
  for (int k = 0; k <= nf; ++k) {
    const double prior = k == nf ? options_.prior_fx_px
                                 : (params.kind(free_columns_[k]) == ParameterKind::kLength ? options_.prior_length_m
                                                                                            : options_.prior_angle_rad);
    value.a_value += variance[k] / (prior * prior);
  }
  return value;
}

}  // namespace selfcal::planning
