// Compiled rollout of armcli's simulator: the same step as armcli.rollout._Stepper.
//
// Why: a Python step loop pays ~100 us of interpreter overhead per step around a ~1 us
// Pinocchio ABA call; running the whole loop here removes it. The algorithm must stay
// identical to the Python reference (tests compare both to ~1e-12), so any change to
// one is made to the other.
//
// Built by `make native` (armcli.native.build) against the Pinocchio headers shipped in
// the `pin` wheel; loaded with ctypes; plain C ABI, caller-owned buffers, no exceptions
// cross the boundary.

#include <cmath>
#include <limits>
#include <vector>

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/energy.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody.hpp"

namespace pin = pinocchio;
using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;

namespace {

// Field order of the per-joint parameter rows; mirrors armcli.rollout.PARAM_FIELDS.
enum { KP, KD, DAMPING, FRICTION, LOWER, UPPER, EFFORT, VABORT, NPARAM };
enum { FAIL_NONE = 0, FAIL_NONFINITE = 1, FAIL_VELOCITY = 2, FAIL_ENERGY = 3 };
constexpr int PGS_MAX_ITERS = 200;
constexpr double PGS_TOL = 1e-14;
constexpr long ENERGY_EVERY = 100;

pin::Model build_model(int n, const int* jtype, const int* parent, const double* placement,
                       const double* axis, const double* inertia, const double* gravity) {
  pin::Model model;
  for (int i = 0; i < n; ++i) {
    const double* P = placement + 12 * i;
    Eigen::Matrix3d R;
    R << P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8];
    const pin::SE3 M(R, Eigen::Vector3d(P[9], P[10], P[11]));
    const Eigen::Vector3d ax(axis[3 * i], axis[3 * i + 1], axis[3 * i + 2]);
    const std::string name = "j" + std::to_string(i);
    pin::JointIndex id = 0;
    switch (jtype[i]) {
      case 0: id = model.addJoint(parent[i], pin::JointModelRX(), M, name); break;
      case 1: id = model.addJoint(parent[i], pin::JointModelRY(), M, name); break;
      case 2: id = model.addJoint(parent[i], pin::JointModelRZ(), M, name); break;
      case 3: id = model.addJoint(parent[i], pin::JointModelRevoluteUnaligned(ax), M, name); break;
      case 4: id = model.addJoint(parent[i], pin::JointModelPX(), M, name); break;
      case 5: id = model.addJoint(parent[i], pin::JointModelPY(), M, name); break;
      case 6: id = model.addJoint(parent[i], pin::JointModelPZ(), M, name); break;
      default: id = model.addJoint(parent[i], pin::JointModelPrismaticUnaligned(ax), M, name);
    }
    const double* I = inertia + 13 * i;  // mass, com[3], I[9] row-major
    Eigen::Matrix3d Ic;
    Ic << I[4], I[5], I[6], I[7], I[8], I[9], I[10], I[11], I[12];
    model.appendBodyToJoint(id, pin::Inertia(I[0], Eigen::Vector3d(I[1], I[2], I[3]), Ic));
  }
  model.gravity.linear(Eigen::Vector3d(gravity[0], gravity[1], gravity[2]));
  return model;
}

struct Stepper {
  pin::Model& model;
  pin::Data data;
  int n;
  const double* prm;  // n x NPARAM
  bool gravity_comp;
  double dt;
  Vec tau_pd, tau_aba, armature, g, vstar, qpred, lam, lo, hi;
  Mat A;
  std::vector<unsigned char> sat;

  Stepper(pin::Model& m, const double* params, bool gc, double dt_)
      : model(m), data(m), n(m.nv), prm(params), gravity_comp(gc), dt(dt_),
        tau_pd(n), tau_aba(n), armature(n), g(Vec::Zero(n)), vstar(n), qpred(n), lam(n),
        lo(n), hi(n), A(n, n), sat(n) {}

  double p(int i, int f) const { return prm[NPARAM * i + f]; }

  // Motor torque of the PD(+gravity) law, saturated; sets sat[i].
  void motor(const Vec& q, const Vec& v, const double* qr, const double* vr, Vec& out) {
    if (gravity_comp) g = pin::computeGeneralizedGravity(model, data, q);
    for (int i = 0; i < n; ++i) {
      const double t = p(i, KP) * (qr[i] - q[i]) + p(i, KD) * (vr[i] - v[i]) + g[i];
      const double e = p(i, EFFORT);
      sat[i] = std::fabs(t) > e;
      out[i] = sat[i] ? std::copysign(e, t) : t;
    }
  }

