// armcli.sim._rollout: the simulator's dynamics, defined once.
//
// One step at state (q, v), reference (q_ref, v_ref) at the step's start:
//
// 1. motor torque tau = Kp (q_ref - q) + Kd (v_ref - v) [+ g(q)], saturated at the effort limit;
// 2. velocity-proportional torques (Kd of unsaturated joints, viscous damping D) are implicit
//    in semi-implicit Euler: (M + dt B)(v* - v)/dt = tau_explicit - B v - nle, B = diag(Kd + D).
//    ABA adds `model.armature` to the diagonal of M, so armature = dt B gives exactly this and
//    the step is stable for any non-negative Kd and D;
// 3. Coulomb friction and joint stops are solved at velocity level, like MuJoCo's frictionloss
//    and limit constraints: v' = argmin 1/2 |v' - v*|^2_(M + dt B) + dt sum F_i |v'_i| subject to
//    the stop bounds, by projected Gauss-Seidel. A joint at rest under a small torque stays
//    exactly at rest, and since v' = 0 is feasible the projection never adds kinetic energy;
// 4. the motor torque over the whole step, tau - Kd (v' - v), respects the effort limit too: a
//    joint whose implicit Kd would push it past the limit is saturated and the step solved
//    again, so the reported torque is the applied one;
// 5. q' = q + dt v', clamped to the limits against round-off.
//
// Semi-implicit Euler is first order. It is symplectic only where the mass matrix is constant
// (one joint, parallel prismatic axes); on a multi-link arm the Coriolis and centrifugal terms
// are taken at the step's start, and a free swing's energy drifts slowly (docs: simulate.py).
//
// RK4 integrates the smooth part (PD, gravity, damping) explicitly with the classic four
// stages, then applies the same projection. The reference is a piecewise polynomial: a step
// that contains a trajectory knot is split there, each part integrated on its own piece, so a
// knot between grid points does not cost the method its order. A knot where the reference
// velocity or acceleration jumps (and the start of the run) kicks the fast closed-loop modes,
// which a single RK4 step at the controller's dt resolves poorly; from there the steps are
// integrated with step-doubling error control (RK4_TOL) until a whole step passes unrefined.
//
// A continuous joint's state is its angle, unbounded; Pinocchio's configuration holds
// (cos, sin) of it. Such joints have infinite limits, hence no stops.
//
// Python hands over the pinocchio.Model serialised by Pinocchio (the model itself, bit for
// bit), the per-joint parameters by name and the reference as its polynomial pieces; it gets
// back the states at the steps it asked for and running tracking statistics, so memory does
// not grow with the number of steps. `Rollout.advance` releases the GIL: rollouts run on
// threads in parallel.
//
// Built at install time by scikit-build-core (CMakeLists.txt) against the Pinocchio of the
// `pin` wheel, using its explicit template instantiations so compiling takes seconds.

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <boost/archive/binary_iarchive.hpp>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/energy.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody/data.hpp"
#include "pinocchio/multibody/model.hpp"
#include "pinocchio/serialization/model.hpp"

#ifndef ARMCLI_SOURCE_SHA256
#define ARMCLI_SOURCE_SHA256 ""
#endif

namespace nb = nanobind;
namespace pin = pinocchio;
using Vec = Eigen::VectorXd;
using CRef = Eigen::Ref<const Vec>;
using Doubles = std::vector<double>;

namespace {

enum { FAIL_NONE = 0, FAIL_NONFINITE = 1, FAIL_VELOCITY = 2, FAIL_ENERGY = 3 };
constexpr int PGS_MAX_ITERS = 200;
constexpr double PGS_TOL = 1e-14;
constexpr long ENERGY_EVERY = 100;  // steps between kinetic-energy checks
constexpr double INF = std::numeric_limits<double>::infinity();
constexpr double REST_POS = 1e-12;  // relative: a joint this close to a stop is on it
constexpr double REST_VEL = 1e-9;   // [rad/s or m/s] and not moving away faster: resting on it
constexpr double KNOT_SNAP = 1e-9;  // relative to dt: a knot this close to a step boundary is on it
constexpr double RK4_TOL = 1e-9;    // [rad or m] RK4 step-doubling tolerance after a kick
constexpr int RK4_MAX_DEPTH = 8;    // at most 2^8 sub-steps per step

template <typename T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;

Doubles vec(const In<double>& a, size_t n, const char* what) {
  if (a.size() != n) throw std::invalid_argument(std::string(what) + ": wrong length");
  return Doubles(a.data(), a.data() + n);
}

// The pinocchio.Model Python serialised with Model.saveToBinary: the same model, exactly.
struct Model {
  pin::Model model;
};

Model load_model(nb::bytes data) {
  Model m;
  std::stringbuf buf(std::string(data.c_str(), data.size()));
  boost::archive::binary_iarchive archive(buf);
  archive >> m.model;
  for (pin::JointIndex j = 1; j < static_cast<pin::JointIndex>(m.model.njoints); ++j) {
    const int nq = m.model.nqs[j], nv = m.model.nvs[j];
    if (nv != 1 || (nq != 1 && nq != 2))
      throw std::invalid_argument("joint " + m.model.names[j] +
                                  ": only one-degree-of-freedom joints can be simulated");
  }
  return m;
}

// Per-joint parameters and settings of one closed loop.
struct Plant {
  pin::Model model;
  int n = 0;
  Doubles kp, kd, damping, friction, lower, upper, effort, vabort;
  bool gc = false, rk4 = false;
  double dt = 0.0, energy_max = INF;
};

// q_ref(t), v_ref(t): quintic pieces in local time; after the last knot the final position.
struct Reference {
  int n = 0, S = 0;         // joints, pieces
  Doubles knots, c, fin;    // c[(s * 6 + k) * n + i]: coefficient k of piece s, joint i
  std::vector<char> jump;   // jump[s]: v_ref or its derivative is discontinuous at knots[s]

