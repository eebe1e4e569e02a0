// armcli.sim._raycast: a sensor's rays cast against MuJoCo's primitive geoms.
//
// mj_multiRay tests every ray against every geom; a 160 x 120 depth image is 19,200 rays and
// cost 3-6x a drive's 100 physics steps. A pinhole's rays leave one point through a regular
// grid, so each geom is tested only on the pixels its bounding box (MuJoCo's geom_aabb)
// projects onto, and not at all when the box lies before the near plane (the robot behind
// the camera); a z-buffer over geoms. The ray of pixel (u, v) is o + t (x_n, y_n, 1) in the
// optical frame, so t is the depth along the optical axis itself; a pixel keeps the first
// surface crossing with near <= t <= far (from inside a shape: its exit, as MuJoCo's rays
// see it). A lidar's rays (cast_rays) each start at range_min: mj_multiRay casts from the
// origin and a lidar inside its own housing would have every ray cast again; here a ray
// tests a geom only where its segment [start, stop] passes the geom's bounding sphere.
//
// Shapes are MuJoCo's, in each geom's frame (geom_xpos, geom_xmat): plane (z = 0, seen from
// +z only, bounded by size[0], size[1] unless 0), sphere, capsule, ellipsoid, cylinder (radius
// size[0], half height size[1]), box (half sizes). Other types (mesh, height field, SDF) are not
// cast here: their pixels come back in `other`, for the caller to cast with MuJoCo.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace nb = nanobind;

namespace {

constexpr int PLANE = 0, SPHERE = 2, CAPSULE = 3, ELLIPSOID = 4, CYLINDER = 5, BOX = 6;
constexpr double INF = std::numeric_limits<double>::infinity();

template <typename T>
using In = nb::ndarray<const T, nb::c_contig, nb::device::cpu>;
template <typename T>
using Out = nb::ndarray<T, nb::c_contig, nb::device::cpu>;

struct Ray {
  double o[3], d[3];  // in the geom's frame; t scales d (not unit)
};

// The first t >= lo among the two roots of a t^2 + 2 b t + c = 0 that `keep` accepts.
template <typename Keep>
double quadratic(double a, double b, double c, double lo, Keep keep) {
  if (a <= 0.0) return INF;
  const double disc = b * b - a * c;
  if (disc < 0.0) return INF;
  const double s = std::sqrt(disc);
  for (double t : {(-b - s) / a, (-b + s) / a})
    if (t >= lo && keep(t)) return t;
  return INF;
}

double plane(const Ray& r, const double* size, double lo) {
  if (r.d[2] >= 0.0 || r.o[2] < 0.0) return INF;  // MuJoCo: seen from its +z side only
  const double t = -r.o[2] / r.d[2];
  if (t < lo) return INF;
  for (int i = 0; i < 2; ++i)
    if (size[i] > 0.0 && std::abs(r.o[i] + t * r.d[i]) > size[i]) return INF;
  return t;
}

double sphere(const Ray& r, double radius, double lo) {
  const double* o = r.o;
  const double* d = r.d;
  return quadratic(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], o[0] * d[0] + o[1] * d[1] + o[2] * d[2],
                   o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - radius * radius, lo,
                   [](double) { return true; });
}

double ellipsoid(const Ray& r, const double* size, double lo) {
  Ray s;
  for (int i = 0; i < 3; ++i) {
    s.o[i] = r.o[i] / size[i];
    s.d[i] = r.d[i] / size[i];
  }
  return sphere(s, 1.0, lo);
}

// The side x^2 + y^2 = radius^2 where |z| <= h.
double side(const Ray& r, double radius, double h, double lo) {
  const double* o = r.o;
  const double* d = r.d;
  return quadratic(d[0] * d[0] + d[1] * d[1], o[0] * d[0] + o[1] * d[1],
                   o[0] * o[0] + o[1] * o[1] - radius * radius, lo,
                   [&](double t) { return std::abs(o[2] + t * d[2]) <= h; });
}

