#include "bundle/kinematic_lm.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Dense>

namespace selfcal::bundle::internal {

const char* TerminationName(LmSummary::Termination termination) {
  switch (termination) {
    case LmSummary::Termination::kConvergence: return "CONVERGENCE";
    case LmSummary::Termination::kNoConvergence: return "NO_CONVERGENCE";
    case LmSummary::Termination::kFailure: return "FAILURE";
  }
  return "FAILURE";
}

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Map2x3 = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>;

// Where every unknown lives in the parameter vector x = [free rho | free intrinsics | yardstick ends | other
// dots], and the observations in the order the elimination reads them (each eliminated dot's rows
// together, dots ascending; then the rows of the yardstick ends).
struct Layout {
  int n = 0, m = 0;        // free rho entries, free intrinsics
  int num_globals = 0;     // n + m + 3 per yardstick end
  std::vector<int> column;  // per dot: its first column in x
  std::vector<int> eliminated;               // dots eliminated by their Schur complement, ascending
  std::vector<int> chunk_begin;              // per eliminated dot (and one past the end): its first row
  int num_chunk_rows = 0;                    // observations of eliminated dots (they come first)
  std::vector<int> order;                    // observation index per row
  int size() const { return static_cast<int>(column.empty() ? num_globals : num_globals + 3 * eliminated.size()); }
};

Layout MakeLayout(const BundleData& data, int n, int m) {
  Layout layout;
  layout.n = n;
  layout.m = m;
  const int num_dots = static_cast<int>(data.dot_ids.size());
  std::vector<bool> global(num_dots, false);
  for (const Yardstick& y : data.yardsticks) global[y.dot_a] = global[y.dot_b] = true;
  layout.column.assign(num_dots, -1);
  int next = n + m;
  for (int d = 0; d < num_dots; ++d) {
    if (global[d]) layout.column[d] = next, next += 3;
  }
  layout.num_globals = next;
  for (int d = 0; d < num_dots; ++d) {
    if (!global[d]) layout.column[d] = next, next += 3, layout.eliminated.push_back(d);
  }
  std::vector<std::vector<int>> rows(num_dots);
  for (size_t k = 0; k < data.observations.size(); ++k) rows[data.observations[k].dot].push_back(static_cast<int>(k));
  for (int d : layout.eliminated) {
    layout.chunk_begin.push_back(static_cast<int>(layout.order.size()));
    layout.order.insert(layout.order.end(), rows[d].begin(), rows[d].end());
  }
  layout.chunk_begin.push_back(static_cast<int>(layout.order.size()));
  layout.num_chunk_rows = static_cast<int>(layout.order.size());
  for (int d = 0; d < num_dots; ++d) {
    if (global[d]) layout.order.insert(layout.order.end(), rows[d].begin(), rows[d].end());
  }
  return layout;
}

// The residuals and (when asked) the Jacobian at one point, rows in layout order: per observation the
// whitened residual (corrected for the Huber loss), its derivatives by the n + m leading globals and by
// its dot; per yardstick the residual and its derivatives by both ends.
struct Linearization {
  std::vector<double> r, jg, jd;  // 2, 2 x (n + m) and 2 x 3 per row
  std::vector<double> ry, jy;     // 1 and 2 x 3 per yardstick
};

class Problem {
 public:
  Problem(const BundleData& data, const std::vector<int>& free, const std::vector<int>& free_intrinsics,
          const LmOptions& options, const BundleState& start)
      : data_(data), free_(free), free_intrinsics_(free_intrinsics), options_(options), start_(start),
        layout_(MakeLayout(data, static_cast<int>(free.size()), static_cast<int>(free_intrinsics.size()))),
        caches_(data.joints.size()) {}

  const Layout& layout() const { return layout_; }

  Eigen::VectorXd Pack(const BundleState& state) const {
    Eigen::VectorXd x(layout_.size());
    for (int k = 0; k < layout_.n; ++k) x[k] = state.rho[free_[k]];
    for (int k = 0; k < layout_.m; ++k) x[layout_.n + k] = state.intrinsics[free_intrinsics_[k]];
    for (size_t d = 0; d < state.dots.size(); ++d) x.segment<3>(layout_.column[d]) = state.dots[d];
    return x;
  }

