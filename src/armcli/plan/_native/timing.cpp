// Time parameterisation of a polyline with TOPP-RA (the toppra C++ library, the same
// algorithm and Seidel LP solver as the Python package plan.timing uses without the
// extension): each straight segment timed from rest to rest under joint velocity,
// acceleration and (optionally) torque limits, sampled at the output rate; then the
// velocities and accelerations of the clamped C² cubic spline through those samples.
//
// Corner blends (blend > 0): a rest at every corner makes a many-segment path slow. Each
// corner P between segments of lengths L1, L2 (joint-space, Euclidean) is replaced by the
// quadratic Bézier from A = P - r u1 to C = P + r u2 (u: the unit directions, r = blend *
// min(L1, L2), blend < 0.5 so that neighbouring blends never overlap) when the curve is free
// by the planner's own state check every `step` (max norm); otherwise r is halved, and
// after BLEND_HALVINGS the motion stops at P as before. The curve lies in the triangle A P
// C, inside the joint-limit box; with s the arc length on the lines and 2r along the curve,
// dq/ds is continuous (unit length at the joins) and d²q/ds² = (u2 - u1) / (2r) is constant
// on the curve: TOPP-RA times each stretch between stops in one pass, through its corners.

#include <cmath>
#include <memory>
#include <stdexcept>
#include <toppra/algorithm/toppra.hpp>
#include <toppra/constraint/joint_torque.hpp>
#include <toppra/constraint/linear_joint_acceleration.hpp>
#include <toppra/constraint/linear_joint_velocity.hpp>
#include <toppra/geometric_path.hpp>
#include <toppra/parametrizer/const_accel.hpp>
#include <toppra/solver/seidel.hpp>

#include "core.hpp"
#include "timing.hpp"

namespace armcli_plan {

namespace {

constexpr double MAX_PATH_SPEED_SQ = 1e16;  // [1/s²] sdot² bound (toppra's default: 100)
constexpr int BLEND_HALVINGS = 3;  // a blend that collides is tried with r / 2, r / 4, r / 8
constexpr int BLEND_GRID_DIVISOR = 3;  // a blend gets grid / 3 TOPP-RA intervals

// Lines joined by quadratic Bézier blends (a stretch of the path between two stops).
struct Piece {
  bool line = true;
  Vec a, p, c;  // line: from a to c; blend: ends a and c, corner p
  double s0 = 0.0, len = 0.0;  // where it starts on the path and its length in s
};

class Blended : public toppra::GeometricPath {
 public:
  explicit Blended(std::vector<Piece> pieces)
      : toppra::GeometricPath(static_cast<int>(pieces.front().a.size())),
        pieces_(std::move(pieces)) {}
  toppra::Vector eval_single(toppra::value_type s, int order) const override {
    size_t k = 0;
    while (k + 1 < pieces_.size() && pieces_[k + 1].s0 <= s) ++k;
    const Piece& P = pieces_[k];
    const double u = std::min(std::max((s - P.s0) / P.len, 0.0), 1.0);
    if (P.line) {
      if (order == 0) return P.a + u * (P.c - P.a);
      if (order == 1) return (P.c - P.a) / P.len;
      return toppra::Vector::Zero(P.a.size());
    }
    if (order == 0) return (1 - u) * (1 - u) * P.a + 2 * (1 - u) * u * P.p + u * u * P.c;
    if (order == 1) return (2 * (1 - u) * (P.p - P.a) + 2 * u * (P.c - P.p)) / P.len;
    return 2 * (P.a - 2 * P.p + P.c) / (P.len * P.len);
  }
  toppra::Bound pathInterval() const override {
    return toppra::Bound(0.0, pieces_.back().s0 + pieces_.back().len);
  }
  // TOPP-RA's grid: `grid` intervals per line, grid / 3 per blend, every join a gridpoint.
  toppra::Vector gridpoints(int grid) const {
    std::vector<double> g{0.0};
    for (const Piece& P : pieces_) {
      const int m = P.line ? grid : std::max(2, grid / BLEND_GRID_DIVISOR);
      for (int i = 1; i <= m; ++i) g.push_back(P.s0 + P.len * i / m);
    }
    return Eigen::Map<toppra::Vector>(g.data(), static_cast<long>(g.size()));
  }