  // The piece holding t (right-continuous, as numpy's searchsorted(side="right") - 1);
  // S after the last knot.
  int piece(double t) const {
    if (S == 0 || !(t < knots[S])) return S;
    const long s = std::upper_bound(knots.begin(), knots.end(), t) - knots.begin() - 1;
    return static_cast<int>(std::max(0L, s));
  }

  void eval(int s, double t, double* q, double* v) const {
    if (s >= S) {
      for (int i = 0; i < n; ++i) q[i] = fin[i], v[i] = 0.0;
      return;
    }
    const double tau = t - knots[s];
    const double* cc = c.data() + static_cast<size_t>(s) * 6 * n;
    for (int i = 0; i < n; ++i) {
      double qi = cc[5 * n + i], vi = 5.0 * cc[5 * n + i];
      for (int k = 4; k >= 0; --k) {
        qi = qi * tau + cc[k * n + i];
        if (k >= 1) vi = vi * tau + k * cc[k * n + i];
      }
      q[i] = qi, v[i] = vi;
    }
  }

  // d v_ref / dt on piece s at t (zero after the last knot).
  void accel(int s, double t, double* a) const {
    if (s >= S) {
      for (int i = 0; i < n; ++i) a[i] = 0.0;
      return;
    }
    const double tau = t - knots[s];
    const double* cc = c.data() + static_cast<size_t>(s) * 6 * n;
    for (int i = 0; i < n; ++i) {
      double ai = 20.0 * cc[5 * n + i];
      for (int k = 4; k >= 2; --k) ai = ai * tau + k * (k - 1) * cc[k * n + i];
      a[i] = ai;
    }
  }
};

Reference make_reference(In<double> knots, In<double> coeffs, In<double> fin) {
  Reference r;
  r.n = static_cast<int>(fin.size());
  r.S = static_cast<int>(knots.size()) - 1;
  if (r.S < 0 || coeffs.size() != static_cast<size_t>(r.S) * 6 * r.n)
    throw std::invalid_argument("reference: knots, coefficients and final position disagree");
  r.knots = Doubles(knots.data(), knots.data() + knots.size());
  r.c = Doubles(coeffs.data(), coeffs.data() + coeffs.size());
  r.fin = Doubles(fin.data(), fin.data() + fin.size());
  r.jump.assign(r.S + 1, 0);
  // the PD torque has a kink (v_ref jumps) or a corner in its rate (a_ref jumps) there
  Doubles ql(r.n), vl(r.n), al(r.n), qr(r.n), vr(r.n), ar(r.n);
  auto differ = [](double x, double y) { return std::fabs(x - y) > 1e-12 * (1.0 + std::fabs(y)); };
  for (int s = 1; s <= r.S; ++s) {
    r.eval(s - 1, r.knots[s], ql.data(), vl.data());
    r.eval(s, r.knots[s], qr.data(), vr.data());
    r.accel(s - 1, r.knots[s], al.data());
    r.accel(s, r.knots[s], ar.data());
    for (int i = 0; i < r.n; ++i)
      if (differ(vl[i], vr[i]) || differ(al[i], ar[i])) r.jump[s] = 1;
  }
  return r;
}

struct Stepper {
  pin::Model model;  // own copy: the armature (implicit gains) changes during the run
  pin::Data data;
  const Plant& P;
  int n;
  double dt;
  bool any_friction = false;
  Vec qa, va, ta;
  Eigen::MatrixXd A, Ah;
  Doubles tau, lo, hi, fdt, lam, dv, tpd, ab, vs, qp;  // ab, vs, qp: step scratch
  std::vector<char> sat, stop;
  std::vector<int> locked;  // RK4: joints held by their stops during the stages
  Doubles force;            // their stop forces (M^-1 units), for the sign test
  std::vector<char> arm_key;  // saturation pattern of the current armature; empty: zero
  bool arm_set = false;
  std::vector<int> iq;          // each joint's first index in Pinocchio's configuration
  std::vector<char> unbounded;  // continuous joint: configuration (cos, sin) of its angle