  // Friction and joint stops at velocity level; returns true if any impulse is non-zero.
  bool project(const Vec& q, const Vec& vs, const Vec& qp, Vec& vout, Vec& qout) {
    bool any = false;
    for (int i = 0; i < n; ++i) {
      lo[i] = -std::numeric_limits<double>::infinity();
      hi[i] = std::numeric_limits<double>::infinity();
      if (qp[i] > p(i, UPPER)) hi[i] = vs[i] + (p(i, UPPER) - qp[i]) / dt;
      if (qp[i] < p(i, LOWER)) lo[i] = vs[i] + (p(i, LOWER) - qp[i]) / dt;
      any = any || p(i, FRICTION) > 0.0 || std::isfinite(lo[i]) || std::isfinite(hi[i]);
    }
    vout = vs;
    qout = qp;
    if (!any) return false;
    A = pin::computeMinverse(model, data, q);
    A.triangularView<Eigen::StrictlyLower>() = A.transpose();
    lam.setZero();
    for (int it = 0; it < PGS_MAX_ITERS; ++it) {
      double change = 0.0, scale = 0.0;
      for (int i = 0; i < n; ++i) {
        double w = vs[i];
        for (int j = 0; j < n; ++j) w += A(i, j) * lam[j];
        w -= A(i, i) * lam[i];
        const double thr = A(i, i) * dt * p(i, FRICTION);
        double u = w > thr ? w - thr : (w < -thr ? w + thr : 0.0);
        u = std::min(std::max(u, lo[i]), hi[i]);
        const double li = (u - w) / A(i, i);
        change = std::max(change, std::fabs(li - lam[i]));
        lam[i] = li;
        scale = std::max(scale, std::fabs(li));
      }
      if (change <= PGS_TOL * (1.0 + scale)) break;
    }
    for (int i = 0; i < n; ++i) {
      double dv = 0.0;
      for (int j = 0; j < n; ++j) dv += A(i, j) * lam[j];
      vout[i] = vs[i] + dv;
      qout[i] = qp[i] + dt * dv;
    }
    return true;
  }

  void clamp(Vec& q) const {
    for (int i = 0; i < n; ++i) q[i] = std::min(std::max(q[i], p(i, LOWER)), p(i, UPPER));
  }

  // Semi-implicit Euler, velocity terms (Kd, damping) implicit through the armature.
  void euler(const Vec& q, const Vec& v, const double* qr, const double* vr, Vec& qn, Vec& vn,
             double* tau_out) {
    motor(q, v, qr, vr, tau_pd);
    for (int i = 0; i < n; ++i) {
      const double b = p(i, DAMPING) + (sat[i] ? 0.0 : p(i, KD));
      armature[i] = dt * b;
      // tau_pd already holds -Kd v for unsaturated joints: B v_k is subtracted exactly once.
      tau_aba[i] = tau_pd[i] - p(i, DAMPING) * v[i];
    }
    model.armature = armature;
    const Vec& a = pin::aba(model, data, q, v, tau_aba);
    vstar = v + dt * a;
    qpred = q + dt * vstar;
    project(q, vstar, qpred, vn, qn);
    clamp(qn);
    for (int i = 0; i < n; ++i)
      tau_out[i] = sat[i] ? tau_pd[i] : tau_pd[i] - p(i, KD) * (vn[i] - v[i]);
  }

  Vec accel(const Vec& q, const Vec& v, const double* qr, const double* vr, Vec& tau) {
    motor(q, v, qr, vr, tau);
    for (int i = 0; i < n; ++i) tau_aba[i] = tau[i] - p(i, DAMPING) * v[i];
    return pin::aba(model, data, q, v, tau_aba);
  }