 private:
  std::vector<Piece> pieces_;
};

// Whether the blend a -> (p) -> c is free by the planner's check every `step` (max norm).
bool blend_free(Work& w, const Vec& a, const Vec& p, const Vec& c, double step) {
  const double bound = (p - a).cwiseAbs().maxCoeff() + (c - p).cwiseAbs().maxCoeff();
  const int m = std::max(2, static_cast<int>(std::ceil(bound / step)));
  Vec x(a.size());
  for (int k : bisection_order(m)) {
    if (k == m) continue;  // the ends lie on the segments, checked by the planner
    const double u = static_cast<double>(k) / m;
    x = (1 - u) * (1 - u) * a + 2 * (1 - u) * u * p + u * u * c;
    if (!w.free(x.data())) return false;
  }
  return true;
}

// Each corner's blend radius (0: the motion stops there), checked as blend_free says.
std::vector<double> radii(Work& w, const RMat& W, double blend, double step) {
  const long N = W.rows();
  std::vector<double> r(N, 0.0);
  for (long k = 1; k + 1 < N; ++k) {
    const Vec P = W.row(k).transpose();
    const Vec d1 = P - W.row(k - 1).transpose(), d2 = W.row(k + 1).transpose() - P;
    const double L1 = d1.norm(), L2 = d2.norm();
    if (!(L1 > 0.0) || !(L2 > 0.0)) continue;
    double rk = blend * std::min(L1, L2);
    for (int h = 0; h <= BLEND_HALVINGS; ++h, rk *= 0.5) {
      if (blend_free(w, P - rk * d1 / L1, P, P + rk * d2 / L2, step)) {
        r[k] = rk;
        break;
      }
    }
  }
  return r;
}

// The stretch of W from stop i to stop j (rows), its inner corners blended by radius r.
std::vector<Piece> stretch(const RMat& W, const std::vector<double>& r, long i, long j) {
  std::vector<Piece> out;
  double s = 0.0;
  Vec from = W.row(i).transpose();
  for (long k = i; k < j; ++k) {
    const Vec P = W.row(k + 1).transpose();
    const Vec d = P - W.row(k).transpose();
    const double L = d.norm();
    const Vec to = k + 1 < j ? Vec(P - r[k + 1] * d / L) : P;
    Piece line;
    line.a = from, line.c = to, line.s0 = s, line.len = (to - from).norm();
    if (line.len > 0.0) out.push_back(line), s += line.len;
    if (k + 1 == j) break;
    const Vec d2 = W.row(k + 2).transpose() - P;
    Piece curve;
    curve.line = false;
    curve.a = to, curve.p = P, curve.c = P + r[k + 1] * d2 / d2.norm();
    curve.s0 = s, curve.len = 2.0 * r[k + 1];
    out.push_back(curve), s += curve.len;
    from = curve.c;
  }
  return out;
}

class Segment : public toppra::GeometricPath {
 public:
  Segment(const Vec& a, const Vec& b)
      : toppra::GeometricPath(static_cast<int>(a.size())), a_(a), d_(b - a) {}
  toppra::Vector eval_single(toppra::value_type s, int order) const override {
    if (order == 0) return a_ + s * d_;
    if (order == 1) return d_;
    return toppra::Vector::Zero(a_.size());
  }
  toppra::Bound pathInterval() const override { return toppra::Bound(0.0, 1.0); }

 private:
  Vec a_, d_;
};

// Joint torques of the planned joints along the path: RNEA, followers moving with leaders.
class Torque : public toppra::constraint::JointTorque {
 public:
  Torque(const Scene& s, const std::vector<int>& iv, const Vec& limit)
      : JointTorque(-limit, limit, Vec()), s_(s), iv_(iv), data_(s.model) {}
  void computeInverseDynamics(const toppra::Vector& x, const toppra::Vector& xd,
                              const toppra::Vector& xdd, toppra::Vector& tau) override {
    tau.resize(static_cast<Eigen::Index>(iv_.size()));
    inverse_dynamics(s_, data_, x.data(), xd.data(), xdd.data(), iv_, q_, v_, a_, tau.data());
  }

