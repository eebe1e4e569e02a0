// armcli.sim._drivestep: the whole-robot drive's steps between two plugin updates, compiled.
//
// The drive (armcli.drive / sim.drive's run) steps MuJoCo once per dt; per step it sets the
// rotors to the plugin's commanded wheel speeds, writes the arm's actuator controls (the
// reference's ctrl row, plus g(q) / Kp of the fixed-base arm with gravity compensation),
// steps, and records the sensors and the clutch torques. Only the plugin's update (every
// `update_rate` period) and a path follower need Python; between two updates these steps
// are this loop, the same arithmetic in the same order as the Python loop it replaces
// (armcli's drive keeps that loop as the fallback and its tests compare the two).
//
// MuJoCo is not linked: Python hands over mj_step's address (ctypes, the very libmujoco the
// mujoco package loaded), the mjModel / mjData addresses and numpy views of the mjData
// arrays this loop touches, so the extension builds without MuJoCo's headers and cannot
// disagree with the installed MuJoCo about struct layouts. g(q) is Pinocchio's, on the
// pinocchio.Model Python serialised (bit for bit), as armcli.sim._rollout does.

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <boost/archive/binary_iarchive.hpp>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

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

namespace {

template <typename T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;
template <typename T>
using Out = nb::ndarray<T, nb::c_contig, nb::device::cpu>;
using StepFn = void (*)(const void*, void*);

std::vector<int64_t> ints(const In<int64_t>& a) {
  return std::vector<int64_t>(a.data(), a.data() + a.size());
}

// The gravity compensation of `simulate`'s controller: g(q) of the fixed-base arm model with
// its joints at the MuJoCo arm joints' positions and every other coordinate at rest
// (Robot.q(values) from Robot.rest_q; a continuous joint as its (cos, sin) pair).
struct Gravity {
  pin::Model model;
  pin::Data data;
  Vec q;                       // the rest configuration, then the current one
  std::vector<int64_t> idx_q;  // per arm joint: its first coordinate in q
  std::vector<char> continuous;

  const double* eval(const double* positions) {
    for (size_t i = 0; i < idx_q.size(); ++i) {
      const double x = positions[i];
      if (continuous[i]) {
        q[idx_q[i]] = std::cos(x), q[idx_q[i] + 1] = std::sin(x);
      } else {
        q[idx_q[i]] = x;
      }
    }
    return pin::computeGeneralizedGravity(model, data, CRef(q)).data();
  }
};

struct Stepper {
  StepFn step = nullptr;
  const void* m = nullptr;
  void* d = nullptr;
  double *qpos = nullptr, *qvel = nullptr, *ctrl = nullptr, *sens = nullptr, *qfrc = nullptr;
  int64_t nsens = 0;
  std::vector<int64_t> rotor, wheel_dof, wheel_force;  // 2 each: dofs, sensor columns
  std::vector<int64_t> arm_qpos, act, cols;            // arm joints' qpos; actuated: ctrl, joint
  std::vector<double> inv_kp;                          // per actuated joint (0: no g through ctrl)
  bool gc = false;
  Gravity g;
  std::vector<double> positions;
  // Owned by Python, kept alive by the references the Stepper holds.
  In<double> ctrl_arm;  // (T, ncols): the reference's ctrl rows
  Out<double> rec;      // (N + 1, nsens): every state's sensors
  Out<double> seen;     // (N + 1, 9): qpos[0:7] and the wheels' qvel before each step