double cylinder(const Ray& r, const double* size, double lo) {
  const double radius = size[0], h = size[1];
  double best = side(r, radius, h, lo);
  if (r.d[2] != 0.0) {
    for (double z : {-h, h}) {  // the flat caps
      const double t = (z - r.o[2]) / r.d[2];
      const double x = r.o[0] + t * r.d[0], y = r.o[1] + t * r.d[1];
      if (t >= lo && t < best && x * x + y * y <= radius * radius) best = t;
    }
  }
  return best;
}

double capsule(const Ray& r, const double* size, double lo) {
  const double radius = size[0], h = size[1];
  double best = side(r, radius, h, lo);
  for (double z : {-h, h}) {  // the hemispheres, each beyond its end of the side
    Ray c = r;
    c.o[2] -= z;
    const double* o = c.o;
    const double* d = c.d;
    const double t = quadratic(
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2], o[0] * d[0] + o[1] * d[1] + o[2] * d[2],
        o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - radius * radius, lo,
        [&](double s) { return (o[2] + s * d[2]) * z >= 0.0; });
    best = std::min(best, t);
  }
  return best;
}

double box(const Ray& r, const double* size, double lo) {
  double best = INF;
  for (int i = 0; i < 3; ++i) {
    if (r.d[i] == 0.0) continue;
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    for (double face : {-size[i], size[i]}) {
      const double t = (face - r.o[i]) / r.d[i];
      if (t < lo || t >= best) continue;
      if (std::abs(r.o[j] + t * r.d[j]) <= size[j] && std::abs(r.o[k] + t * r.d[k]) <= size[k])
        best = t;
    }
  }
  return best;
}

double hit(int type, const Ray& r, const double* size, double lo) {
  switch (type) {
    case PLANE: return plane(r, size, lo);
    case SPHERE: return sphere(r, size[0], lo);
    case CAPSULE: return capsule(r, size, lo);
    case ELLIPSOID: return ellipsoid(r, size, lo);
    case CYLINDER: return cylinder(r, size, lo);
    case BOX: return box(r, size, lo);
    default: return INF;
  }
}

bool cast_here(int type) { return type == PLANE || (type >= SPHERE && type <= BOX); }

struct Camera {
  double o[3], R[9];  // origin, R_world_optical (row-major)
  double fx, fy, cx, cy, near, far;
  int width, height;
};

struct Geom {  // one geom in the world: MuJoCo's type, size, pose and local bounding box
  int type;
  const double *size, *pos, *mat, *aabb;  // aabb: centre (3), half sizes (3), geom frame
};

// Pixels [u0, u1) x [v0, v1) the geom's bounding box may cover; false when it lies wholly
// before the near plane (behind the camera: the robot's own base, the camera's housing).
bool footprint(const Camera& cam, const Geom& g, int* fp) {
  fp[0] = 0, fp[1] = cam.width, fp[2] = 0, fp[3] = cam.height;
  if (g.type == PLANE) return true;
  double A[9], c[3], w[3];  // A = R^T mat: geom axes in the optical frame; c: box centre
  for (int i = 0; i < 3; ++i) {
    w[i] = g.pos[i] - cam.o[i];
    for (int k = 0; k < 3; ++k) w[i] += g.mat[3 * i + k] * g.aabb[k];
  }
  for (int i = 0; i < 3; ++i) {
    c[i] = cam.R[i] * w[0] + cam.R[3 + i] * w[1] + cam.R[6 + i] * w[2];
    for (int k = 0; k < 3; ++k)
      A[3 * i + k] = cam.R[i] * g.mat[k] + cam.R[3 + i] * g.mat[3 + k] + cam.R[6 + i] * g.mat[6 + k];
  }
  double ez = 0.0;
  for (int k = 0; k < 3; ++k) ez += std::abs(A[6 + k]) * g.aabb[3 + k];
  if (c[2] + ez < cam.near) return false;
  if (c[2] - ez <= 1e-9) return true;  // reaches behind the camera: every pixel
  double lo[2] = {INF, INF}, hi[2] = {-INF, -INF};
  for (int corner = 0; corner < 8; ++corner) {
    double p[3];
    for (int i = 0; i < 3; ++i) {
      p[i] = c[i];
      for (int k = 0; k < 3; ++k) p[i] += A[3 * i + k] * ((corner >> k & 1) ? 1 : -1) * g.aabb[3 + k];
    }
    for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], p[a] / p[2]), hi[a] = std::max(hi[a], p[a] / p[2]);
  }
  const double f[2] = {cam.fx, cam.fy}, ctr[2] = {cam.cx, cam.cy};
  const int n[2] = {cam.width, cam.height};
  for (int a = 0; a < 2; ++a) {
    fp[2 * a] = std::max(0, static_cast<int>(std::floor(ctr[a] + f[a] * lo[a])));
    fp[2 * a + 1] = std::min(n[a], static_cast<int>(std::ceil(ctr[a] + f[a] * hi[a])) + 1);
  }
  return fp[0] < fp[1] && fp[2] < fp[3];
}

