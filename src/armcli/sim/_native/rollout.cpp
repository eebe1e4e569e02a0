// armcli.sim._rollout: the simulator's rollout compiled, the same step as armcli.sim.stepper.Stepper.
//
// Why: a Python step loop pays interpreter overhead around a sub-microsecond Pinocchio ABA
// call; running the whole loop here removes it, and releasing the GIL lets a batch of
// rollouts (gain sets, models) run on threads. The algorithm must stay identical to the
// Python reference (tests compare both to 1e-12): every floating-point operation is written
// in the same order, and the build disables FMA contraction. Any change to one is made to
// the other.
//
// Built at install time by scikit-build-core (CMakeLists.txt) against the Pinocchio of the
// `pin` wheel, using its explicit template instantiations (Eigen::Ref arguments) so that
// compiling takes seconds, not minutes.

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/energy.hpp"
#include "pinocchio/algorithm/rnea.hpp"
#include "pinocchio/multibody/data.hpp"
#include "pinocchio/multibody/model.hpp"

namespace nb = nanobind;
namespace pin = pinocchio;
using Vec = Eigen::VectorXd;
using CRef = Eigen::Ref<const Vec>;

namespace {

// Field order of the per-joint parameter rows; mirrors armcli.sim.stepper.PARAM_FIELDS.
enum { KP, KD, DAMPING, FRICTION, LOWER, UPPER, EFFORT, VABORT, NPARAM };
enum { FAIL_NONE = 0, FAIL_NONFINITE = 1, FAIL_VELOCITY = 2, FAIL_ENERGY = 3 };
enum { FLAG_SATURATED = 1, FLAG_STOP = 2 };
constexpr int PGS_MAX_ITERS = 200;
constexpr double PGS_TOL = 1e-14;
constexpr long ENERGY_EVERY = 100;
constexpr int RK4_ROWS = 3;
constexpr double INF = std::numeric_limits<double>::infinity();
constexpr int ABI_VERSION = 3;
constexpr double REST_POS = 1e-12;  // mirrors armcli.sim.stepper.REST_POS
constexpr double REST_VEL = 1e-9;

template <typename T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;
template <typename T>
using Out = nb::ndarray<T, nb::c_contig, nb::device::cpu>;

// A pinocchio::Model rebuilt from flat arrays (armcli.sim.native.model_arrays).
struct Plant {
  pin::Model model;
};

Plant build_model(In<int32_t> jtype, In<int32_t> parent, In<double> placement, In<double> axis,
                  In<double> inertia, In<double> gravity) {
  const size_t n = jtype.shape(0);
  if (parent.size() != n || placement.size() != 12 * n || axis.size() != 3 * n ||
      inertia.size() != 13 * n || gravity.size() != 3)
    throw std::invalid_argument("model arrays: inconsistent sizes");
  Plant p;
  pin::Model& model = p.model;
  for (size_t i = 0; i < n; ++i) {
    const double* P = placement.data() + 12 * i;
    Eigen::Matrix3d R;
    R << P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8];
    const pin::SE3 M(R, Eigen::Vector3d(P[9], P[10], P[11]));
    const double* a = axis.data() + 3 * i;
    const Eigen::Vector3d ax(a[0], a[1], a[2]);
    const int par = parent.data()[i];
    if (par < 0 || static_cast<size_t>(par) > i) throw std::invalid_argument("bad parent index");
    const std::string name = "j" + std::to_string(i);
    pin::JointIndex id = 0;
    switch (jtype.data()[i]) {
      case 0: id = model.addJoint(par, pin::JointModelRX(), M, name); break;
      case 1: id = model.addJoint(par, pin::JointModelRY(), M, name); break;
      case 2: id = model.addJoint(par, pin::JointModelRZ(), M, name); break;
      case 3: id = model.addJoint(par, pin::JointModelRevoluteUnaligned(ax), M, name); break;
      case 4: id = model.addJoint(par, pin::JointModelPX(), M, name); break;
      case 5: id = model.addJoint(par, pin::JointModelPY(), M, name); break;
      case 6: id = model.addJoint(par, pin::JointModelPZ(), M, name); break;
      case 7: id = model.addJoint(par, pin::JointModelPrismaticUnaligned(ax), M, name); break;
      case 8: id = model.addJoint(par, pin::JointModelRUBX(), M, name); break;
      case 9: id = model.addJoint(par, pin::JointModelRUBY(), M, name); break;
      case 10: id = model.addJoint(par, pin::JointModelRUBZ(), M, name); break;
      case 11: id = model.addJoint(par, pin::JointModelRevoluteUnboundedUnaligned(ax), M, name); break;
      default: throw std::invalid_argument("unknown joint type code");
    }
    const double* I = inertia.data() + 13 * i;  // mass, com[3], I[9] row-major
    Eigen::Matrix3d Ic;
    Ic << I[4], I[5], I[6], I[7], I[8], I[9], I[10], I[11], I[12];
    model.appendBodyToJoint(id, pin::Inertia(I[0], Eigen::Vector3d(I[1], I[2], I[3]), Ic));
  }
  const double* g = gravity.data();
  model.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
  return p;
}