  explicit Stepper(const Plant& plant)
      : model(plant.model), data(plant.model), P(plant), n(plant.n), dt(plant.dt),
        qa(plant.model.nq), va(n), ta(n), A(n, n), Ah(n, n), tau(n), lo(n), hi(n), fdt(n),
        lam(n), dv(n), tpd(n), ab(n), vs(n), qp(n), sat(n), stop(n), iq(n), unbounded(n) {
    for (int i = 0; i < n; ++i) {
      any_friction = any_friction || P.friction[i] > 0.0;
      fdt[i] = dt * P.friction[i];
      iq[i] = model.idx_qs[i + 1];
      unbounded[i] = model.nqs[i + 1] == 2;
    }
    set_armature(nullptr);
  }

  // Pinocchio's configuration of the joint angles/positions q.
  void setq(const double* q) {
    for (int i = 0; i < n; ++i) {
      if (unbounded[i]) qa[iq[i]] = std::cos(q[i]), qa[iq[i] + 1] = std::sin(q[i]);
      else qa[iq[i]] = q[i];
    }
  }

  // Implicit velocity gains of the Euler step: dt (D + Kd) on unsaturated joints; none: zero.
  void set_armature(const std::vector<char>* s) {
    std::vector<char> key = s ? *s : std::vector<char>();
    if (arm_set && key == arm_key) return;
    for (int i = 0; i < n; ++i)
      model.armature[i] = s ? dt * (P.damping[i] + ((*s)[i] ? 0.0 : P.kd[i])) : 0.0;
    arm_key = key;
    arm_set = true;
  }

  // The WORLD convention leaves the factorisation that computeMinverse(model, data) reuses.
  const Vec& aba(const double* q, const double* v, const double* t) {
    setq(q);
    for (int i = 0; i < n; ++i) va[i] = v[i], ta[i] = t[i];
    return pin::aba(model, data, CRef(qa), CRef(va), CRef(ta), pin::Convention::WORLD);
  }

  double kinetic_energy(const double* q, const double* v) {
    set_armature(nullptr);  // the arm alone
    setq(q);
    for (int i = 0; i < n; ++i) va[i] = v[i];
    return pin::computeKineticEnergy(model, data, CRef(qa), CRef(va));
  }

  // PD(+gravity) torque, saturated; sets sat.
  void motor(const double* q, const double* v, const double* qr, const double* vr, double* out) {
    for (int i = 0; i < n; ++i) out[i] = P.kp[i] * (qr[i] - q[i]) + P.kd[i] * (vr[i] - v[i]);
    if (P.gc) {
      setq(q);
      const Vec& g = pin::computeGeneralizedGravity(model, data, CRef(qa));
      for (int i = 0; i < n; ++i) out[i] = out[i] + g[i];
    }
    for (int i = 0; i < n; ++i) {
      sat[i] = std::fabs(out[i]) > P.effort[i];
      if (sat[i]) out[i] = std::copysign(P.effort[i], out[i]);
    }
  }