  // Classic RK4 on the smooth dynamics, then the same friction/stop projection.
  void rk4(const Vec& q, const Vec& v, const double* r0, const double* r1, const double* r2,
           int nr, Vec& qn, Vec& vn, double* tau_out) {
    Vec t1(n), tmp(n);
    const Vec k1v = accel(q, v, r0, r0 + nr, t1);
    const std::vector<unsigned char> sat1 = sat;  // stage-1 flags are the ones reported
    const Vec k1q = v;
    const Vec k2q = v + 0.5 * dt * k1v;
    const Vec k2v = accel(q + 0.5 * dt * k1q, k2q, r1, r1 + nr, tmp);
    const Vec k3q = v + 0.5 * dt * k2v;
    const Vec k3v = accel(q + 0.5 * dt * k2q, k3q, r1, r1 + nr, tmp);
    const Vec k4q = v + dt * k3v;
    const Vec k4v = accel(q + dt * k3q, k4q, r2, r2 + nr, tmp);
    vstar = v + (dt / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    qpred = q + (dt / 6.0) * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
    sat = sat1;
    project(q, vstar, qpred, vn, qn);
    clamp(qn);
    for (int i = 0; i < n; ++i) tau_out[i] = t1[i];
  }
};

}  // namespace

extern "C" {

int armcli_abi_version() { return 1; }

// ref: rows of [q_ref(n), v_ref(n)] at t = k*dt (Euler, steps+1 rows) or k*dt/2 (RK4,
// 2*steps+1 rows). Outputs per batch item b: q/v (steps+1)*n, tau steps*n, flags steps*n
// (bit 0 saturated, bit 1 joint-stop constraint active). Returns 0.
int armcli_rollout(int n, const int* jtype, const int* parent, const double* placement,
                   const double* axis, const double* inertia, const double* gravity,
                   const double* params, int gravity_comp, double dt, int integrator,
                   long steps, int batch, double energy_max, const double* q0,
                   const double* v0, const double* ref, double* q_out, double* v_out,
                   double* tau_out, unsigned char* flags_out, long* fail_step,
                   int* fail_joint, int* fail_code) {
  pin::Model model = build_model(n, jtype, parent, placement, axis, inertia, gravity);
  const int nr = 2 * n;  // one reference row
  for (int b = 0; b < batch; ++b) {
    Stepper s(model, params, gravity_comp != 0, dt);
    model.armature.setZero();
    Vec q = Eigen::Map<const Vec>(q0 + b * n, n), v = Eigen::Map<const Vec>(v0 + b * n, n);
    Vec qn(n), vn(n);
    double* Q = q_out + b * (steps + 1) * n;
    double* V = v_out + b * (steps + 1) * n;
    double* T = tau_out + b * steps * n;
    unsigned char* F = flags_out + b * steps * n;
    Eigen::Map<Vec>(Q, n) = q;
    Eigen::Map<Vec>(V, n) = v;
    fail_step[b] = -1;
    fail_joint[b] = -1;
    fail_code[b] = FAIL_NONE;
    for (long k = 0; k < steps; ++k) {
      if (integrator == 0) {
        s.euler(q, v, ref + k * nr, ref + k * nr + n, qn, vn, T + k * n);
      } else {
        const double* r0 = ref + 2 * k * nr;
        s.rk4(q, v, r0, r0 + nr, r0 + 2 * nr, n, qn, vn, T + k * n);
      }
      for (int i = 0; i < n; ++i) {
        const bool stop = std::isfinite(s.lo[i]) || std::isfinite(s.hi[i]);
        F[k * n + i] = (s.sat[i] ? 1 : 0) | (stop ? 2 : 0);
      }
      q = qn;
      v = vn;
      Eigen::Map<Vec>(Q + (k + 1) * n, n) = q;
      Eigen::Map<Vec>(V + (k + 1) * n, n) = v;
      int code = FAIL_NONE, joint = -1;
      for (int i = 0; i < n && code == FAIL_NONE; ++i) {
        if (!std::isfinite(q[i]) || !std::isfinite(v[i])) code = FAIL_NONFINITE, joint = i;
        else if (std::fabs(v[i]) > s.p(i, VABORT)) code = FAIL_VELOCITY, joint = i;
      }
      if (code == FAIL_NONE && (k + 1) % ENERGY_EVERY == 0) {
        model.armature.setZero();
        const double ke = pin::computeKineticEnergy(model, s.data, q, v);
        if (!(ke <= energy_max)) code = FAIL_ENERGY;
      }
      if (code != FAIL_NONE) {
        fail_step[b] = k + 1;
        fail_joint[b] = joint;
        fail_code[b] = code;
        break;
      }
    }
  }
  return 0;
}
}
