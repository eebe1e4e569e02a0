// The collision check of one state and of one straight edge (see core.hpp).

#include <algorithm>
#include <boost/archive/binary_iarchive.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <coal/BV/OBBRSS.h>
#include <coal/BVH/BVH_model.h>
#include <coal/shape/geometric_shapes.h>

#include "core.hpp"
#include "pinocchio/algorithm/kinematics.hpp"
#include "pinocchio/serialization.hpp"

namespace armcli_plan {

namespace {

constexpr double UNBOUNDED = 1e10;     // [m] a local box this large is a half-space's
constexpr double CHEAP_GAP = 0.08;     // [m] a box gap this wide is distance bound enough
constexpr double DISTANCE_TOL = 1e-6;  // [m] coal's distance may be this much too large
constexpr double HULL_SLACK = 1e-6;    // [m] a hull must clear the margin by this much
constexpr double HULL_DISTANCE_TOL = 1e-5;  // [m] GJK's distance between hulls may be this high
constexpr double OBB_SLACK = 1e-9;     // [m] and an oriented box by this much

template <typename T>
void load(const std::string& bytes, T& out) {
  std::stringbuf buf(bytes);
  boost::archive::binary_iarchive archive(buf);
  archive >> out;
}

Box box_of(const coal::CollisionGeometry& g) {
  Box b;
  const Vec3 lo = g.aabb_local.min_, hi = g.aabb_local.max_;
  b.bounded = lo.allFinite() && hi.allFinite() && lo.cwiseAbs().maxCoeff() < UNBOUNDED &&
              hi.cwiseAbs().maxCoeff() < UNBOUNDED;
  b.c = 0.5 * (lo + hi);
  b.h = 0.5 * (hi - lo);
  return b;
}

Obb obb_of(const coal::CollisionGeometry& g, const Box& box) {
  Obb o;
  if (g.getObjectType() == coal::OT_BVH && g.getNodeType() == coal::BV_OBBRSS) {
    const auto& bvh = static_cast<const coal::BVHModel<coal::OBBRSS>&>(g);
    if (bvh.getNumBVs() > 0) {
      const coal::OBB& root = bvh.getBV(0).bv.obb;
      o.R = root.axes, o.c = root.To, o.e = root.extent;
      return o;
    }
  }
  if (g.getNodeType() == coal::GEOM_BOX) {
    o.e = static_cast<const coal::Box&>(g).halfSide;
    return o;
  }
  o.c = box.c, o.e = box.h;  // other shapes: their local box
  return o;
}

// A mesh's convex hull (it contains the mesh: clear of it, the mesh is clear too).
std::shared_ptr<coal::CollisionGeometry> hull_of(coal::CollisionGeometry& g) {
  if (g.getObjectType() != coal::OT_BVH) return nullptr;
  auto& bvh = static_cast<coal::BVHModelBase&>(g);
  if (bvh.num_vertices < 4) return nullptr;
  try {
    bvh.buildConvexHull(false, "Qt");
  } catch (const std::exception&) {  // a flat or degenerate mesh: no hull, exact checks only
    return nullptr;
  }
  if (!bvh.convex) return nullptr;
  bvh.convex->computeLocalAABB();
  return bvh.convex;
}

}  // namespace

bool obb_apart(const Obb& A, const Obb& B, double margin) {
  // Gottschalk's separating-axis test of A grown by `margin` on each axis (which holds the
  // points within `margin` of A) and B: apart on an axis means farther than the margin.
  const Eigen::Matrix3d R = A.R.transpose() * B.R;
  const Vec3 t = A.R.transpose() * (B.c - A.c);
  const Vec3 a = A.e.array() + margin + OBB_SLACK, &b = B.e;
  const Eigen::Matrix3d AR = R.cwiseAbs().array() + 1e-12;
  for (int i = 0; i < 3; ++i)
    if (std::abs(t[i]) > a[i] + AR.row(i).dot(b)) return true;
  for (int j = 0; j < 3; ++j)
    if (std::abs(t.dot(R.col(j))) > AR.col(j).dot(a) + b[j]) return true;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = a[i1] * AR(i2, j) + a[i2] * AR(i1, j);
      const double rb = b[j1] * AR(i, j2) + b[j2] * AR(i, j1);
      if (std::abs(t[i2] * R(i1, j) - t[i1] * R(i2, j)) > ra + rb) return true;
    }
  }
  return false;
}

