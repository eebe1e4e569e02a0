// Certification's collision sweep: every sample of a trajectory checked exactly, most of them
// proved free without a coal query.
//
// A pair's distance d at sample k bounds it at any later sample m: no point of geometry g moves
// farther than sum_j lever(g, j) |x_j(m) - x_j(k)| between the two configurations (the
// straight joint-space path between them is one way there; along it a point's speed is at
// most sum_j lever(g, j) |dx_j/dt|). So while d exceeds the two geometries' bounds the pair
// is free and needs no query; otherwise it is queried (coal distance, or the box gap where
// the boxes are far apart), and when that is not clearly positive, checked exactly as the
// Python checker checks it (coal collide, no margin). The verdict at every sample is the
// exact check's; only provably free pairs are skipped.
//
// lever(g, j): for a revolute joint, the longest distance from its axis to any point of g
// over every configuration, bounded by the chain's link offsets (joint placements, plus the
// stroke of any prismatic joint between) plus g's placement and its bounding sphere; for a
// prismatic joint, 1. A mimic follower adds its multiplier times its own lever. Two
// geometries' distance depends on their relative pose only, which the joints above both
// do not change: a pair's bound counts the joints on the path between them alone.

#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "core.hpp"
#include "pinocchio/algorithm/rnea.hpp"