  // Projected Gauss-Seidel on the friction/stop problem, warm-started from the previous
  // solve's impulses (lam persists across steps): a sticking joint converges in one sweep.
  void pgs(const double* vs) {
    for (int it = 0; it < PGS_MAX_ITERS; ++it) {
      double change = 0.0, scale = 0.0;
      for (int i = 0; i < n; ++i) {
        double w = vs[i];
        for (int j = 0; j < n; ++j) w += A(i, j) * lam[j];
        w -= A(i, i) * lam[i];
        const double thr = A(i, i) * fdt[i];
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
      double s = 0.0;
      for (int j = 0; j < n; ++j) s += A(i, j) * lam[j];
      dv[i] = s;
    }
  }

  // Friction and joint stops at velocity level. A joint whose predicted position qp passes
  // a stop gets the bound v' <= (upper - q)/dt (>= lower alike) and the position q + dt v':
  // it ends on the stop with no velocity into it. Other joints move by pos_gain dt dv: the
  // whole impulse for Euler, half of it for RK4, whose positions already integrate the
  // acceleration over the step (a constant constraint force moves a joint by dt dv / 2).
  // `after_aba`: the last ABA was at q with the current armature, so M^-1 comes from its
  // factorisation instead of a pass of its own.
  void project(const double* q, const double* vs, const double* qp, double pos_gain, double* qn,
               double* vn, bool after_aba) {
    bool any = any_friction;
    for (int i = 0; i < n; ++i) {
      lo[i] = -INF, hi[i] = INF;
      if (qp[i] > P.upper[i]) hi[i] = (P.upper[i] - q[i]) / dt;
      else if (qp[i] < P.lower[i]) lo[i] = (P.lower[i] - q[i]) / dt;
      stop[i] = hi[i] < INF || lo[i] > -INF;
      any = any || stop[i];
    }
    if (!any) {
      for (int i = 0; i < n; ++i) qn[i] = qp[i], vn[i] = vs[i];
      return;
    }
    if (after_aba) {
      A = pin::computeMinverse(model, data);
    } else {
      setq(q);
      A = pin::computeMinverse(model, data, CRef(qa));
    }
    A.triangularView<Eigen::StrictlyLower>() = A.transpose();
    pgs(vs);
    for (int i = 0; i < n; ++i) {
      vn[i] = vs[i] + dv[i];
      qn[i] = stop[i] ? q[i] + dt * vn[i] : qp[i] + pos_gain * dt * dv[i];
    }
  }

  void clamp(double* q) const {
    for (int i = 0; i < n; ++i) q[i] = std::min(std::max(q[i], P.lower[i]), P.upper[i]);
  }

  // Semi-implicit Euler; a joint whose whole-step motor torque would exceed its limit is
  // saturated and the step solved again.
  void euler(const double* q, const double* v, const double* qr, const double* vr, double* qn,
             double* vn) {
    motor(q, v, qr, vr, tpd.data());
    while (true) {
      set_armature(&sat);
      for (int i = 0; i < n; ++i) ab[i] = tpd[i] - P.damping[i] * v[i];
      const Vec& a = aba(q, v, ab.data());
      for (int i = 0; i < n; ++i) vs[i] = v[i] + dt * a[i];
      for (int i = 0; i < n; ++i) qp[i] = q[i] + dt * vs[i];
      project(q, vs.data(), qp.data(), 1.0, qn, vn, true);
      bool over = false;
      for (int i = 0; i < n; ++i) tau[i] = sat[i] ? tpd[i] : tpd[i] - P.kd[i] * (vn[i] - v[i]);
      for (int i = 0; i < n; ++i) {
        if (!sat[i] && std::fabs(tau[i]) > P.effort[i]) {
          over = true;
          sat[i] = 1;
          tpd[i] = std::copysign(P.effort[i], tau[i]);
        }
      }
      if (!over) break;
    }
    clamp(qn);
  }

  // Explicit acceleration under the saturated motor torque t (RK4 stages); joints in
  // `locked` are held (zero acceleration) by their stops.
  void accel(const double* q, const double* v, const double* qr, const double* vr, double* t,
             double* a) {
    motor(q, v, qr, vr, t);
    for (int i = 0; i < n; ++i) ab[i] = t[i] - P.damping[i] * v[i];
    const Vec& acc = aba(q, v, ab.data());
    for (int i = 0; i < n; ++i) a[i] = acc[i];
    if (!locked.empty()) hold(q, a);
  }

  // a + A[:, S] x with A[S, S] x = -a[S] (A = M^-1): exactly the constrained dynamics.
  void hold(const double* q, double* a) {
    const size_t m = locked.size();
    setq(q);
    Ah = pin::computeMinverse(model, data, CRef(qa));
    auto Au = [&](int i, int j) { return Ah(std::min(i, j), std::max(i, j)); };
    Doubles As(m * m), b(m);
    for (size_t i = 0; i < m; ++i) {
      for (size_t j = 0; j < m; ++j) As[i * m + j] = Au(locked[i], locked[j]);
      b[i] = -a[locked[i]];
    }
    force = solve_spd(As, b, m);
    for (int i = 0; i < n; ++i) {
      double acc = a[i];
      for (size_t jj = 0; jj < m; ++jj) acc += Au(i, locked[jj]) * force[jj];
      a[i] = acc;
    }
    for (int i : locked) a[i] = 0.0;
  }

  // Cholesky solve of a small symmetric positive definite system.
  static Doubles solve_spd(const Doubles& A, const Doubles& b, size_t n) {
    Doubles L(n * n, 0.0), y(n, 0.0), x(n, 0.0);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j <= i; ++j) {
        double s = A[i * n + j];
        for (size_t k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
        L[i * n + j] = i == j ? std::sqrt(s) : s / L[j * n + j];
      }
    for (size_t i = 0; i < n; ++i) {
      double s = b[i];
      for (size_t k = 0; k < i; ++k) s -= L[i * n + k] * y[k];
      y[i] = s / L[i * n + i];
    }
    for (size_t i = n; i-- > 0;) {
      double s = y[i];
      for (size_t k = i + 1; k < n; ++k) s -= L[k * n + i] * x[k];
      x[i] = s / L[i * n + i];
    }
    return x;
  }

  // Joints resting on a stop and pressed into it: at the stop (to round-off), not moving
  // away, with the stop force pushing back (found by dropping any joint it would pull).
  void resting(const double* q, const double* v, const double* qr, const double* vr) {
    Doubles side(n, 0.0), a(n), t(n);
    bool any = false;
    for (int i = 0; i < n; ++i) {
      const double up = P.upper[i], dn = P.lower[i];
      if (std::isfinite(up) && q[i] >= up - REST_POS * (1.0 + std::fabs(up)) && v[i] >= -REST_VEL)
        side[i] = 1.0;
      else if (std::isfinite(dn) && q[i] <= dn + REST_POS * (1.0 + std::fabs(dn)) &&
               v[i] <= REST_VEL)
        side[i] = -1.0;
      any = any || side[i] != 0.0;
    }
    locked.clear();
    if (!any) return;
    accel(q, v, qr, vr, t.data(), a.data());
    for (int i = 0; i < n; ++i)
      if (side[i] * a[i] > 0.0) locked.push_back(i);
    while (!locked.empty()) {
      accel(q, v, qr, vr, t.data(), a.data());
      std::vector<int> keep;
      for (size_t k = 0; k < locked.size(); ++k)
        if (side[locked[k]] * force[k] <= 0.0) keep.push_back(locked[k]);
      if (keep.size() == locked.size()) break;
      locked = keep;
    }
  }
};

// The smooth dynamics' RK4 over [a, a + h] on one reference piece, in place on (q, v).
struct Rk4 {
  Stepper& st;
  const Reference& ref;
  int n;
  Doubles k1v, k2v, k3v, k4v, k2q, k3q, k4q, qs, t, r;