// The ray origin in the geom's frame, and M = mat^T R: a direction R d in the geom's frame.
void to_geom(const double* o, const double* R, const Geom& g, double* og, double* M) {
  double rel[3];
  for (int i = 0; i < 3; ++i) rel[i] = o[i] - g.pos[i];
  for (int i = 0; i < 3; ++i) {
    og[i] = g.mat[i] * rel[0] + g.mat[3 + i] * rel[1] + g.mat[6 + i] * rel[2];
    for (int j = 0; j < 3; ++j)
      M[3 * i + j] = g.mat[i] * R[j] + g.mat[3 + i] * R[3 + j] + g.mat[6 + i] * R[6 + j];
  }
}

void cast_geom(const Camera& cam, const Geom& g, double* depth, int32_t* geom, uint8_t* other,
               int id) {
  int fp[4];
  if (!footprint(cam, g, fp)) return;
  if (!cast_here(g.type)) {
    for (int v = fp[2]; v < fp[3]; ++v)
      for (int u = fp[0]; u < fp[1]; ++u) other[v * cam.width + u] = 1;
    return;
  }
  Ray r;
  double M[9];
  to_geom(cam.o, cam.R, g, r.o, M);
  for (int v = fp[2]; v < fp[3]; ++v) {
    const double yn = (v - cam.cy) / cam.fy;
    for (int u = fp[0]; u < fp[1]; ++u) {
      const double xn = (u - cam.cx) / cam.fx;
      for (int i = 0; i < 3; ++i) r.d[i] = M[3 * i] * xn + M[3 * i + 1] * yn + M[3 * i + 2];
      const int p = v * cam.width + u;
      const double t = hit(g.type, r, g.size, cam.near);
      if (t <= cam.far && t < depth[p]) depth[p] = t, geom[p] = id;
    }
  }
}

void check_sizes(size_t n, const In<double>& sizes, const In<double>& pos, const In<double>& mats,
                 const In<double>& aabb, const In<int32_t>& ids) {
  if (sizes.size() != 3 * n || pos.size() != 3 * n || mats.size() != 9 * n ||
      aabb.size() != 6 * n || ids.size() != n)
    throw std::invalid_argument("raycast: geom array sizes disagree");
}

Geom geom_at(size_t g, const In<int32_t>& types, const In<double>& sizes, const In<double>& pos,
             const In<double>& mats, const In<double>& aabb) {
  return Geom{types.data()[g], sizes.data() + 3 * g, pos.data() + 3 * g, mats.data() + 9 * g,
              aabb.data() + 6 * g};
}

// Depth [m] (+inf: nothing between near and far), the geom hit (-1), pixels left to MuJoCo.
void cast_pinhole(In<double> origin, In<double> R, double fx, double fy, double cx, double cy,
                  int width, int height, double near, double far, In<int32_t> types,
                  In<double> sizes, In<double> pos, In<double> mats, In<double> aabb,
                  In<int32_t> ids, Out<double> depth, Out<int32_t> geom, Out<uint8_t> other) {
  Camera cam{};
  std::copy_n(origin.data(), 3, cam.o);
  std::copy_n(R.data(), 9, cam.R);
  cam.fx = fx, cam.fy = fy, cam.cx = cx, cam.cy = cy, cam.near = near, cam.far = far;
  cam.width = width, cam.height = height;
  const size_t n = types.size(), pixels = static_cast<size_t>(width) * height;
  check_sizes(n, sizes, pos, mats, aabb, ids);
  if (depth.size() != pixels || geom.size() != pixels || other.size() != pixels)
    throw std::invalid_argument("cast_pinhole: image array sizes disagree");
  nb::gil_scoped_release release;
  std::fill_n(depth.data(), pixels, INF);
  std::fill_n(geom.data(), pixels, -1);
  std::fill_n(other.data(), pixels, 0);
  for (size_t g = 0; g < n; ++g)
    cast_geom(cam, geom_at(g, types, sizes, pos, mats, aabb), depth.data(), geom.data(),
              other.data(), ids.data()[g]);
}

