// armcli.plan._planner: the Python interface of the compiled planner (see core.hpp).
//
// Built at install time by scikit-build-core (CMakeLists.txt) with armcli.sim._rollout,
// against the Pinocchio and coal of the `pin` wheel and the toppra library of cmeel-toppra.
// Long calls (planning, sweeps, timing, batches) release the GIL.

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core.hpp"
#include "timing.hpp"

#ifndef ARMCLI_SOURCE_SHA256
#define ARMCLI_SOURCE_SHA256 ""
#endif

namespace nb = nanobind;
using namespace armcli_plan;

namespace {

template <typename T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;
using Out = nb::ndarray<nb::numpy, double>;

Vec vec(const In<double>& a, long n, const char* what) {
  if (a.ndim() != 1 || (n >= 0 && static_cast<long>(a.shape(0)) != n))
    throw std::invalid_argument(std::string(what) + ": wrong shape");
  return Eigen::Map<const Vec>(a.data(), static_cast<long>(a.shape(0)));
}

const double* rows(const In<double>& a, long n, const char* what, long& count) {
  if (a.ndim() != 2 || static_cast<long>(a.shape(1)) != n)
    throw std::invalid_argument(std::string(what) + ": wrong shape");
  count = static_cast<long>(a.shape(0));
  return a.data();
}

Out matrix(const RMat& m) {
  auto* copy = new RMat(m);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<RMat*>(p); });
  return Out(copy->data(), {static_cast<size_t>(m.rows()), static_cast<size_t>(m.cols())}, owner);
}

Out vector1(const Vec& v) {
  auto* copy = new Vec(v);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<Vec*>(p); });
  return Out(copy->data(), {static_cast<size_t>(v.size())}, owner);
}

nb::ndarray<nb::numpy, bool> flags(const std::vector<uint8_t>& f) {
  auto* copy = new std::vector<uint8_t>(f);
  nb::capsule owner(copy, [](void* p) noexcept { delete static_cast<std::vector<uint8_t>*>(p); });
  return nb::ndarray<nb::numpy, bool>(copy->data(), {f.size()}, owner);
}

RMat rmat(const double* data, long r, long c) { return Eigen::Map<const RMat>(data, r, c); }

// The Scene with the Python thread's own scratch space.
struct PyScene {
  std::unique_ptr<Scene> scene;
  std::unique_ptr<Work> work;

  const double* x(const In<double>& a) const {
    if (a.ndim() != 1 || static_cast<long>(a.shape(0)) != scene->n)
      throw std::invalid_argument("x: one value per planned joint");
    return a.data();
  }
};

PyScene* make_scene(nb::bytes model, nb::bytes geometry, In<double> q_template,
                    In<int32_t> joint, In<int32_t> iq, In<int32_t> iv, In<bool> continuous,
                    In<double> offset, In<double> coeff, In<int32_t> pair_a, In<int32_t> pair_b,
                    In<bool> moving, In<int32_t> body, In<double> lower, In<double> upper) {
  const long n = static_cast<long>(lower.shape(0)), E = static_cast<long>(joint.shape(0));
  const long P = static_cast<long>(pair_a.shape(0));
  if (iq.shape(0) != E || iv.shape(0) != E || continuous.shape(0) != E || offset.shape(0) != E)
    throw std::invalid_argument("map: arrays of different lengths");
  long rows_ = 0;
  const double* c = rows(coeff, n, "coeff", rows_);
  if (rows_ != E) throw std::invalid_argument("coeff: one row per map entry");
  std::vector<MapEntry> map(E);
  for (long e = 0; e < E; ++e) {
    map[e].joint = joint.data()[e], map[e].iq = iq.data()[e], map[e].iv = iv.data()[e];
    map[e].continuous = continuous.data()[e], map[e].offset = offset.data()[e];
    map[e].coeff = Eigen::Map<const Vec>(c + e * n, n);
  }
  if (pair_b.shape(0) != P || moving.shape(0) != P)
    throw std::invalid_argument("pairs: arrays of different lengths");
  std::vector<Pair> pairs(P);
  for (long p = 0; p < P; ++p)
    pairs[p] = Pair{pair_a.data()[p], pair_b.data()[p], moving.data()[p], 0.0};
  auto* out = new PyScene;
  out->scene = std::make_unique<Scene>(
      std::string(model.c_str(), model.size()), std::string(geometry.c_str(), geometry.size()),
      vec(q_template, -1, "q_template"), std::move(map), std::move(pairs),
      std::vector<int>(body.data(), body.data() + body.shape(0)), vec(lower, n, "lower"),
      vec(upper, n, "upper"));
  out->work = std::make_unique<Work>(*out->scene);
  return out;
}