  Rk4(Stepper& s, const Reference& rf)
      : st(s), ref(rf), n(s.n), k1v(n), k2v(n), k3v(n), k4v(n), k2q(n), k3q(n), k4q(n), qs(n),
        t(n), r(2 * n) {}

  // `k1` (the first stage, when already evaluated at (q, v, a)) may be null.
  void step(double* q, double* v, double a, double h, int piece, const double* k1) {
    const double h2 = 0.5 * h, h6 = h / 6.0;
    if (k1) std::copy(k1, k1 + n, k1v.begin());
    else stage(q, v, a, piece, k1v.data());
    for (int i = 0; i < n; ++i) k2q[i] = v[i] + h2 * k1v[i], qs[i] = q[i] + h2 * v[i];
    stage(qs.data(), k2q.data(), a + h2, piece, k2v.data());
    for (int i = 0; i < n; ++i) k3q[i] = v[i] + h2 * k2v[i], qs[i] = q[i] + h2 * k2q[i];
    stage(qs.data(), k3q.data(), a + h2, piece, k3v.data());
    for (int i = 0; i < n; ++i) k4q[i] = v[i] + h * k3v[i], qs[i] = q[i] + h * k3q[i];
    stage(qs.data(), k4q.data(), a + h, piece, k4v.data());
    for (int i = 0; i < n; ++i) {
      const double vi = v[i];
      v[i] = vi + h6 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
      q[i] = q[i] + h6 * (vi + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i]);
    }
  }

  void stage(const double* q, const double* v, double time, int piece, double* acc) {
    ref.eval(piece, time, r.data(), r.data() + n);
    st.accel(q, v, r.data(), r.data() + n, t.data(), acc);
  }