struct Stepper {
  pin::Model model;  // own copy: the armature (implicit gains) changes during the run
  pin::Data data;
  int n;
  const double* prm;  // n x NPARAM
  bool gc;
  double dt;
  bool any_friction = false;
  Vec qa, va, ta;
  Eigen::MatrixXd A;
  std::vector<double> tau, lo, hi, fdt, lam, dv, tpd, t1;
  std::vector<char> sat, stop, sat1;
  std::vector<int> locked;     // RK4: joints held by their stops during the stages
  std::vector<double> force;   // their stop forces (M^-1 units), for the sign test
  Eigen::MatrixXd Ah;
  std::vector<char> arm_key;  // saturation pattern of the current armature; empty: zero
  bool arm_set = false;
  std::vector<int> iq;        // each joint's first index in Pinocchio's configuration
  std::vector<char> unbounded;  // continuous joint: configuration (cos, sin) of its angle

  Stepper(const pin::Model& m, const double* params, bool gravity_comp, double dt_)
      : model(m), data(m), n(m.nv), prm(params), gc(gravity_comp), dt(dt_), qa(m.nq), va(n),
        ta(n), A(n, n), Ah(n, n), tau(n), lo(n), hi(n), fdt(n), lam(n), dv(n), tpd(n), t1(n), sat(n),
        stop(n), sat1(n), iq(n), unbounded(n) {
    for (int i = 0; i < n; ++i) {
      any_friction = any_friction || p(i, FRICTION) > 0.0;
      fdt[i] = dt * p(i, FRICTION);
      iq[i] = model.idx_qs[i + 1];
      unbounded[i] = model.nqs[i + 1] == 2;
    }
    set_armature(nullptr);
  }

  // Pinocchio's configuration of the joint angles/positions q (cos, sin for a continuous joint).
  void setq(const double* q) {
    for (int i = 0; i < n; ++i) {
      if (unbounded[i]) qa[iq[i]] = std::cos(q[i]), qa[iq[i] + 1] = std::sin(q[i]);
      else qa[iq[i]] = q[i];
    }
  }

  double p(int i, int f) const { return prm[NPARAM * i + f]; }

  void set_armature(const std::vector<char>* s) {
    std::vector<char> key = s ? *s : std::vector<char>();
    if (arm_set && key == arm_key) return;
    for (int i = 0; i < n; ++i)
      model.armature[i] = s ? dt * (p(i, DAMPING) + ((*s)[i] ? 0.0 : p(i, KD))) : 0.0;
    arm_key = key;
    arm_set = true;
  }

  const Vec& aba(const double* q, const double* v, const double* t) {
    setq(q);
    for (int i = 0; i < n; ++i) va[i] = v[i], ta[i] = t[i];
    return pin::aba(model, data, CRef(qa), CRef(va), CRef(ta), pin::Convention::LOCAL);
  }