nb::tuple plan(PyScene& ps, In<double> start, In<double> goal, double range, double goal_bias,
               double step, double timeout, uint64_t seed, int threads, long attempt_nodes,
               double bridge, double bridge_sigma, double lazy_step) {
  PlanOptions o;
  o.lazy_step = lazy_step;
  o.bridge = bridge, o.bridge_sigma = bridge_sigma;
  o.range = range, o.goal_bias = goal_bias, o.step = step, o.timeout = timeout, o.seed = seed;
  o.threads = threads, o.attempt_nodes = attempt_nodes;
  if (!(range > 0.0) || !(step > 0.0) || !(timeout > 0.0) || threads < 1 || attempt_nodes < 2)
    throw std::invalid_argument("range, step, timeout must be > 0; threads >= 1");
  const Vec a = Eigen::Map<const Vec>(ps.x(start), ps.scene->n);
  const Vec b = Eigen::Map<const Vec>(ps.x(goal), ps.scene->n);
  PlanStats stats;
  RMat path;
  {
    nb::gil_scoped_release release;
    path = rrt_connect(*ps.scene, a, b, o, stats);
  }
  nb::dict d;
  d["attempt"] = stats.attempt, d["states"] = stats.states, d["nodes"] = stats.nodes;
  d["timed_out"] = stats.timed_out;
  if (path.rows() == 0) return nb::make_tuple(nb::none(), d);
  return nb::make_tuple(matrix(path), d);
}

}  // namespace