// Rays from one origin along unit `dirs`, each seeing only [start, stop]: the distance to the
// first surface there (+inf: none), the geom (-1), rays a non-primitive may meet (for MuJoCo).
void cast_rays(In<double> origin, In<double> dirs, In<double> start, In<double> stop,
               In<int32_t> types, In<double> sizes, In<double> pos, In<double> mats,
               In<double> aabb, In<double> rbound, In<int32_t> ids, Out<double> dist,
               Out<int32_t> geom, Out<uint8_t> other) {
  const size_t n = types.size(), rays = start.size();
  check_sizes(n, sizes, pos, mats, aabb, ids);
  if (dirs.size() != 3 * rays || stop.size() != rays || dist.size() != rays ||
      geom.size() != rays || other.size() != rays || rbound.size() != n)
    throw std::invalid_argument("cast_rays: ray array sizes disagree");
  nb::gil_scoped_release release;
  const double* o = origin.data();
  std::fill_n(dist.data(), rays, INF);
  std::fill_n(geom.data(), rays, -1);
  std::fill_n(other.data(), rays, 0);
  const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (size_t k = 0; k < n; ++k) {
    const Geom g = geom_at(k, types, sizes, pos, mats, aabb);
    const double rb = rbound.data()[k];
    double c[3];  // the bounding sphere's centre relative to the origin
    for (int i = 0; i < 3; ++i) c[i] = g.pos[i] - o[i];
    Ray r;
    double M[9];
    to_geom(o, identity, g, r.o, M);
    for (size_t j = 0; j < rays; ++j) {
      const double* d = dirs.data() + 3 * j;
      const double lo = start.data()[j], hi = std::min(stop.data()[j], dist.data()[j]);
      if (g.type != PLANE) {  // the ray's segment [lo, hi] must pass the bounding sphere
        const double along = c[0] * d[0] + c[1] * d[1] + c[2] * d[2];
        const double off = c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - along * along;
        if (off > rb * rb || along + rb < lo || along - rb > hi) continue;
      }
      if (!cast_here(g.type)) {
        other.data()[j] = 1;
        continue;
      }
      for (int i = 0; i < 3; ++i) r.d[i] = M[3 * i] * d[0] + M[3 * i + 1] * d[1] + M[3 * i + 2] * d[2];
      const double t = hit(g.type, r, g.size, lo);
      if (t <= hi) dist.data()[j] = t, geom.data()[j] = ids.data()[k];
    }
  }
}

}  // namespace

NB_MODULE(_raycast, m) {
#ifdef ARMCLI_SOURCE_SHA256
  m.attr("SOURCE_SHA256") = ARMCLI_SOURCE_SHA256;
#endif
  m.def("cast_pinhole", &cast_pinhole, nb::arg("origin"), nb::arg("R"), nb::arg("fx"),
        nb::arg("fy"), nb::arg("cx"), nb::arg("cy"), nb::arg("width"), nb::arg("height"),
        nb::arg("near"), nb::arg("far"), nb::arg("types"), nb::arg("sizes"), nb::arg("pos"),
        nb::arg("mats"), nb::arg("aabb"), nb::arg("ids"), nb::arg("depth"), nb::arg("geom"),
        nb::arg("other"),
        "Cast a pinhole's rays against primitive geoms, in place (see raycast.cpp).");
  m.def("cast_rays", &cast_rays, nb::arg("origin"), nb::arg("dirs"), nb::arg("start"),
        nb::arg("stop"), nb::arg("types"), nb::arg("sizes"), nb::arg("pos"), nb::arg("mats"),
        nb::arg("aabb"), nb::arg("rbound"), nb::arg("ids"), nb::arg("dist"), nb::arg("geom"),
        nb::arg("other"),
        "Cast rays from one point against primitive geoms, in place (see raycast.cpp).");
}