  // Steps k0 .. k1 - 1 with the rotors at `command` and the arm at reference rows `rows`.
  void run(int64_t k0, int64_t k1, const int64_t* rows, double wl, double wr) {
    const int64_t N = static_cast<int64_t>(rec.shape(0)) - 1;
    const int64_t T = static_cast<int64_t>(ctrl_arm.shape(0));
    if (k0 < 0 || k1 > N || k0 > k1) throw std::invalid_argument("steps out of range");
    const size_t nc = act.size(), na = arm_qpos.size();
    const double* ca = ctrl_arm.data();
    double* out = rec.data();
    double* obs = seen.data();
    for (int64_t k = k0; k < k1; ++k) {
      const int64_t j = rows[k - k0];
      if (j < 0 || j >= T) throw std::invalid_argument("reference row out of range");
      double* o = obs + k * 9;
      for (int i = 0; i < 7; ++i) o[i] = qpos[i];
      o[7] = qvel[wheel_dof[0]], o[8] = qvel[wheel_dof[1]];
      qvel[rotor[0]] = wl, qvel[rotor[1]] = wr;
      const double* row = ca + j * static_cast<int64_t>(nc);
      if (gc) {
        for (size_t i = 0; i < na; ++i) positions[i] = qpos[arm_qpos[i]];
        const double* gv = g.eval(positions.data());
        for (size_t c = 0; c < nc; ++c) ctrl[act[c]] = row[c] + gv[cols[c]] * inv_kp[c];
      } else {
        for (size_t c = 0; c < nc; ++c) ctrl[act[c]] = row[c];
      }
      step(m, d);
      double* r = out + k * nsens;
      for (int64_t s = 0; s < nsens; ++s) r[s] = sens[s];
      r[wheel_force[0]] = -qfrc[rotor[0]], r[wheel_force[1]] = -qfrc[rotor[1]];
    }
  }
};

pin::Model load_model(nb::bytes data) {
  pin::Model model;
  std::stringbuf buf(std::string(data.c_str(), data.size()));
  boost::archive::binary_iarchive archive(buf);
  archive >> model;
  return model;
}

double* view(Out<double> a, size_t n, const char* what) {
  if (a.size() < n) throw std::invalid_argument(std::string(what) + ": too short");
  return a.data();
}

Stepper* make_stepper(uintptr_t step, uintptr_t m, uintptr_t d, Out<double> qpos,
                      Out<double> qvel, Out<double> ctrl, Out<double> sensordata,
                      Out<double> qfrc_constraint, In<int64_t> rotor, In<int64_t> wheel_dof,
                      In<int64_t> wheel_force, In<int64_t> arm_qpos, In<int64_t> act,
                      In<int64_t> cols, In<double> inv_kp, In<double> ctrl_arm, Out<double> rec,
                      Out<double> seen, nb::object gravity_model, In<double> rest_q,
                      In<int64_t> idx_q, In<uint8_t> continuous) {
  auto* s = new Stepper();
  s->step = reinterpret_cast<StepFn>(step);
  s->m = reinterpret_cast<const void*>(m), s->d = reinterpret_cast<void*>(d);
  s->rotor = ints(rotor), s->wheel_dof = ints(wheel_dof), s->wheel_force = ints(wheel_force);
  s->arm_qpos = ints(arm_qpos), s->act = ints(act), s->cols = ints(cols);
  s->inv_kp.assign(inv_kp.data(), inv_kp.data() + inv_kp.size());
  if (s->rotor.size() != 2 || s->wheel_dof.size() != 2 || s->wheel_force.size() != 2)
    throw std::invalid_argument("two wheels");
  if (s->act.size() != s->cols.size() || s->inv_kp.size() != s->act.size())
    throw std::invalid_argument("act, cols, inv_kp: one per actuated joint");
  if (ctrl_arm.ndim() != 2 || ctrl_arm.shape(1) != s->act.size())
    throw std::invalid_argument("ctrl_arm: one column per actuated joint");
  if (rec.ndim() != 2 || seen.ndim() != 2 || seen.shape(1) != 9 || seen.shape(0) != rec.shape(0))
    throw std::invalid_argument("rec (N + 1, nsens), seen (N + 1, 9)");
  s->nsens = static_cast<int64_t>(sensordata.size());
  if (static_cast<int64_t>(rec.shape(1)) != s->nsens)
    throw std::invalid_argument("rec: one column per sensordata value");
  s->qpos = view(qpos, 7, "qpos"), s->qvel = qvel.data(), s->ctrl = ctrl.data();
  s->sens = sensordata.data(), s->qfrc = qfrc_constraint.data();
  s->ctrl_arm = ctrl_arm, s->rec = rec, s->seen = seen;
  s->gc = !gravity_model.is_none();
  s->positions.resize(s->arm_qpos.size());
  if (s->gc) {
    s->g.model = load_model(nb::cast<nb::bytes>(gravity_model));
    s->g.data = pin::Data(s->g.model);
    if (static_cast<int64_t>(rest_q.size()) != s->g.model.nq)
      throw std::invalid_argument("rest_q: the arm model's nq");
    s->g.q = Eigen::Map<const Vec>(rest_q.data(), static_cast<Eigen::Index>(rest_q.size()));
    s->g.idx_q = ints(idx_q);
    s->g.continuous.assign(continuous.data(), continuous.data() + continuous.size());
    if (s->g.idx_q.size() != s->arm_qpos.size() || s->g.continuous.size() != s->arm_qpos.size())
      throw std::invalid_argument("idx_q, continuous: one per arm joint");
    for (int64_t c : s->cols)
      if (c < 0 || c >= s->g.model.nv) throw std::invalid_argument("cols: beyond the arm's nv");
  }
  return s;
}

void advance(Stepper& s, int64_t k0, int64_t k1, In<int64_t> rows, double wl, double wr) {
  if (static_cast<int64_t>(rows.size()) != k1 - k0)
    throw std::invalid_argument("rows: one per step");
  s.run(k0, k1, rows.data(), wl, wr);
}

}  // namespace

NB_MODULE(_drivestep, m) {
  m.doc() = "The whole-robot drive's steps between plugin updates (see armcli drive's run).";
  m.attr("SOURCE_SHA256") = ARMCLI_SOURCE_SHA256;
  nb::class_<Stepper>(m, "Stepper")
      .def("advance", &advance, nb::arg("k0"), nb::arg("k1"), nb::arg("rows"), nb::arg("wl"),
           nb::arg("wr"), "Steps k0 .. k1 - 1: rotors at (wl, wr), the arm at `rows`.");
  m.def("stepper", &make_stepper, nb::arg("step"), nb::arg("m"), nb::arg("d"), nb::arg("qpos"),
        nb::arg("qvel"), nb::arg("ctrl"), nb::arg("sensordata"), nb::arg("qfrc_constraint"),
        nb::arg("rotor"), nb::arg("wheel_dof"), nb::arg("wheel_force"), nb::arg("arm_qpos"),
        nb::arg("act"), nb::arg("cols"), nb::arg("inv_kp"), nb::arg("ctrl_arm"), nb::arg("rec"),
        nb::arg("seen"), nb::arg("gravity_model").none(), nb::arg("rest_q"), nb::arg("idx_q"),
        nb::arg("continuous"), nb::rv_policy::take_ownership);
}