  // RK4 with step doubling: the two half steps are kept when they agree with the whole
  // step to RK4_TOL, else each half is refined the same way. True: passed unrefined.
  bool controlled(double* q, double* v, double a, double b, int piece, const double* k1,
                  int depth) {
    const double h = b - a;
    Doubles q1(q, q + n), v1(v, v + n), q2(q, q + n), v2(v, v + n);
    step(q1.data(), v1.data(), a, h, piece, k1);
    step(q2.data(), v2.data(), a, 0.5 * h, piece, k1);
    step(q2.data(), v2.data(), a + 0.5 * h, 0.5 * h, piece, nullptr);
    double err = 0.0;
    for (int i = 0; i < n; ++i)
      err = std::max(err, std::max(std::fabs(q2[i] - q1[i]), h * std::fabs(v2[i] - v1[i])));
    if (err <= RK4_TOL || depth >= RK4_MAX_DEPTH) {
      std::copy(q2.begin(), q2.end(), q), std::copy(v2.begin(), v2.end(), v);
      return err <= RK4_TOL && depth == 0;
    }
    controlled(q, v, a, a + 0.5 * h, piece, k1, depth + 1);
    controlled(q, v, a + 0.5 * h, b, piece, nullptr, depth + 1);
    return false;
  }
};

struct Outcome {
  long fail_step = -1;
  int fail_joint = -1;
  int fail_code = FAIL_NONE;
};

// One closed-loop run, advanced in chunks; records the states at the requested steps and
// running tracking statistics over every state.
struct Rollout {
  Plant plant;
  Reference ref;
  Stepper st;
  Rk4 rk;
  int n;
  long N, k = 0;
  Doubles q, v, qn, vn, qr, vr, k1, t1;
  std::vector<char> sat1;
  bool control = true;  // RK4 error control: on from the start and after a kick
  size_t kc = 0;        // first knot not yet handled
  // requested states: row j holds step rec[j]
  std::vector<int64_t> rec;
  size_t ri = 0;
  long pending = -1;  // the row waiting for its step's torque and flags
  Doubles Q, V, QR, VR, T;
  std::vector<uint8_t> SAT, STOP;
  // statistics: squared-error sum, max |error|, last state outside the settle band
  double settle_tol;
  Doubles sum_e2, max_e, last_e;
  std::vector<int64_t> last_out, nsat, rises;
  std::vector<char> prev_stop;
  bool finished = false;
  Outcome out;

  Rollout(const Plant& p, const Reference& r, const Doubles& q0, const Doubles& v0, long steps,
          std::vector<int64_t> record, double tol)
      : plant(p), ref(r), st(plant), rk(st, ref), n(p.n), N(steps), q(q0), v(v0), qn(n), vn(n),
        qr(n), vr(n), k1(n), t1(n), sat1(n), rec(std::move(record)), settle_tol(tol),
        sum_e2(n), max_e(n), last_e(n), last_out(n, -1), nsat(n), rises(n), prev_stop(n) {
    const size_t K = rec.size();
    Q.assign(K * n, NAN), V.assign(K * n, NAN), QR.assign(K * n, NAN), VR.assign(K * n, NAN);
    T.assign(K * n, NAN), SAT.assign(K * n, 0), STOP.assign(K * n, 0);
  }

  // The state at step k: statistics, and a record row when one is requested.
  void observe() {
    const double t = k * plant.dt;
    ref.eval(ref.piece(t), t, qr.data(), vr.data());
    for (int i = 0; i < n; ++i) {
      const double e = q[i] - qr[i];
      sum_e2[i] += e * e;
      max_e[i] = std::max(max_e[i], std::fabs(e));
      last_e[i] = e;
      if (std::fabs(e) > settle_tol) last_out[i] = k;
    }
    if (ri < rec.size() && rec[ri] == k) {
      const size_t o = ri * n;
      for (int i = 0; i < n; ++i) Q[o + i] = q[i], V[o + i] = v[i], QR[o + i] = qr[i], VR[o + i] = vr[i];
      // the final state has no step after it: it reports the last step's torque and flags
      if (k == N && k > 0) fill(ri);
      else pending = static_cast<long>(ri);
      ++ri;
    }
  }

  // The torque applied and the flags of the step just taken, into record row `row`.
  void fill(size_t row) {
    const size_t o = row * n;
    for (int i = 0; i < n; ++i) T[o + i] = st.tau[i], SAT[o + i] = st.sat[i], STOP[o + i] = st.stop[i];
  }

  void rk4_step() {
    const double dt = plant.dt, t = k * dt, end = t + dt, eps = KNOT_SNAP * dt;
    st.set_armature(nullptr);
    // the step's parts: cut at knots strictly inside it; a kick at a cut turns control on
    Doubles cuts{t};
    std::vector<char> kick{0};
    while (kc < ref.knots.size() && ref.knots[kc] < end - eps) {
      const double knot = ref.knots[kc];
      if (knot > t + eps) cuts.push_back(knot), kick.push_back(ref.jump[kc]);
      else if (knot >= t - eps && ref.jump[kc]) kick[0] = 1;
      ++kc;
    }
    cuts.push_back(end);
    const int first = ref.piece(0.5 * (cuts[0] + cuts[1]));
    ref.eval(first, t, qr.data(), vr.data());
    st.resting(q.data(), v.data(), qr.data(), vr.data());
    const std::vector<int> held = st.locked;
    st.accel(q.data(), v.data(), qr.data(), vr.data(), t1.data(), k1.data());
    sat1 = st.sat;  // stage-1 flags and torque are the ones reported
    Doubles yq(q), yv(v);
    const size_t parts = cuts.size() - 1;
    for (size_t j = 0; j < parts; ++j) {
      const double a = cuts[j], b = cuts[j + 1];
      const int piece = j == 0 ? first : ref.piece(0.5 * (a + b));
      const double* kk = j == 0 ? k1.data() : nullptr;
      control = control || kick[j];
      if (!control) {
        rk.step(yq.data(), yv.data(), a, b - a, piece, kk);
        continue;
      }
      const bool passed = rk.controlled(yq.data(), yv.data(), a, b, piece, kk, 0);
      if (passed && parts == 1) control = false;  // a whole step passed: the kick is over
    }
    st.sat = sat1;
    std::copy(t1.begin(), t1.end(), st.tau.begin());
    st.locked.clear();
    st.project(q.data(), yv.data(), yq.data(), 0.5, qn.data(), vn.data(), false);
    for (int i : held) st.stop[i] = 1;
    st.clamp(qn.data());
  }