Scene::Scene(const std::string& model_bytes, const std::string& geom_bytes,
             const Vec& q_template_, std::vector<MapEntry> map_, std::vector<Pair> pairs_,
             std::vector<int> body_, const Vec& lower_, const Vec& upper_)
    : q_template(q_template_), lower(lower_), upper(upper_), map(std::move(map_)),
      pairs(std::move(pairs_)), body(std::move(body_)), n(static_cast<int>(lower_.size())) {
  load(model_bytes, model);
  load(geom_bytes, geom);
  if (q_template.size() != model.nq) throw std::invalid_argument("q_template: wrong length");
  if (upper.size() != n) throw std::invalid_argument("upper: wrong length");
  for (const MapEntry& e : map) {
    if (e.coeff.size() != n) throw std::invalid_argument("map: coefficient length");
    if (e.joint < 1 || e.joint >= model.njoints || e.iq < 0 || e.iq >= model.nq ||
        e.iv < 0 || e.iv >= model.nv || (e.continuous && e.iq + 1 >= model.nq))
      throw std::invalid_argument("map: index out of range");
  }
  const int ng = static_cast<int>(geom.ngeoms);
  for (const Pair& p : pairs)
    if (p.a < 0 || p.b < 0 || p.a >= ng || p.b >= ng)
      throw std::invalid_argument("pairs: geometry index out of range");
  if (static_cast<int>(body.size()) != ng) throw std::invalid_argument("body: one per geometry");
  int nb = 0;
  for (int b : body) {
    if (b < 0 || b >= ng) throw std::invalid_argument("body: index out of range");
    nb = std::max(nb, b + 1);
  }
  std::vector<char> joint_moves(model.njoints, 0);
  for (const MapEntry& e : map)
    if (e.coeff.cwiseAbs().maxCoeff() > 0.0) joint_moves[e.joint] = 1;
  geom_moves.assign(ng, 0);
  local.resize(ng);
  local_obb.resize(ng);
  hull.resize(ng);
  for (int g = 0; g < ng; ++g) {
    auto& obj = geom.geometryObjects[g];
    obj.geometry->computeLocalAABB();
    local[g] = box_of(*obj.geometry);
    local_obb[g] = obb_of(*obj.geometry, local[g]);
    hull[g] = hull_of(*obj.geometry);
    for (pin::JointIndex j : model.supports[obj.parentJoint])
      if (joint_moves[j]) geom_moves[g] = 1;
  }
  body_geoms.resize(nb);
  body_moves.assign(nb, 0);
  for (int g = 0; g < ng; ++g) {
    body_geoms[body[g]].push_back(g);
    if (geom_moves[g]) body_moves[body[g]] = 1;
  }
  std::vector<std::vector<int>> index(nb, std::vector<int>(nb, -1));
  for (size_t p = 0; p < pairs.size(); ++p) {
    if (!pairs[p].moving) continue;
    const int a = body[pairs[p].a], b = body[pairs[p].b];
    if (index[a][b] < 0) {
      index[a][b] = static_cast<int>(body_pairs.size());
      body_pairs.push_back(BodyPair{a, b, {}});
    }
    body_pairs[index[a][b]].pairs.push_back(static_cast<int>(p));
  }
  bound_levers();
}

void Scene::q_of(const double* x, Vec& q) const {
  q = q_template;
  for (const MapEntry& e : map) {
    double angle = e.offset;
    for (int k = 0; k < n; ++k) angle += e.coeff[k] * x[k];
    if (e.continuous) {
      q[e.iq] = std::cos(angle);
      q[e.iq + 1] = std::sin(angle);
    } else {
      q[e.iq] = angle;
    }
  }
}