namespace armcli_plan {

namespace {

bool is_prismatic(const pin::Model& m, pin::JointIndex j) {
  return m.joints[j].shortname().find("Prismatic") != std::string::npos;
}

bool is_revolute(const pin::Model& m, pin::JointIndex j) {
  return m.joints[j].shortname().find("Revolute") != std::string::npos;
}

}  // namespace

void Scene::bound_levers() {
  const int nj = model.njoints, ng = static_cast<int>(geom.ngeoms);
  // [m] how far each joint's motion can carry the next joint's origin: its placement
  // offset, plus the stroke of a prismatic joint (its largest |q|)
  Vec reach = Vec::Zero(nj);
  for (int j = 1; j < nj; ++j) reach[j] = model.jointPlacements[j].translation().norm();
  for (int j = 1; j < nj; ++j) {
    if (!is_prismatic(model, j)) continue;
    const int iq = model.joints[j].idx_q();
    double stroke = std::abs(q_template[iq]);
    for (const MapEntry& e : map) {
      if (e.joint != j) continue;
      stroke = std::abs(e.offset);
      for (int k = 0; k < n; ++k)
        stroke += std::abs(e.coeff[k]) * std::max(std::abs(lower[k]), std::abs(upper[k]));
    }
    reach[j] += stroke;
  }
  const int E = static_cast<int>(map.size());
  Eigen::MatrixXd entry = Eigen::MatrixXd::Zero(ng, E);  // lever of map entry e on g (0: none)
  for (int g = 0; g < ng; ++g) {
    const auto& obj = geom.geometryObjects[g];
    const auto& chain = model.supports[obj.parentJoint];  // root ... parent joint
    const double own = obj.placement.translation().norm() + local[g].c.norm() + local[g].h.norm();
    for (int k = 0; k < E; ++k) {
      const MapEntry& e = map[k];
      int pos = -1;
      for (size_t i = 0; i < chain.size(); ++i)
        if (static_cast<int>(chain[i]) == e.joint) pos = static_cast<int>(i);
      if (pos < 0) continue;
      double arm = own;  // distance from the joint's origin (on its axis) to g's points
      for (size_t i = pos + 1; i < chain.size(); ++i) arm += reach[chain[i]];
      double r = is_prismatic(model, e.joint) ? 1.0 : arm;
      if (!is_prismatic(model, e.joint) && !is_revolute(model, e.joint)) r = arm + 1.0;
      entry(g, k) = r;
    }
  }
  lever = Eigen::MatrixXd::Zero(ng, n);
  for (int g = 0; g < ng; ++g)
    for (int k = 0; k < E; ++k) lever.row(g) += map[k].coeff.cwiseAbs().transpose() * entry(g, k);
  pair_lever = Eigen::MatrixXd::Zero(static_cast<long>(pairs.size()), n);
  for (size_t p = 0; p < pairs.size(); ++p)
    for (int k = 0; k < E; ++k) {
      const double ra = entry(pairs[p].a, k), rb = entry(pairs[p].b, k);
      if (ra > 0.0 && rb > 0.0) continue;  // a joint above both: their relative pose keeps
      pair_lever.row(p) += map[k].coeff.cwiseAbs().transpose() * (ra + rb);
    }
}

SweepResult sweep(Work& w, const double* X, long rows) {
  const Scene& s = w.s;
  const int n = s.n, np = static_cast<int>(s.pairs.size());
  SweepResult out;
  if (rows <= 0) return out;
  const long queries = w.queries;
  auto done = [&](long k, int p) {
    out.sample = k, out.pair = p, out.queries = w.queries - queries;
    return out;
  };
  w.place(X);
  for (int p = 0; p < np; ++p)
    if (w.pair_hits(p, 0.0)) return done(0, p);
  // S(k, j): the path length of joint j up to sample k; a pair's bound between samples a and
  // k is sum_j lever(p, j) (S(k, j) - S(a, j)) >= its displacement, and grows with k, so the
  // first sample it fails at is found by bisection.
  std::vector<double> S(static_cast<size_t>(rows) * n, 0.0);
  for (long k = 1; k < rows; ++k)
    for (int j = 0; j < n; ++j)
      S[k * n + j] = S[(k - 1) * n + j] + std::abs(X[k * n + j] - X[(k - 1) * n + j]);
  auto moved = [&](int p, long a, long k) {
    double m = 0.0;
    for (int j = 0; j < n; ++j) m += s.pair_lever(p, j) * (S[k * n + j] - S[a * n + j]);
    return m;
  };
  auto next = [&](int p, long a, double clear) {  // the first sample not proved free
    if (!(clear > 0.0) || a + 1 >= rows) return a + 1;
    if (moved(p, a, rows - 1) < clear) return rows;
    long lo = a, hi = rows - 1;  // moved(lo) < clear <= moved(hi)
    while (hi - lo > 1) {
      const long mid = lo + (hi - lo) / 2;
      (moved(p, a, mid) < clear ? lo : hi) = mid;
    }
    return hi;
  };
  using Due = std::pair<long, int>;  // (sample, pair): earliest first, then pair order
  std::priority_queue<Due, std::vector<Due>, std::greater<Due>> queue;
  for (int p = 0; p < np; ++p)
    if (s.pairs[p].moving) {
      ++out.bounds;
      queue.emplace(next(p, 0, w.pair_distance(p)), p);
    }
  std::vector<int> now;
  while (!queue.empty() && queue.top().first < rows) {
    const long k = queue.top().first;
    now.clear();
    while (!queue.empty() && queue.top().first == k) now.push_back(queue.top().second), queue.pop();
    w.place(X + k * n);  // the pairs not yet proved free at k, in pair order
    for (int p : now) {
      ++out.bounds;
      const double d = w.pair_distance(p);
      if (!(d > 0.0) && w.pair_hits(p, 0.0)) return done(k, p);
      queue.emplace(next(p, k, d), p);
    }
  }
  out.queries = w.queries - queries;
  return out;
}

void inverse_dynamics(const Scene& s, pin::Data& data, const double* x, const double* xd,
                      const double* xdd, const std::vector<int>& iv, Vec& q, Vec& v, Vec& a,
                      double* tau) {
  s.q_of(x, q);
  v.setZero(s.model.nv);
  a.setZero(s.model.nv);
  for (const MapEntry& e : s.map) {
    double vi = 0.0, ai = 0.0;
    for (int k = 0; k < s.n; ++k) vi += e.coeff[k] * xd[k], ai += e.coeff[k] * xdd[k];
    v[e.iv] = vi, a[e.iv] = ai;
  }
  const Vec& t = pin::rnea(s.model, data, q, v, a);
  for (size_t j = 0; j < iv.size(); ++j) tau[j] = t[iv[j]];
}

}  // namespace armcli_plan
