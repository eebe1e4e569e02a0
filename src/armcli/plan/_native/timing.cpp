// Time parameterisation of a polyline with TOPP-RA (the toppra C++ library, the same
// algorithm and Seidel LP solver as the Python package plan.timing uses without the
// extension): each straight segment timed from rest to rest under joint velocity,
// acceleration and (optionally) torque limits, sampled at the output rate; then the
// velocities and accelerations of the clamped C² cubic spline through those samples.

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
                    double rate) {
  const int n = static_cast<int>(W.cols());
  toppra::LinearConstraintPtrs cons{
      std::make_shared<toppra::constraint::LinearJointVelocity>(-lim.velocity, lim.velocity),
      std::make_shared<toppra::constraint::LinearJointAcceleration>(-lim.acceleration,
                                                                     lim.acceleration)};
  if (lim.effort.size() == n) cons.push_back(std::make_shared<Torque>(s, lim.iv, lim.effort));
  for (auto& c : cons) c->discretizationType(toppra::Interpolation);
  const toppra::Vector gridpoints = toppra::Vector::LinSpaced(grid + 1, 0.0, 1.0);
  std::vector<std::shared_ptr<toppra::parametrizer::ConstAccel>> pieces;
  std::vector<double> starts{0.0};
  Timed out;
  for (long k = 0; k + 1 < W.rows(); ++k) {
    auto path = std::make_shared<Segment>(W.row(k).transpose(), W.row(k + 1).transpose());
    toppra::algorithm::TOPPRA algo(cons, path);
    algo.solver(std::make_shared<toppra::solver::Seidel>());
    algo.setGridpoints(gridpoints);
    algo.setInitialXBounds(toppra::Bound(0.0, MAX_PATH_SPEED_SQ));
    if (algo.computePathParametrization(0.0, 0.0) != toppra::ReturnCode::OK) {
      out.failed_segment = static_cast<int>(k);
      return out;
    }
    const auto& data = algo.getParameterizationData();
    pieces.push_back(std::make_shared<toppra::parametrizer::ConstAccel>(
        path, data.gridpoints, data.parametrization));
    starts.push_back(starts.back() + pieces.back()->getTimes().tail(1)[0]);
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