  // PD(+gravity) torque, saturated; sets sat.
  void motor(const double* q, const double* v, const double* qr, const double* vr, double* out) {
    for (int i = 0; i < n; ++i) out[i] = p(i, KP) * (qr[i] - q[i]) + p(i, KD) * (vr[i] - v[i]);
    if (gc) {
      setq(q);
      const Vec& g = pin::computeGeneralizedGravity(model, data, CRef(qa));
      for (int i = 0; i < n; ++i) out[i] = out[i] + g[i];
    }
    for (int i = 0; i < n; ++i) {
      const double e = p(i, EFFORT);
      sat[i] = std::fabs(out[i]) > e;
      if (sat[i]) out[i] = std::copysign(e, out[i]);
    }
  }

  // Warm-started from the previous solve's impulses (lam persists across steps), like
  // armcli.sim.stepper.pgs: a sticking joint converges in one sweep instead of ~30.
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

  // Friction and joint stops at velocity level (see armcli.sim.stepper.Stepper.project).
  void project(const double* q, const double* vs, const double* qp, double pos_gain, double* qn,
               double* vn) {
    bool any = any_friction;
    for (int i = 0; i < n; ++i) {
      lo[i] = -INF, hi[i] = INF;
      if (qp[i] > p(i, UPPER)) hi[i] = (p(i, UPPER) - q[i]) / dt;
      else if (qp[i] < p(i, LOWER)) lo[i] = (p(i, LOWER) - q[i]) / dt;
      stop[i] = hi[i] < INF || lo[i] > -INF;
      any = any || stop[i];
    }
    if (!any) {
      for (int i = 0; i < n; ++i) qn[i] = qp[i], vn[i] = vs[i];
      return;
    }
    setq(q);
    A = pin::computeMinverse(model, data, CRef(qa));
    A.triangularView<Eigen::StrictlyLower>() = A.transpose();
    pgs(vs);
    for (int i = 0; i < n; ++i) {
      vn[i] = vs[i] + dv[i];
      qn[i] = stop[i] ? q[i] + dt * vn[i] : qp[i] + pos_gain * dt * dv[i];
    }
  }

  void clamp(double* q) const {
    for (int i = 0; i < n; ++i) q[i] = std::min(std::max(q[i], p(i, LOWER)), p(i, UPPER));
  }

  // Semi-implicit Euler; a joint whose whole-step motor torque would exceed its limit is
  // saturated and the step solved again.
  void euler(const double* q, const double* v, const double* qr, const double* vr, double* qn,
             double* vn) {
    std::vector<double> ab(n), vs(n), qp(n);
    motor(q, v, qr, vr, tpd.data());
    while (true) {
      set_armature(&sat);
      for (int i = 0; i < n; ++i) ab[i] = tpd[i] - p(i, DAMPING) * v[i];
      const Vec& a = aba(q, v, ab.data());
      for (int i = 0; i < n; ++i) vs[i] = v[i] + dt * a[i];
      for (int i = 0; i < n; ++i) qp[i] = q[i] + dt * vs[i];
      project(q, vs.data(), qp.data(), 1.0, qn, vn);
      bool over = false;
      for (int i = 0; i < n; ++i) tau[i] = sat[i] ? tpd[i] : tpd[i] - p(i, KD) * (vn[i] - v[i]);
      for (int i = 0; i < n; ++i) {
        if (!sat[i] && std::fabs(tau[i]) > p(i, EFFORT)) {
          over = true;
          sat[i] = 1;
          tpd[i] = std::copysign(p(i, EFFORT), tau[i]);
        }
      }
      if (!over) break;
    }
    clamp(qn);
  }

  void accel(const double* q, const double* v, const double* r, double* t, double* a) {
    std::vector<double> ab(n);
    motor(q, v, r, r + n, t);
    for (int i = 0; i < n; ++i) ab[i] = t[i] - p(i, DAMPING) * v[i];
    const Vec& acc = aba(q, v, ab.data());
    for (int i = 0; i < n; ++i) a[i] = acc[i];
    if (!locked.empty()) hold(q, a);
  }