  // Advance by at most `steps` steps (fewer at the end or on failure).
  void run(long steps) {
    const long stop_at = std::min(N, k + steps);
    while (k < stop_at && out.fail_code == FAIL_NONE) {
      observe();
      if (plant.rk4) rk4_step();
      else st.euler(q.data(), v.data(), qr.data(), vr.data(), qn.data(), vn.data());
      if (pending >= 0) fill(static_cast<size_t>(pending)), pending = -1;
      for (int i = 0; i < n; ++i) {
        nsat[i] += st.sat[i] ? 1 : 0;
        rises[i] += (st.stop[i] && !prev_stop[i]) ? 1 : 0;
        prev_stop[i] = st.stop[i];
      }
      q.swap(qn), v.swap(vn);
      ++k;
      check();
    }
    if (k == N && !finished && out.fail_code == FAIL_NONE) {
      finished = true;
      observe();
    }
  }

  void check() {
    int code = FAIL_NONE, joint = -1;
    for (int i = 0; i < n && code == FAIL_NONE; ++i) {
      if (!std::isfinite(q[i]) || !std::isfinite(v[i])) code = FAIL_NONFINITE, joint = i;
      else if (std::fabs(v[i]) > plant.vabort[i]) code = FAIL_VELOCITY, joint = i;
    }
    if (code == FAIL_NONE && k % ENERGY_EVERY == 0 &&
        !(st.kinetic_energy(q.data(), v.data()) <= plant.energy_max))
      code = FAIL_ENERGY;
    if (code != FAIL_NONE) out.fail_step = k, out.fail_joint = joint, out.fail_code = code;
  }
};

// -- Python interface ------------------------------------------------------------------------

Plant make_plant(const Model& m, In<double> kp, In<double> kd, In<double> damping,
                 In<double> friction, In<double> lower, In<double> upper, In<double> effort,
                 In<double> vabort, bool gravity_comp, double dt, const std::string& integrator,
                 double energy_max) {
  Plant p;
  p.model = m.model;
  const size_t n = static_cast<size_t>(m.model.nv);
  p.n = static_cast<int>(n);
  p.kp = vec(kp, n, "kp"), p.kd = vec(kd, n, "kd"), p.damping = vec(damping, n, "damping");
  p.friction = vec(friction, n, "friction"), p.lower = vec(lower, n, "lower");
  p.upper = vec(upper, n, "upper"), p.effort = vec(effort, n, "effort");
  p.vabort = vec(vabort, n, "vabort");
  p.rk4 = integrator == "rk4";
  if (!p.rk4 && integrator != "euler") throw std::invalid_argument("integrator: euler or rk4");
  if (!(dt > 0.0)) throw std::invalid_argument("dt must be > 0");
  p.gc = gravity_comp, p.dt = dt, p.energy_max = energy_max;
  return p;
}

template <typename T>
nb::ndarray<nb::numpy, T> array(const std::vector<T>& data, size_t rows, size_t cols) {
  auto* copy = new std::vector<T>(data);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(copy->data(), {rows, cols}, owner);
}

template <typename T>
nb::ndarray<nb::numpy, T> vector1(const std::vector<T>& data) {
  auto* copy = new std::vector<T>(data);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(copy->data(), {data.size()}, owner);
}

Rollout* make_rollout(const Plant& plant, const Reference& ref, In<double> q0, In<double> v0,
                      long steps, In<int64_t> record, double settle_tol) {
  const size_t n = static_cast<size_t>(plant.n);
  if (ref.n != plant.n) throw std::invalid_argument("reference: wrong number of joints");
  if (steps < 0) throw std::invalid_argument("steps must be >= 0");
  std::vector<int64_t> rec(record.data(), record.data() + record.size());
  for (size_t j = 0; j < rec.size(); ++j)
    if (rec[j] < 0 || rec[j] > steps || (j > 0 && rec[j] <= rec[j - 1]))
      throw std::invalid_argument("record: steps must increase strictly within [0, steps]");
  return new Rollout(plant, ref, vec(q0, n, "q0"), vec(v0, n, "v0"), steps, std::move(rec),
                     settle_tol);
}

nb::tuple advance(Rollout& r, long steps) {
  {
    nb::gil_scoped_release release;
    r.run(steps);
  }
  return nb::make_tuple(r.out.fail_step, r.out.fail_joint, r.out.fail_code);
}

nb::dict records(const Rollout& r) {
  const size_t K = r.rec.size(), n = static_cast<size_t>(r.n);
  nb::dict d;
  d["step"] = vector1(r.rec);
  d["q"] = array(r.Q, K, n), d["v"] = array(r.V, K, n);
  d["q_ref"] = array(r.QR, K, n), d["v_ref"] = array(r.VR, K, n);
  d["tau"] = array(r.T, K, n);
  d["saturated"] = array(r.SAT, K, n), d["stop"] = array(r.STOP, K, n);
  return d;
}

nb::dict statistics(const Rollout& r) {
  nb::dict d;
  d["states"] = r.finished ? r.N + 1 : r.k;
  d["steps"] = r.k;
  d["sum_e2"] = vector1(r.sum_e2), d["max_e"] = vector1(r.max_e), d["last_e"] = vector1(r.last_e);
  d["last_out"] = vector1(r.last_out), d["saturated_steps"] = vector1(r.nsat);
  d["stop_rises"] = vector1(r.rises);
  return d;
}

}  // namespace