 private:
  const Scene& s_;
  std::vector<int> iv_;
  pin::Data data_;
  Vec q_, v_, a_;
};

}  // namespace

Timed time_polyline(const Scene& s, const RMat& W, const TimingLimits& lim, int grid,
                    double rate, Work* w, double blend, double step) {
  const int n = static_cast<int>(W.cols());
  toppra::LinearConstraintPtrs cons{
      std::make_shared<toppra::constraint::LinearJointVelocity>(-lim.velocity, lim.velocity),
      std::make_shared<toppra::constraint::LinearJointAcceleration>(-lim.acceleration,
                                                                     lim.acceleration)};
  if (lim.effort.size() == n) cons.push_back(std::make_shared<Torque>(s, lim.iv, lim.effort));
  for (auto& c : cons) c->discretizationType(toppra::Interpolation);
  const toppra::Vector gridpoints = toppra::Vector::LinSpaced(grid + 1, 0.0, 1.0);
  std::vector<double> r(W.rows(), 0.0);
  if (w != nullptr && blend > 0.0) r = radii(*w, W, blend, step);
  std::vector<std::shared_ptr<toppra::parametrizer::ConstAccel>> pieces;
  std::vector<double> starts{0.0};
  Timed out;
  for (long k = 0; k + 1 < W.rows();) {
    long j = k + 1;  // the next stop: the end, or a corner not blended
    while (j + 1 < W.rows() && r[j] > 0.0) ++j;
    toppra::GeometricPathPtr path;
    toppra::Vector grid_k = gridpoints;
    if (j == k + 1) {
      path = std::make_shared<Segment>(W.row(k).transpose(), W.row(k + 1).transpose());
    } else {
      auto blended = std::make_shared<Blended>(stretch(W, r, k, j));
      grid_k = blended->gridpoints(grid);
      path = blended;
    }
    toppra::algorithm::TOPPRA algo(cons, path);
    algo.solver(std::make_shared<toppra::solver::Seidel>());
    algo.setGridpoints(grid_k);
    algo.setInitialXBounds(toppra::Bound(0.0, MAX_PATH_SPEED_SQ));
    if (algo.computePathParametrization(0.0, 0.0) != toppra::ReturnCode::OK) {
      out.failed_segment = static_cast<int>(k);
      return out;
    }
    const auto& data = algo.getParameterizationData();
    pieces.push_back(std::make_shared<toppra::parametrizer::ConstAccel>(
        path, data.gridpoints, data.parametrization));
    starts.push_back(starts.back() + pieces.back()->getTimes().tail(1)[0]);
    k = j;
  }
  const double duration = starts.back();
  const long points = std::max<long>(2, static_cast<long>(std::ceil(duration * rate)) + 1);
  out.times.resize(points);
  const double dt = duration / static_cast<double>(points - 1);  // as numpy's linspace
  for (long i = 0; i < points; ++i) out.times[i] = static_cast<double>(i) * dt;
  out.times[points - 1] = duration;
  out.positions.resize(points, n);
  size_t seg = 0;
  for (long i = 0; i < points; ++i) {
    const double t = out.times[i];
    while (seg + 1 < pieces.size() && starts[seg + 1] <= t) ++seg;
    const double span = pieces[seg]->getTimes().tail(1)[0];
    const double local = std::min(std::max(t - starts[seg], 0.0), span);
    out.positions.row(i) = pieces[seg]->eval_single(local, 0).transpose();
  }
  out.positions.row(0) = W.row(0);
  out.positions.row(points - 1) = W.row(W.rows() - 1);
  spline(out.times, out.positions, out.velocities, out.accelerations);
  return out;
}

void spline(const Vec& t, const RMat& y, RMat& v, RMat& a) {
  // Slopes s of the cubic through (t_i, y_i) with s_0 = s_N = 0 (clamped, as scipy's
  // CubicSpline with bc_type ((1, 0), (1, 0))): h_i s_{i-1} + 2 (h_{i-1} + h_i) s_i +
  // h_{i-1} s_{i+1} = 3 (h_i m_{i-1} + h_{i-1} m_i) inside, solved by the Thomas algorithm.
  const long N = t.size() - 1, n = y.cols();
  v = RMat::Zero(N + 1, n);
  a = RMat::Zero(N + 1, n);
  Vec h = t.tail(N) - t.head(N);
  RMat m(N, n);
  for (long i = 0; i < N; ++i) m.row(i) = (y.row(i + 1) - y.row(i)) / h[i];
  if (N >= 2) {
    const long K = N - 1;  // unknowns s_1 .. s_{N-1}
    Vec c_(K);
    RMat d_(K, n);
    for (long k = 0; k < K; ++k) {
      const long i = k + 1;
      const double lo = h[i], diag = 2.0 * (h[i - 1] + h[i]), up = h[i - 1];
      Eigen::RowVectorXd rhs = 3.0 * (h[i] * m.row(i - 1) + h[i - 1] * m.row(i));
      if (k == 0) {
        c_[k] = up / diag;
        d_.row(k) = rhs / diag;
      } else {
        const double den = diag - lo * c_[k - 1];
        c_[k] = up / den;
        d_.row(k) = (rhs - lo * d_.row(k - 1)) / den;
      }
    }
    for (long k = K - 1; k >= 0; --k) {
      v.row(k + 1) = d_.row(k);
      if (k + 1 < K) v.row(k + 1) -= c_[k] * v.row(k + 2);
    }
  }
  for (long i = 0; i < N; ++i)  // second derivative at each knot, from the piece after it
    a.row(i) = (6.0 * m.row(i) - 4.0 * v.row(i) - 2.0 * v.row(i + 1)) / h[i];
  a.row(N) = (-6.0 * m.row(N - 1) + 2.0 * v.row(N - 1) + 4.0 * v.row(N)) / h[N - 1];
}

}  // namespace armcli_plan