NB_MODULE(_planner, m) {
  m.doc() = "armcli's planner: collision checks, RRT-Connect, certification sweep, timing.";
  m.attr("SOURCE_SHA256") = ARMCLI_SOURCE_SHA256;
  nb::class_<PyScene>(m, "Scene")
      .def_prop_ro("n", [](const PyScene& s) { return s.scene->n; })
      .def_prop_ro("npairs", [](const PyScene& s) { return s.scene->pairs.size(); })
      .def_prop_ro("queries", [](const PyScene& s) { return s.work->queries; })
      .def_prop_ro("states", [](const PyScene& s) { return s.work->states; })
      .def("q", [](const PyScene& s, In<double> x) {
            Vec q;
            s.scene->q_of(s.x(x), q);
            return vector1(q);
          }, nb::arg("x"))
      .def("set_margins", [](PyScene& s, In<double> margins) {
            const Vec m = vec(margins, static_cast<long>(s.scene->pairs.size()), "margins");
            for (size_t p = 0; p < s.scene->pairs.size(); ++p) s.scene->pairs[p].margin = m[p];
            s.scene->max_margin = m.size() ? std::max(0.0, m.maxCoeff()) : 0.0;
          }, nb::arg("margins"))
      .def("colliding", [](PyScene& s, In<double> x, double margin) {
            s.work->place(s.x(x));
            std::vector<int> out;
            for (size_t p = 0; p < s.scene->pairs.size(); ++p)
              if (s.scene->pairs[p].moving && s.work->pair_hits(static_cast<int>(p), margin))
                out.push_back(static_cast<int>(p));
            return out;
          }, nb::arg("x"), nb::arg("margin"))
      .def("first_collision", [](PyScene& s, In<double> x, bool every_pair) {
            return s.work->first_hit(s.x(x), every_pair ? EXACT_ALL : EXACT_MOVING);
          }, nb::arg("x"), nb::arg("every_pair"))
      .def("free", [](PyScene& s, In<double> x) { return s.work->free(s.x(x)); }, nb::arg("x"))
      .def("free_many", [](PyScene& s, In<double> X) {
            long count = 0;
            const double* x = rows(X, s.scene->n, "X", count);
            std::vector<uint8_t> out(count);
            {
              nb::gil_scoped_release release;
              for (long k = 0; k < count; ++k) out[k] = s.work->free(x + k * s.scene->n);
            }
            return flags(out);
          }, nb::arg("X"))
      .def("motion_free", [](PyScene& s, In<double> a, In<double> b, double step) {
            if (!(step > 0.0)) throw std::invalid_argument("step must be > 0");
            return s.work->motion_free(s.x(a), s.x(b), step);
          }, nb::arg("a"), nb::arg("b"), nb::arg("step"))
      .def("motion_free_many", [](PyScene& s, In<double> A, In<double> B, double step) {
            long ca = 0, cb = 0;
            const double* a = rows(A, s.scene->n, "A", ca);
            const double* b = rows(B, s.scene->n, "B", cb);
            if (ca != cb) throw std::invalid_argument("A and B: as many rows");
            if (!(step > 0.0)) throw std::invalid_argument("step must be > 0");
            std::vector<uint8_t> out(ca);
            {
              nb::gil_scoped_release release;
              const int n = s.scene->n;
              for (long k = 0; k < ca; ++k) out[k] = s.work->motion_free(a + k * n, b + k * n, step);
            }
            return flags(out);
          }, nb::arg("A"), nb::arg("B"), nb::arg("step"))
      .def("plan", &plan, nb::arg("start"), nb::arg("goal"), nb::kw_only(), nb::arg("range"),
           nb::arg("goal_bias"), nb::arg("step"), nb::arg("timeout"), nb::arg("seed"),
           nb::arg("threads"), nb::arg("attempt_nodes"), nb::arg("bridge") = 0.0,
           nb::arg("bridge_sigma") = 0.3, nb::arg("lazy_step") = 0.0)
      .def("shortcut", [](PyScene& s, In<double> path, double step, uint64_t seed, int tries,
                          int patience) {
            long count = 0;
            const double* p = rows(path, s.scene->n, "path", count);
            if (count < 2) throw std::invalid_argument("path: at least two waypoints");
            RMat out;
            {
              nb::gil_scoped_release release;
              out = shortcut(*s.work, rmat(p, count, s.scene->n), step, seed, tries, patience);
            }
            return matrix(out);
          }, nb::arg("path"), nb::arg("step"), nb::arg("seed"), nb::arg("tries"),
           nb::arg("patience"))
      .def("sweep", [](PyScene& s, In<double> X) {
            long count = 0;
            const double* x = rows(X, s.scene->n, "X", count);
            SweepResult r;
            {
              nb::gil_scoped_release release;
              r = sweep(*s.work, x, count);
            }
            return nb::make_tuple(r.sample, r.pair, r.queries, r.bounds);
          }, nb::arg("X"))
      .def("inverse_dynamics", [](PyScene& s, In<double> X, In<double> XD, In<double> XDD,
                                  std::vector<int> iv) {
            const int n = s.scene->n;
            long c0 = 0, c1 = 0, c2 = 0;
            const double* x = rows(X, n, "X", c0);
            const double* xd = rows(XD, n, "XD", c1);
            const double* xdd = rows(XDD, n, "XDD", c2);
            if (c0 != c1 || c0 != c2) throw std::invalid_argument("X, XD, XDD: as many rows");
            for (int i : iv)
              if (i < 0 || i >= s.scene->model.nv) throw std::invalid_argument("iv: out of range");
            RMat tau(c0, static_cast<long>(iv.size()));
            {
              nb::gil_scoped_release release;
              Vec q, v, a;
              for (long k = 0; k < c0; ++k)
                inverse_dynamics(*s.scene, s.work->data, x + k * n, xd + k * n, xdd + k * n, iv, q,
                                 v, a, tau.row(k).data());
            }
            return matrix(tau);
          }, nb::arg("X"), nb::arg("XD"), nb::arg("XDD"), nb::arg("iv"))
      .def("time_polyline", [](PyScene& s, In<double> W, In<double> velocity,
                               In<double> acceleration, In<double> effort, std::vector<int> iv,
                               int grid, double rate, double blend, double step) -> nb::object {
            const int n = s.scene->n;
            long count = 0;
            const double* w = rows(W, n, "W", count);
            if (count < 2 || grid < 1 || !(rate > 0.0))
              throw std::invalid_argument("two waypoints, grid >= 1 and rate > 0 needed");
            if (!(blend >= 0.0 && blend < 0.5) || !(step > 0.0))
              throw std::invalid_argument("blend in [0, 0.5) and step > 0 needed");
            TimingLimits lim;
            lim.velocity = vec(velocity, n, "velocity");
            lim.acceleration = vec(acceleration, n, "acceleration");
            lim.effort = vec(effort, -1, "effort");
            if (lim.effort.size() != 0 && lim.effort.size() != n)
              throw std::invalid_argument("effort: one per joint, or none");
            lim.iv = iv;
            if (static_cast<long>(iv.size()) != n) throw std::invalid_argument("iv: one per joint");
            Timed t;
            {
              nb::gil_scoped_release release;
              t = time_polyline(*s.scene, rmat(w, count, n), lim, grid, rate, s.work.get(), blend,
                                step);
            }
            if (t.failed_segment >= 0) return nb::int_(t.failed_segment);
            return nb::make_tuple(vector1(t.times), matrix(t.positions), matrix(t.velocities),
                                  matrix(t.accelerations));
          }, nb::arg("W"), nb::arg("velocity"), nb::arg("acceleration"), nb::arg("effort"),
           nb::arg("iv"), nb::arg("grid"), nb::arg("rate"), nb::arg("blend") = 0.0,
           nb::arg("step") = 0.02)
      .def_prop_ro("lever", [](const PyScene& s) {
            RMat l = s.scene->lever;
            return matrix(l);
          }, nb::rv_policy::automatic)
      .def_prop_ro("pair_lever", [](const PyScene& s) {
            RMat l = s.scene->pair_lever;
            return matrix(l);
          }, nb::rv_policy::automatic);
  m.def("scene", &make_scene, nb::arg("model"), nb::arg("geometry"), nb::arg("q_template"),
        nb::arg("joint"), nb::arg("iq"), nb::arg("iv"), nb::arg("continuous"), nb::arg("offset"),
        nb::arg("coeff"), nb::arg("pair_a"), nb::arg("pair_b"), nb::arg("moving"), nb::arg("body"),
        nb::arg("lower"), nb::arg("upper"), nb::rv_policy::take_ownership);
  m.def("spline", [](In<double> t, In<double> y) {
        long count = 0;
        const long n = y.ndim() == 2 ? static_cast<long>(y.shape(1)) : 0;
        const double* p = rows(y, n, "y", count);
        if (static_cast<long>(t.shape(0)) != count || count < 2)
          throw std::invalid_argument("t and y: as many points, at least two");
        RMat v, a;
        spline(vec(t, count, "t"), rmat(p, count, n), v, a);
        return nb::make_tuple(matrix(v), matrix(a));
      }, nb::arg("t"), nb::arg("y"));
  m.def("bisection_order", &bisection_order, nb::arg("n"));
}