  void Unpack(const Eigen::VectorXd& x, BundleState* state) const {
    *state = start_;
    for (int k = 0; k < layout_.n; ++k) state->rho[free_[k]] = x[k];
    for (int k = 0; k < layout_.m; ++k) state->intrinsics[free_intrinsics_[k]] = x[layout_.n + k];
    for (size_t d = 0; d < state->dots.size(); ++d) state->dots[d] = x.segment<3>(layout_.column[d]);
  }

  // The cost 1/2 sum rho(|r|^2) at x, and the linearisation when `lin` is given. False when a residual or
  // a derivative cannot be evaluated (a dot behind a camera, anything non-finite).
  bool Evaluate(const Eigen::VectorXd& x, double* cost, Linearization* lin);

 private:
  const BundleData& data_;
  const std::vector<int>& free_;
  const std::vector<int>& free_intrinsics_;
  const LmOptions& options_;
  const BundleState& start_;
  const Layout layout_;
  std::vector<PoseCache> caches_;
  BundleState point_;
  std::vector<double> d_columns_;
};

bool AllFinite(const double* v, int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

bool Problem::Evaluate(const Eigen::VectorXd& x, double* cost, Linearization* lin) {
  Unpack(x, &point_);
  const bool jacobian = lin != nullptr;
  for (size_t p = 0; p < caches_.size(); ++p) {
    ComputePoseCache(data_, static_cast<int>(p), point_.rho.data(), free_, jacobian, &caches_[p]);
  }
  const int n = layout_.n, m = layout_.m, width = n + m;
  const int rows = static_cast<int>(layout_.order.size());
  if (jacobian) {
    lin->r.resize(2 * rows);
    lin->jg.resize(static_cast<size_t>(2 * width) * rows);
    lin->jd.resize(6 * static_cast<size_t>(rows));
  }
  const double a = options_.huber_threshold, b = a * a;
  double sum = 0;
  double r[2], d_intrinsics[2 * kNumIntrinsics], d_dot[6];
  d_columns_.resize(2 * static_cast<size_t>(n));
  double* const dc = d_columns_.data();
  for (int row = 0; row < rows; ++row) {
    const Observation& o = data_.observations[layout_.order[row]];
    if (!EvaluateReprojection(point_.intrinsics, data_.sigma_px, caches_[o.pose], point_.dots[o.dot], o.pixel, r,
                              jacobian ? dc : nullptr, jacobian && m > 0 ? d_intrinsics : nullptr,
                              jacobian ? d_dot : nullptr)) {
      return false;
    }
    const double s = r[0] * r[0] + r[1] * r[1];
    double rho0 = s, rho1 = 1.0;
    if (a > 0 && s > b) {  // Ceres' HuberLoss, outlier region
      const double norm = std::sqrt(s);
      rho0 = 2.0 * a * norm - b;
      rho1 = std::max(std::numeric_limits<double>::min(), a / norm);
    }
    sum += 0.5 * rho0;
    if (!jacobian) continue;
    // Ceres' corrector with rho'' <= 0: residual and Jacobian scaled by sqrt(rho') (1 without a loss).
    const double scale = a > 0 ? std::sqrt(rho1) : 1.0;
    double* jg = &lin->jg[static_cast<size_t>(2 * width) * row];
    for (int i = 0; i < 2; ++i) {
      lin->r[2 * row + i] = r[i] * scale;
      for (int c = 0; c < n; ++c) jg[i * width + c] = dc[i * n + c] * scale;
      for (int k = 0; k < m; ++k) jg[i * width + n + k] = d_intrinsics[i * kNumIntrinsics + free_intrinsics_[k]] * scale;
      for (int c = 0; c < 3; ++c) lin->jd[6 * row + 3 * i + c] = d_dot[3 * i + c] * scale;
    }
    if (!AllFinite(jg, 2 * width) || !AllFinite(&lin->jd[6 * row], 6)) return false;
  }
  if (jacobian) {
    lin->ry.resize(data_.yardsticks.size());
    lin->jy.resize(6 * data_.yardsticks.size());
  }
  for (size_t k = 0; k < data_.yardsticks.size(); ++k) {
    const Yardstick& y = data_.yardsticks[k];
    const Eigen::Vector3d diff = point_.dots[y.dot_a] - point_.dots[y.dot_b];
    const double norm = diff.norm(), inv_sigma = 1.0 / data_.yardstick_sigma_m;
    const double residual = (norm - y.length_m) * inv_sigma;
    if (!std::isfinite(residual)) return false;
    sum += 0.5 * residual * residual;
    if (!jacobian) continue;
    if (!(norm > 0)) return false;
    lin->ry[k] = residual;
    const Eigen::Vector3d d = diff / norm * inv_sigma;
    for (int c = 0; c < 3; ++c) lin->jy[6 * k + c] = d[c], lin->jy[6 * k + 3 + c] = -d[c];
  }
  *cost = sum;
  return true;
}

// Calls f(column, entry, residual) for every Jacobian entry of `lin`, row by row.
template <typename F>
void ForEachEntry(const Layout& layout, const BundleData& data, const Linearization& lin, F&& f) {
  const int width = layout.n + layout.m;
  const int rows = static_cast<int>(layout.order.size());
  for (int row = 0; row < rows; ++row) {
    const int dot_column = layout.column[data.observations[layout.order[row]].dot];
    for (int i = 0; i < 2; ++i) {
      const double r = lin.r[2 * row + i];
      const double* jg = &lin.jg[static_cast<size_t>(2 * width) * row + i * width];
      for (int c = 0; c < width; ++c) f(c, jg[c], r);
      for (int c = 0; c < 3; ++c) f(dot_column + c, lin.jd[6 * row + 3 * i + c], r);
    }
  }
  for (size_t k = 0; k < data.yardsticks.size(); ++k) {
    const double r = lin.ry[k];
    const int a = layout.column[data.yardsticks[k].dot_a], b = layout.column[data.yardsticks[k].dot_b];
    for (int c = 0; c < 3; ++c) f(a + c, lin.jy[6 * k + c], r), f(b + c, lin.jy[6 * k + 3 + c], r);
  }
}

Eigen::VectorXd SquaredColumnNorms(const Layout& layout, const BundleData& data, const Linearization& lin) {
  Eigen::VectorXd norms = Eigen::VectorXd::Zero(layout.size());
  ForEachEntry(layout, data, lin, [&](int c, double j, double) { norms[c] += j * j; });
  return norms;
}

Eigen::VectorXd Gradient(const Layout& layout, const BundleData& data, const Linearization& lin) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(layout.size());
  ForEachEntry(layout, data, lin, [&](int c, double j, double r) { g[c] += j * r; });
  return g;
}

void ScaleColumns(const Layout& layout, const BundleData& data, const Eigen::VectorXd& scale, Linearization* lin) {
  const int width = layout.n + layout.m;
  const int rows = static_cast<int>(layout.order.size());
  for (int row = 0; row < rows; ++row) {
    const int dot_column = layout.column[data.observations[layout.order[row]].dot];
    for (int i = 0; i < 2; ++i) {
      double* jg = &lin->jg[static_cast<size_t>(2 * width) * row + i * width];
      for (int c = 0; c < width; ++c) jg[c] *= scale[c];
      for (int c = 0; c < 3; ++c) lin->jd[6 * row + 3 * i + c] *= scale[dot_column + c];
    }
  }
  for (size_t k = 0; k < data.yardsticks.size(); ++k) {
    const int a = layout.column[data.yardsticks[k].dot_a], b = layout.column[data.yardsticks[k].dot_b];
    for (int c = 0; c < 3; ++c) lin->jy[6 * k + c] *= scale[a + c], lin->jy[6 * k + 3 + c] *= scale[b + c];
  }
}

// J step, row by row (observations, then yardsticks).
Eigen::VectorXd MultiplyJacobian(const Layout& layout, const BundleData& data, const Linearization& lin,
                                 const Eigen::VectorXd& step) {
  const int width = layout.n + layout.m;
  const int rows = static_cast<int>(layout.order.size());
  Eigen::VectorXd out(2 * rows + static_cast<int>(data.yardsticks.size()));
  for (int row = 0; row < rows; ++row) {
    const int dot_column = layout.column[data.observations[layout.order[row]].dot];
    for (int i = 0; i < 2; ++i) {
      const double* jg = &lin.jg[static_cast<size_t>(2 * width) * row + i * width];
      double sum = 0;
      for (int c = 0; c < width; ++c) sum += jg[c] * step[c];
      for (int c = 0; c < 3; ++c) sum += lin.jd[6 * row + 3 * i + c] * step[dot_column + c];
      out[2 * row + i] = sum;
    }
  }
  for (size_t k = 0; k < data.yardsticks.size(); ++k) {
    const int a = layout.column[data.yardsticks[k].dot_a], b = layout.column[data.yardsticks[k].dot_b];
    double sum = 0;
    for (int c = 0; c < 3; ++c) sum += lin.jy[6 * k + c] * step[a + c] + lin.jy[6 * k + 3 + c] * step[b + c];
    out[2 * rows + static_cast<int>(k)] = sum;
  }
  return out;
}

// The solution y of (J^T J + D^2) y = J^T r, the dots eliminated (Ceres' DENSE_SCHUR solves the same
// system). The globals' normal matrix is one symmetric rank update over every observation row, each
// dot's coupling one 3 x (n + m) block, their correction one product over all dots. False when a system
// is not positive definite or the solution not finite.
bool SolveDamped(const Layout& layout, const BundleData& data, const Linearization& lin, const Eigen::VectorXd& d,
                 Eigen::VectorXd* y) {
  const int width = layout.n + layout.m, g = layout.num_globals;
  const int rows = static_cast<int>(layout.order.size());
  const int num_elim = static_cast<int>(layout.eliminated.size());
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(g, g);  // lower triangle used
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(g);
  const Eigen::Map<const RowMajor> f_all(lin.jg.data(), 2 * rows, width);
  const Eigen::Map<const Eigen::VectorXd> r_all(lin.r.data(), 2 * rows);
  s.topLeftCorner(width, width).selfadjointView<Eigen::Lower>().rankUpdate(f_all.transpose());
  rhs.head(width).noalias() = f_all.transpose() * r_all;
  // Per eliminated dot: C = E^T E + D^2, B = E^T F; the correction B^T C^-1 B for all dots at once.
  RowMajor b_all(3 * num_elim, width), t_all(3 * num_elim, width);
  Eigen::VectorXd u_all(3 * num_elim);  // C^-1 E^T r
  for (int k = 0; k < num_elim; ++k) {
    const int begin = layout.chunk_begin[k], count = layout.chunk_begin[k + 1] - begin;
    const Eigen::Map<const RowMajor> f(&lin.jg[static_cast<size_t>(2 * width) * begin], 2 * count, width);
    const Map2x3 e(&lin.jd[6 * static_cast<size_t>(begin)], 2 * count, 3);
    const Eigen::Map<const Eigen::VectorXd> r(&lin.r[2 * static_cast<size_t>(begin)], 2 * count);
    Eigen::Matrix3d c = e.transpose().lazyProduct(e);
    c.diagonal() += d.segment<3>(layout.column[layout.eliminated[k]]).cwiseAbs2();
    const Eigen::LLT<Eigen::Matrix3d> llt(c);
    if (llt.info() != Eigen::Success) return false;
    auto b = b_all.middleRows<3>(3 * k);
    b.noalias() = e.transpose().lazyProduct(f);
    t_all.middleRows<3>(3 * k) = llt.solve(b);
    u_all.segment<3>(3 * k) = llt.solve(e.transpose().lazyProduct(r));
  }
  s.topLeftCorner(width, width).triangularView<Eigen::Lower>() -= b_all.transpose() * t_all;
  rhs.head(width).noalias() -= b_all.transpose() * u_all;
  // The rows of the yardstick ends (their dots are global) and the yardsticks.
  for (int q = layout.num_chunk_rows; q < rows; ++q) {
    const int col = layout.column[data.observations[layout.order[q]].dot];
    const Eigen::Map<const RowMajor> f(&lin.jg[static_cast<size_t>(2 * width) * q], 2, width);
    const Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> e(&lin.jd[6 * static_cast<size_t>(q)]);
    const Eigen::Map<const Eigen::Vector2d> r(&lin.r[2 * static_cast<size_t>(q)]);
    s.block(col, 0, 3, width).noalias() += e.transpose() * f;
    s.block<3, 3>(col, col).noalias() += e.transpose() * e;
    rhs.segment<3>(col).noalias() += e.transpose() * r;
  }
  for (size_t k = 0; k < data.yardsticks.size(); ++k) {
    const int a = layout.column[data.yardsticks[k].dot_a], b = layout.column[data.yardsticks[k].dot_b];
    const Eigen::Map<const Eigen::Vector3d> ja(&lin.jy[6 * k]), jb(&lin.jy[6 * k + 3]);
    const int lo = std::min(a, b), hi = std::max(a, b);
    const Eigen::Vector3d& j_lo = a < b ? ja : jb;  // (a row of S, the other's column) in the lower triangle
    const Eigen::Vector3d& j_hi = a < b ? jb : ja;
    s.block<3, 3>(a, a).noalias() += ja * ja.transpose();
    s.block<3, 3>(b, b).noalias() += jb * jb.transpose();
    s.block<3, 3>(hi, lo).noalias() += j_hi * j_lo.transpose();
    rhs.segment<3>(a) += ja * lin.ry[k];
    rhs.segment<3>(b) += jb * lin.ry[k];
  }
  s.diagonal() += d.head(g).cwiseAbs2();
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(s);
  if (llt.info() != Eigen::Success) return false;
  y->resize(layout.size());
  y->head(g) = llt.solve(rhs);
  for (int k = 0; k < num_elim; ++k) {
    y->segment<3>(layout.column[layout.eliminated[k]]) =
        u_all.segment<3>(3 * k) - t_all.middleRows<3>(3 * k) * y->head(width);
  }
  return y->allFinite();
}

std::string Format(const char* format, double a, double b) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), format, a, b);
  return buffer;
}