Work::Work(const Scene& s_) : s(s_), data(s_.model) {
  const size_t ng = s.geom.ngeoms, np = s.pairs.size();
  tf.resize(ng);
  world.resize(ng);
  body_world.resize(s.body_geoms.size());
  stamp.assign(ng, 0);
  body_stamp.assign(s.body_geoms.size(), 0);
  world_obb.resize(ng);
  hull_collide.resize(np);
  hull_distance.resize(np);
  collide.reserve(np);
  distance.reserve(np);
  // CONTACT: coal 3.0.3's boolean-only query can miss a penetration (a cylinder 7.9 mm into
  // a box: collide 0, distance -0.0079); with contacts its GJK runs to the end and is exact.
  request.assign(np, coal::CollisionRequest(coal::CONTACT, 1));
  for (size_t p = 0; p < np; ++p) {
    const auto& a = s.geom.geometryObjects[s.pairs[p].a].geometry;
    const auto& b = s.geom.geometryObjects[s.pairs[p].b].geometry;
    collide.emplace_back(a.get(), b.get());
    distance.emplace_back(a.get(), b.get());
    const auto &ha = s.hull[s.pairs[p].a], &hb = s.hull[s.pairs[p].b];
    if (ha || hb) {
      const coal::CollisionGeometry *ga = ha ? ha.get() : a.get(), *gb = hb ? hb.get() : b.get();
      hull_collide[p] = std::make_unique<coal::ComputeCollision>(ga, gb);
      hull_distance[p] = std::make_unique<coal::ComputeDistance>(ga, gb);
    }
    request[p].enable_cached_gjk_guess = true;  // as Pinocchio's GeometryData sets it
    request[p].enable_contact = true;
  }
  x_tmp = s.lower;
  // every placement once: the geometries no planned joint moves keep it
  s.q_of(x_tmp.data(), q);
  pin::forwardKinematics(s.model, data, q);
  for (size_t g = 0; g < ng; ++g) {
    const auto& obj = s.geom.geometryObjects[g];
    const pin::SE3 M = data.oMi[obj.parentJoint] * obj.placement;
    tf[g] = coal::Transform3s(M.rotation(), M.translation());
    const Box& b = s.local[g];
    world[g].bounded = b.bounded;
    world[g].c = M.rotation() * b.c + M.translation();
    world[g].h = M.rotation().cwiseAbs() * b.h;
    world_obb[g].R = M.rotation() * s.local_obb[g].R;
    world_obb[g].c = M.rotation() * s.local_obb[g].c + M.translation();
    world_obb[g].e = s.local_obb[g].e;
  }
  for (size_t b = 0; b < s.body_geoms.size(); ++b) body_box(static_cast<int>(b));
}

void Work::body_box(int b) {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  bool bounded = true;
  for (int g : s.body_geoms[b]) {
    bounded = bounded && world[g].bounded;
    lo = lo.cwiseMin(world[g].c - world[g].h);
    hi = hi.cwiseMax(world[g].c + world[g].h);
  }
  body_world[b].bounded = bounded && !s.body_geoms[b].empty();
  body_world[b].c = 0.5 * (lo + hi);
  body_world[b].h = 0.5 * (hi - lo);
}

void Work::place(const double* x) {
  s.q_of(x, q);
  pin::forwardKinematics(s.model, data, q);
  ++version;  // every moving geometry's placement is now stale, computed when asked for
}

void Work::ready(int g) {
  if (!s.geom_moves[g] || stamp[g] == version) return;
  stamp[g] = version;
  const auto& obj = s.geom.geometryObjects[g];
  const pin::SE3 M = data.oMi[obj.parentJoint] * obj.placement;
  tf[g].setTransform(M.rotation(), M.translation());
  const Box& b = s.local[g];
  world[g].c.noalias() = M.rotation() * b.c + M.translation();
  world[g].h.noalias() = M.rotation().cwiseAbs() * b.h;
  world_obb[g].R.noalias() = M.rotation() * s.local_obb[g].R;
  world_obb[g].c.noalias() = M.rotation() * s.local_obb[g].c + M.translation();
}

void Work::ready_body(int b) {
  if (!s.body_moves[b] || body_stamp[b] == version) return;
  body_stamp[b] = version;
  for (int g : s.body_geoms[b]) ready(g);
  body_box(b);
}

bool Work::pair_hits(int p, double margin) {
  const Pair& P = s.pairs[p];
  ready(P.a), ready(P.b);
  const Box &A = world[P.a], &B = world[P.b];
  if (A.bounded && B.bounded) {
    const Vec3 gap = (A.c - B.c).cwiseAbs() - A.h - B.h;
    if (gap.maxCoeff() > margin) return false;  // farther apart than the margin on an axis
    if (obb_apart(world_obb[P.a], world_obb[P.b], margin)) return false;
  }
  coal::CollisionRequest& r = request[p];
  if (hull_collide[p]) {  // the convex hulls clear by more than the margin: so are the meshes
    r.security_margin = margin + HULL_SLACK;
    r.distance_upper_bound = r.security_margin + 1e-6;
    coal::CollisionResult res;
    ++queries;
    (*hull_collide[p])(tf[P.a], tf[P.b], r, res);
    if (!res.isCollision()) return false;
  }
  r.security_margin = margin;
  r.distance_upper_bound = margin + 1e-6;  // as pinocchio::computeCollision sets it
  coal::CollisionResult res;
  ++queries;
  collide[p](tf[P.a], tf[P.b], r, res);
  return res.isCollision();
}