NB_MODULE(_rollout, m) {
  m.doc() = "armcli's simulator: the step, compiled (see armcli.sim.native).";
  m.attr("SOURCE_SHA256") = ARMCLI_SOURCE_SHA256;
  m.attr("FAIL_NONE") = int(FAIL_NONE);
  m.attr("FAIL_NONFINITE") = int(FAIL_NONFINITE);
  m.attr("FAIL_VELOCITY") = int(FAIL_VELOCITY);
  m.attr("FAIL_ENERGY") = int(FAIL_ENERGY);
  nb::class_<Model>(m, "Model")
      .def_prop_ro("nv", [](const Model& x) { return x.model.nv; })
      .def_prop_ro("nq", [](const Model& x) { return x.model.nq; });
  m.def("load_model", &load_model, nb::arg("data"),
        "The pinocchio.Model serialised by Model.saveToBinary.");
  nb::class_<Plant>(m, "Plant");
  m.def("plant", &make_plant, nb::arg("model"), nb::kw_only(), nb::arg("kp"), nb::arg("kd"),
        nb::arg("damping"), nb::arg("friction"), nb::arg("lower"), nb::arg("upper"),
        nb::arg("effort"), nb::arg("vabort"), nb::arg("gravity_comp"), nb::arg("dt"),
        nb::arg("integrator"), nb::arg("energy_max"));
  nb::class_<Reference>(m, "Reference")
      .def("sample",
           [](const Reference& r, In<double> t) {
             const size_t T = t.size(), n = static_cast<size_t>(r.n);
             std::vector<double> q(T * n), v(T * n);
             for (size_t j = 0; j < T; ++j)
               r.eval(r.piece(t.data()[j]), t.data()[j], q.data() + j * n, v.data() + j * n);
             return nb::make_tuple(array(q, T, n), array(v, T, n));
           },
           nb::arg("t"), "q_ref, v_ref at times t (the piece holding each t).");
  m.def("reference", &make_reference, nb::arg("knots"), nb::arg("coeffs"), nb::arg("final"));
  nb::class_<Rollout>(m, "Rollout")
      .def_prop_ro("step", [](const Rollout& r) { return r.k; })
      .def_prop_ro("q", [](const Rollout& r) { return vector1(r.q); }, nb::rv_policy::automatic)
      .def_prop_ro("v", [](const Rollout& r) { return vector1(r.v); }, nb::rv_policy::automatic)
      .def("advance", &advance, nb::arg("steps"),
           "Run up to `steps` more steps without the GIL; (fail_step, fail_joint, fail_code).")
      .def("records", &records, "The requested states (copies).")
      .def("statistics", &statistics, "Running tracking statistics over every state.");
  m.def("rollout", &make_rollout, nb::arg("plant"), nb::arg("reference"), nb::arg("q0"),
        nb::arg("v0"), nb::arg("steps"), nb::arg("record"), nb::arg("settle_tol"),
        nb::rv_policy::take_ownership);
}