  // Cancel the locked joints' accelerations with stop forces (armcli.sim.stepper.Stepper.hold).
  void hold(const double* q, double* a) {
    const size_t m = locked.size();
    setq(q);
    Ah = pin::computeMinverse(model, data, CRef(qa));
    auto Au = [&](int i, int j) { return Ah(std::min(i, j), std::max(i, j)); };
    std::vector<double> As(m * m), b(m);
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

  static std::vector<double> solve_spd(const std::vector<double>& A, const std::vector<double>& b,
                                       size_t n) {
    std::vector<double> L(n * n, 0.0), y(n, 0.0), x(n, 0.0);
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

  // Joints resting on a stop and pressed into it (armcli.sim.stepper.Stepper.resting).
  std::vector<int> resting(const double* q, const double* v, const double* r) {
    std::vector<double> side(n, 0.0), a(n), t(n);
    bool any = false;
    for (int i = 0; i < n; ++i) {
      const double hi_ = p(i, UPPER), lo_ = p(i, LOWER);
      if (q[i] >= hi_ - REST_POS * (1.0 + std::fabs(hi_)) && v[i] >= -REST_VEL) side[i] = 1.0;
      else if (q[i] <= lo_ + REST_POS * (1.0 + std::fabs(lo_)) && v[i] <= REST_VEL) side[i] = -1.0;
      any = any || side[i] != 0.0;
    }
    locked.clear();
    if (!any) return locked;
    accel(q, v, r, t.data(), a.data());
    for (int i = 0; i < n; ++i)
      if (side[i] * a[i] > 0.0) locked.push_back(i);
    while (!locked.empty()) {
      accel(q, v, r, t.data(), a.data());
      std::vector<int> keep;
      for (size_t k = 0; k < locked.size(); ++k)
        if (side[locked[k]] * force[k] <= 0.0) keep.push_back(locked[k]);
      if (keep.size() == locked.size()) break;
      locked = keep;
    }
    return locked;
  }

  // Classic RK4 on the smooth dynamics, then the same friction/stop projection.
  void rk4(const double* q, const double* v, const double* r0, const double* r1,
           const double* r2, double* qn, double* vn) {
    const double h2 = 0.5 * dt, h6 = dt / 6.0;
    std::vector<double> k1v(n), k2v(n), k3v(n), k4v(n), k2q(n), k3q(n), k4q(n), qs(n), tmp(n);
    std::vector<double> vs(n), qp(n);
    set_armature(nullptr);
    const std::vector<int> held = resting(q, v, r0);
    accel(q, v, r0, t1.data(), k1v.data());
    sat1 = sat;  // stage-1 flags and torque are the ones reported
    for (int i = 0; i < n; ++i) k2q[i] = v[i] + h2 * k1v[i], qs[i] = q[i] + h2 * v[i];
    accel(qs.data(), k2q.data(), r1, tmp.data(), k2v.data());
    for (int i = 0; i < n; ++i) k3q[i] = v[i] + h2 * k2v[i], qs[i] = q[i] + h2 * k2q[i];
    accel(qs.data(), k3q.data(), r1, tmp.data(), k3v.data());
    for (int i = 0; i < n; ++i) k4q[i] = v[i] + dt * k3v[i], qs[i] = q[i] + dt * k3q[i];
    accel(qs.data(), k4q.data(), r2, tmp.data(), k4v.data());
    for (int i = 0; i < n; ++i) {
      vs[i] = v[i] + h6 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
      qp[i] = q[i] + h6 * (v[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i]);
    }
    sat = sat1;
    for (int i = 0; i < n; ++i) tau[i] = t1[i];
    locked.clear();
    project(q, vs.data(), qp.data(), 0.5, qn, vn);
    for (int i : held) stop[i] = 1;
    clamp(qn);
  }
};

struct Outcome {
  long fail_step = -1;
  int fail_joint = -1;
  int fail_code = FAIL_NONE;
};

// One rollout into caller-owned arrays. Runs without the GIL.
Outcome run(const pin::Model& model, const double* params, bool gc, double dt, bool rk4,
            double energy_max, long steps, const double* q0, const double* v0, const double* ref,
            double* Q, double* V, double* T, uint8_t* F) {
  Stepper s(model, params, gc, dt);
  const int n = s.n, nr = 2 * n;
  std::vector<double> q(q0, q0 + n), v(v0, v0 + n), qn(n), vn(n);
  for (int i = 0; i < n; ++i) Q[i] = q[i], V[i] = v[i];
  Outcome out;
  for (long k = 0; k < steps; ++k) {
    if (rk4) {
      const double* r = ref + RK4_ROWS * k * nr;
      s.rk4(q.data(), v.data(), r, r + nr, r + 2 * nr, qn.data(), vn.data());
    } else {
      s.euler(q.data(), v.data(), ref + k * nr, ref + k * nr + n, qn.data(), vn.data());
    }
    q = qn;
    v = vn;
    for (int i = 0; i < n; ++i) {
      Q[(k + 1) * n + i] = q[i];
      V[(k + 1) * n + i] = v[i];
      T[k * n + i] = s.tau[i];
      F[k * n + i] = (s.sat[i] ? FLAG_SATURATED : 0) | (s.stop[i] ? FLAG_STOP : 0);
    }
    int code = FAIL_NONE, joint = -1;
    for (int i = 0; i < n && code == FAIL_NONE; ++i) {
      if (!std::isfinite(q[i]) || !std::isfinite(v[i])) code = FAIL_NONFINITE, joint = i;
      else if (std::fabs(v[i]) > s.p(i, VABORT)) code = FAIL_VELOCITY, joint = i;
    }
    if (code == FAIL_NONE && (k + 1) % ENERGY_EVERY == 0) {
      s.set_armature(nullptr);  // the kinetic energy of the arm alone
      s.setq(q.data());
      for (int i = 0; i < n; ++i) s.va[i] = v[i];
      const double ke = pin::computeKineticEnergy(s.model, s.data, CRef(s.qa), CRef(s.va));
      if (!(ke <= energy_max)) code = FAIL_ENERGY;
    }
    if (code != FAIL_NONE) {
      out.fail_step = k + 1, out.fail_joint = joint, out.fail_code = code;
      break;
    }
  }
  return out;
}

nb::tuple rollout(const Plant& plant, In<double> params, bool gravity_comp, double dt,
                  const std::string& integrator, double energy_max, In<double> q0, In<double> v0,
                  In<double> ref, Out<double> Q, Out<double> V, Out<double> T, Out<uint8_t> F) {
  const size_t n = static_cast<size_t>(plant.model.nv);
  const bool rk4 = integrator == "rk4";
  if (!rk4 && integrator != "euler") throw std::invalid_argument("integrator: euler or rk4");
  const size_t rows = ref.ndim() == 2 ? ref.shape(0) : 0;
  const long steps = rows > 0 ? static_cast<long>((rows - 1) / (rk4 ? RK4_ROWS : 1)) : 0;
  if (params.size() != n * NPARAM || q0.size() != n || v0.size() != n || rows == 0 ||
      ref.shape(1) != 2 * n || Q.size() != (steps + 1) * n || V.size() != (steps + 1) * n ||
      T.size() != steps * n || F.size() != steps * n)
    throw std::invalid_argument("rollout: array sizes do not match the model and reference");
  Outcome o;
  {
    nb::gil_scoped_release release;
    o = run(plant.model, params.data(), gravity_comp, dt, rk4, energy_max, steps, q0.data(),
            v0.data(), ref.data(), Q.data(), V.data(), T.data(), F.data());
  }
  return nb::make_tuple(o.fail_step, o.fail_joint, o.fail_code);
}

}  // namespace

NB_MODULE(_rollout, m) {
  m.doc() = "armcli's compiled simulator rollout (see armcli.sim.native).";
  m.attr("ABI_VERSION") = ABI_VERSION;
  nb::class_<Plant>(m, "Model").def_prop_ro("nv", [](const Plant& p) { return p.model.nv; });
  m.def("build_model", &build_model, nb::arg("jtype"), nb::arg("parent"), nb::arg("placement"),
        nb::arg("axis"), nb::arg("inertia"), nb::arg("gravity"));
  m.def("rollout", &rollout, nb::arg("model"), nb::arg("params"), nb::arg("gravity_comp"),
        nb::arg("dt"), nb::arg("integrator"), nb::arg("energy_max"), nb::arg("q0"),
        nb::arg("v0"), nb::arg("ref"), nb::arg("q_out"), nb::arg("v_out"), nb::arg("tau_out"),
        nb::arg("flags_out"),
        "One rollout into the given output arrays; releases the GIL. Returns "
        "(fail_step, fail_joint, fail_code).");
}