int Work::first_hit(const double* x, Mode mode) {
  place(x);
  for (size_t p = 0; p < s.pairs.size(); ++p) {
    const Pair& P = s.pairs[p];
    if (mode != EXACT_ALL && !P.moving) continue;
    if (pair_hits(static_cast<int>(p), mode == PLANNER ? P.margin : 0.0))
      return static_cast<int>(p);
  }
  return -1;
}

bool Work::free(const double* x) {
  place(x);
  ++states;
  if (last_hit >= 0 && pair_hits(last_hit, s.pairs[last_hit].margin)) return false;
  for (const BodyPair& bp : s.body_pairs) {
    ready_body(bp.a), ready_body(bp.b);
    const Box &A = body_world[bp.a], &B = body_world[bp.b];
    if (A.bounded && B.bounded &&
        ((A.c - B.c).cwiseAbs() - A.h - B.h).maxCoeff() > s.max_margin)
      continue;  // the bodies are apart: every pair between them is
    for (int p : bp.pairs) {
      if (p == last_hit) continue;
      if (pair_hits(p, s.pairs[p].margin)) {
        last_hit = p;
        return false;
      }
    }
  }
  return true;
}

bool Work::motion_free(const double* a, const double* b, double step) {
  double big = 0.0;
  for (int i = 0; i < s.n; ++i) big = std::max(big, std::abs(b[i] - a[i]));
  const int n = std::max(1, static_cast<int>(std::ceil(big / step)));
  x_tmp.resize(s.n);
  if (static_cast<int>(orders.size()) <= n) orders.resize(n + 1);
  if (orders[n].empty()) orders[n] = bisection_order(n);
  for (int k : orders[n]) {
    const double u = static_cast<double>(k) / n;
    for (int i = 0; i < s.n; ++i) x_tmp[i] = a[i] + (b[i] - a[i]) * u;
    if (!free(x_tmp.data())) return false;
  }
  return true;
}

double Work::pair_distance(int p) {
  const Pair& P = s.pairs[p];
  ready(P.a), ready(P.b);
  const Box &A = world[P.a], &B = world[P.b];
  if (A.bounded && B.bounded) {
    const Vec3 gap = ((A.c - B.c).cwiseAbs() - A.h - B.h).cwiseMax(0.0);
    const double d = gap.norm();  // the boxes' distance: a lower bound of the shapes'
    if (d > CHEAP_GAP) return d;
  }
  try {
    coal::DistanceRequest r(false);
    coal::DistanceResult res;
    ++queries;
    if (hull_distance[p]) {  // the hulls' distance: a lower bound of the meshes', and cheap
      (*hull_distance[p])(tf[P.a], tf[P.b], r, res);
      if (res.min_distance - HULL_DISTANCE_TOL > 0.0) return res.min_distance - HULL_DISTANCE_TOL;
      res = coal::DistanceResult();
      ++queries;
    }
    distance[p](tf[P.a], tf[P.b], r, res);
    return res.min_distance - DISTANCE_TOL;
  } catch (const std::exception&) {  // a pair coal cannot measure (e.g. a mesh and a plane)
    return -std::numeric_limits<double>::infinity();
  }
}

std::vector<int> bisection_order(int n) {
  std::vector<int> out{n};
  std::vector<char> seen(n + 1, 0);
  seen[0] = seen[n] = 1;
  std::vector<std::pair<int, int>> intervals{{0, n}}, next;
  while (!intervals.empty()) {
    next.clear();
    for (auto [lo, hi] : intervals) {
      const int mid = (lo + hi) / 2;
      if (!seen[mid]) {
        seen[mid] = 1;
        out.push_back(mid);
      }
      if (mid - lo > 1) next.emplace_back(lo, mid);
      if (hi - mid > 1) next.emplace_back(mid, hi);
    }
    intervals.swap(next);
  }
  return out;
}

}  // namespace armcli_plan