// The trust region of Ceres' LevenbergMarquardtStrategy.
struct TrustRegion {
  double radius = 1e4;
  double decrease_factor = 2.0;
  bool reuse_diagonal = false;
  void Accepted(double quality) {
    radius = std::min(1e16, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3)));
    decrease_factor = 2.0;
    reuse_diagonal = false;
  }
  void Rejected() {
    radius /= decrease_factor;
    decrease_factor *= 2.0;
    reuse_diagonal = true;
  }
};

}  // namespace

LmSummary SolveKinematicBundle(const BundleData& data, const std::vector<int>& free,
                               const std::vector<int>& free_intrinsics, const LmOptions& options, BundleState* state) {
  const BundleState start = *state;
  Problem problem(data, free, free_intrinsics, options, start);
  const Layout& layout = problem.layout();
  LmSummary summary;
  Eigen::VectorXd x = problem.Pack(start);
  double x_cost = 0;
  Linearization lin;
  if (!problem.Evaluate(x, &x_cost, &lin)) {
    summary.message = "Residual and Jacobian evaluation failed.";
    return summary;
  }
  summary.initial_cost = summary.final_cost = x_cost;
  // Jacobi scaling, fixed at the start.
  Eigen::VectorXd scaling = SquaredColumnNorms(layout, data, lin);
  for (int i = 0; i < scaling.size(); ++i) scaling[i] = 1.0 / (1.0 + std::sqrt(scaling[i]));
  double gradient_max_norm = Gradient(layout, data, lin).lpNorm<Eigen::Infinity>();
  ScaleColumns(layout, data, scaling, &lin);
  double x_norm = -1;  // as Ceres: unknown until the first successful step, so no parameter test before it
  Eigen::VectorXd best = x;
  TrustRegion region;
  Eigen::VectorXd diagonal;
  int invalid_in_a_row = 0;
  bool successful = true;
  auto finish = [&](LmSummary::Termination termination, const std::string& message) {
    summary.termination = termination;
    summary.message = message;
    problem.Unpack(best, state);
    return summary;
  };
  for (int iteration = 0;; ++iteration) {
    // The end of an iteration: its tests.
    if (iteration >= options.max_iterations) {
      char buffer[96];
      std::snprintf(buffer, sizeof(buffer), "Maximum number of iterations reached. Number of iterations: %d.", iteration);
      return finish(LmSummary::Termination::kNoConvergence, buffer);
    }
    if (successful && gradient_max_norm <= options.gradient_tolerance) {
      return finish(LmSummary::Termination::kConvergence, Format("Gradient tolerance reached. Gradient max norm: %e <= %e",
                                                                 gradient_max_norm, options.gradient_tolerance));
    }
    if (region.radius <= 1e-32) {
      return finish(LmSummary::Termination::kConvergence,
                    Format("Minimum trust region radius reached. Trust region radius: %e <= %e", region.radius, 1e-32));
    }
    successful = false;
    // The step: (J^T J + D^2) y = J^T r in the scaled columns, D^2 = diag(J^T J) / radius.
    if (!region.reuse_diagonal) {
      diagonal = SquaredColumnNorms(layout, data, lin).cwiseMax(1e-6).cwiseMin(1e32);
    }
    Eigen::VectorXd step;
    double model_cost_change = 0;
    const bool solved = SolveDamped(layout, data, lin, (diagonal / region.radius).cwiseSqrt(), &step);
    if (solved) {
      step = -step;  // the system was solved for J y = r
      const Eigen::VectorXd model = MultiplyJacobian(layout, data, lin, step);
      Eigen::VectorXd residuals(model.size());
      residuals << Eigen::Map<const Eigen::VectorXd>(lin.r.data(), static_cast<Eigen::Index>(lin.r.size())),
          Eigen::Map<const Eigen::VectorXd>(lin.ry.data(), static_cast<Eigen::Index>(lin.ry.size()));
      model_cost_change = -model.dot(residuals + model / 2.0);
    }
    if (!solved || !(model_cost_change > 0.0)) {
      if (++invalid_in_a_row >= 5) {
        return finish(LmSummary::Termination::kFailure,
                      "Number of consecutive invalid steps more than Solver::Options::max_num_consecutive_invalid_steps: 5");
      }
      region.Rejected();
      summary.final_cost = std::min(summary.final_cost, x_cost);
      ++summary.iterations;
      continue;
    }
    invalid_in_a_row = 0;
    const Eigen::VectorXd candidate = x + (step.array() * scaling.array()).matrix();
    double candidate_cost = std::numeric_limits<double>::max();
    if (!problem.Evaluate(candidate, &candidate_cost, nullptr)) candidate_cost = std::numeric_limits<double>::max();
    const double step_norm = (x - candidate).norm();
    if (step_norm <= options.parameter_tolerance * (x_norm + options.parameter_tolerance)) {
      return finish(LmSummary::Termination::kConvergence,
                    Format("Parameter tolerance reached. Relative step_norm: %e <= %e.",
                           step_norm / (x_norm + options.parameter_tolerance), options.parameter_tolerance));
    }
    const double cost_change = x_cost - candidate_cost;
    if (std::fabs(cost_change) <= options.function_tolerance * x_cost) {
      return finish(LmSummary::Termination::kConvergence, Format("Function tolerance reached. |cost_change|/cost: %e <= %e",
                                                                 std::fabs(cost_change) / x_cost,
                                                                 options.function_tolerance));
    }
    const double quality = candidate_cost >= std::numeric_limits<double>::max()
                               ? std::numeric_limits<double>::lowest()
                               : cost_change / model_cost_change;
    if (!(quality > 1e-3)) {
      region.Rejected();
      summary.final_cost = std::min(summary.final_cost, candidate_cost);
      ++summary.iterations;
      continue;
    }
    x = candidate;
    x_norm = x.norm();
    if (!problem.Evaluate(x, &x_cost, &lin)) {
      return finish(LmSummary::Termination::kFailure, "Residual and Jacobian evaluation failed.");
    }
    gradient_max_norm = Gradient(layout, data, lin).lpNorm<Eigen::Infinity>();
    ScaleColumns(layout, data, scaling, &lin);
    region.Accepted(quality);
    successful = true;
    summary.final_cost = std::min(summary.final_cost, x_cost);
    best = x;  // every accepted step lowers the cost
    ++summary.iterations;
  }
}

}  // namespace selfcal::bundle::internal
