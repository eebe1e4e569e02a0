// armcli.sim._raycast: a depth camera's rays cast against MuJoCo's primitive geoms.
//
// mj_multiRay tests every ray against every geom; a 160 x 120 depth image is 19,200 rays and
// cost 3-6x a drive's 100 physics steps. A pinhole's rays leave one point through a regular
// grid, so each geom is tested only on the pixels its bounding sphere projects onto (a z-buffer
// over geoms). The ray of pixel (u, v) is o + t (x_n, y_n, 1) in the optical frame, so t is
// the depth along the optical axis itself; a pixel keeps the first surface crossing with
// near <= t <= far (from inside a shape: its exit, as MuJoCo's rays see it).
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

// Pixels [u0, u1) x [v0, v1) a sphere (centre c in the optical frame, radius rb) covers.
void footprint(const Camera& cam, const double* c, double rb, int* box4) {
  box4[0] = 0, box4[1] = cam.width, box4[2] = 0, box4[3] = cam.height;
  const double z = c[2] - rb;
  if (z <= 1e-9) return;  // the camera is in (or level with) the sphere: every pixel
  const double lo[2] = {c[0] - rb, c[1] - rb}, hi[2] = {c[0] + rb, c[1] + rb};
  const double f[2] = {cam.fx, cam.fy}, ctr[2] = {cam.cx, cam.cy};
  const int n[2] = {cam.width, cam.height};
  for (int a = 0; a < 2; ++a) {  // x / z over z in [z, z + 2 rb] is extreme at an end
    const double small = std::min(lo[a] / z, lo[a] / (c[2] + rb));
    const double large = std::max(hi[a] / z, hi[a] / (c[2] + rb));
    box4[2 * a] = std::max(0, static_cast<int>(std::floor(ctr[a] + f[a] * small)));
    box4[2 * a + 1] = std::min(n[a], static_cast<int>(std::ceil(ctr[a] + f[a] * large)) + 1);
  }
}

void cast_geom(const Camera& cam, int type, const double* size, const double* pos,
               const double* mat, double* depth, int32_t* geom, uint8_t* other, int id,
               double rbound) {
  double rel[3], c[3];
  for (int i = 0; i < 3; ++i) rel[i] = pos[i] - cam.o[i];
  for (int i = 0; i < 3; ++i)
    c[i] = cam.R[i] * rel[0] + cam.R[3 + i] * rel[1] + cam.R[6 + i] * rel[2];
  int fp[4] = {0, cam.width, 0, cam.height};
  if (type != PLANE) {
    if (c[2] + rbound < cam.near) return;  // behind the near plane
    footprint(cam, c, rbound, fp);
  }
  if (!cast_here(type)) {
    for (int v = fp[2]; v < fp[3]; ++v)
      for (int u = fp[0]; u < fp[1]; ++u) other[v * cam.width + u] = 1;
    return;
  }
  Ray r;
  double M[9];  // optical -> geom: mat^T R, columns the optical axes in the geom frame
  for (int i = 0; i < 3; ++i) {
    r.o[i] = -(mat[i] * rel[0] + mat[3 + i] * rel[1] + mat[6 + i] * rel[2]);
    for (int j = 0; j < 3; ++j)
      M[3 * i + j] = mat[i] * cam.R[j] + mat[3 + i] * cam.R[3 + j] + mat[6 + i] * cam.R[6 + j];
  }
  for (int v = fp[2]; v < fp[3]; ++v) {
    const double yn = (v - cam.cy) / cam.fy;
    for (int u = fp[0]; u < fp[1]; ++u) {
      const double xn = (u - cam.cx) / cam.fx;
      for (int i = 0; i < 3; ++i) r.d[i] = M[3 * i] * xn + M[3 * i + 1] * yn + M[3 * i + 2];
      const int p = v * cam.width + u;
      const double t = hit(type, r, size, cam.near);
      if (t <= cam.far && t < depth[p]) depth[p] = t, geom[p] = id;
    }
  }
}

// Depth [m] (+inf: nothing between near and far), the geom hit (-1), pixels left to MuJoCo.
void cast_pinhole(In<double> origin, In<double> R, double fx, double fy, double cx, double cy,
                       int width, int height, double near, double far, In<int32_t> types,
                       In<double> sizes, In<double> pos, In<double> mats, In<double> rbound,
                       In<int32_t> ids, Out<double> depth, Out<int32_t> geom, Out<uint8_t> other) {
  Camera cam{};
  std::copy_n(origin.data(), 3, cam.o);
  std::copy_n(R.data(), 9, cam.R);
  cam.fx = fx, cam.fy = fy, cam.cx = cx, cam.cy = cy, cam.near = near, cam.far = far;
  cam.width = width, cam.height = height;
  const size_t n = types.size(), pixels = static_cast<size_t>(width) * height;
  if (sizes.size() != 3 * n || pos.size() != 3 * n || mats.size() != 9 * n ||
      rbound.size() != n || ids.size() != n || depth.size() != pixels || geom.size() != pixels ||
      other.size() != pixels)
    throw std::invalid_argument("cast_pinhole: array sizes disagree");
  {
    nb::gil_scoped_release release;
    std::fill_n(depth.data(), pixels, INF);
    std::fill_n(geom.data(), pixels, -1);
    std::fill_n(other.data(), pixels, 0);
    for (size_t g = 0; g < n; ++g)
      cast_geom(cam, types.data()[g], sizes.data() + 3 * g, pos.data() + 3 * g,
                mats.data() + 9 * g, depth.data(), geom.data(), other.data(), ids.data()[g],
                rbound.data()[g]);
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
        nb::arg("mats"), nb::arg("rbound"), nb::arg("ids"), nb::arg("depth"), nb::arg("geom"),
        nb::arg("other"),
        "Cast a pinhole's rays against primitive geoms, in place (see raycast.cpp).");
}
