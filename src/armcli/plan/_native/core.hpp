// armcli.plan._planner: the planner's collision loop, compiled (see armcli.plan.native).
//
// `Scene` is the robot (Pinocchio model and collision geometry, as Python built them and
// serialised them with Pinocchio's own binary format) plus the scene objects and the ground,
// the pairs to check, and the map from the planned joints' values x to Pinocchio's q. `Work`
// is one thread's scratch: kinematics data, world placements and one coal query object per
// pair. Everything the Python checker (plan/collision.py) decides, this decides the same way:
// a pair collides when coal says so with the pair's security margin; pairs are culled only
// when their world boxes are farther apart than that margin (so never one coal would report).

#pragma once

#include <Eigen/Core>
#include <atomic>
#include <coal/collision.h>
#include <coal/distance.h>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pinocchio/geometry.hpp"
#include "pinocchio/multibody.hpp"

namespace armcli_plan {

namespace pin = pinocchio;
using Vec = Eigen::VectorXd;
using Vec3 = Eigen::Vector3d;
using RMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A 1-DoF joint of the model whose angle [rad or m] is affine in x: offset + coeff . x.
struct MapEntry {
  int joint = 0;            // Pinocchio joint id
  int iq = 0, iv = 0;       // its index in q and v
  bool continuous = false;  // q holds (cos, sin) of the angle
  double offset = 0.0;
  Vec coeff;  // (n,)
};

// A pair of geometries to check; `moving`: some planned joint changes their relative pose.
struct Pair {
  int a = 0, b = 0;
  bool moving = true;
  double margin = 0.0;  // the planner's security margin [m] (plan.collision.PADDING or 0)
};

// An axis-aligned box: centre and half extents; unbounded (a half-space) is never culled.
struct Box {
  Vec3 c = Vec3::Zero(), h = Vec3::Zero();
  bool bounded = true;
};

// An oriented box: rotation (its axes as columns), centre and half extents.
struct Obb {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Vec3 c = Vec3::Zero(), e = Vec3::Zero();
};

// Whether the boxes are farther apart than `margin` (the separating-axis test, 15 axes).
bool obb_apart(const Obb& a, const Obb& b, double margin);

enum Mode { PLANNER = 0, EXACT_MOVING = 1, EXACT_ALL = 2 };

// The moving pairs between two bodies (links, scene objects): culled together when the
// bodies' boxes (each the union of its geometries' boxes) are apart.
struct BodyPair {
  int a = 0, b = 0;
  std::vector<int> pairs;  // indices into Scene::pairs, in order
};

class Scene {
 public:
  Scene(const std::string& model_bytes, const std::string& geom_bytes, const Vec& q_template,
        std::vector<MapEntry> map, std::vector<Pair> pairs, std::vector<int> body,
        const Vec& lower, const Vec& upper);

  void q_of(const double* x, Vec& q) const;  // planned joint values -> configuration

  pin::Model model;
  pin::GeometryModel geom;
  Vec q_template, lower, upper;
  std::vector<MapEntry> map;
  std::vector<Pair> pairs;
  std::vector<char> geom_moves;  // moved by a planned joint
  std::vector<int> body;         // each geometry's body
  std::vector<std::vector<int>> body_geoms;
  std::vector<char> body_moves;
  std::vector<BodyPair> body_pairs;  // those with a moving pair
  std::vector<Box> local;        // each geometry's box in its own frame
  std::vector<Obb> local_obb;    // and its oriented box (a mesh's: its BVH's root box)
  std::vector<std::shared_ptr<coal::CollisionGeometry>> hull;  // a mesh's convex hull
  Eigen::MatrixXd lever;         // (ngeoms, n) [m per rad or m/m]: see certify.cpp
  Eigen::MatrixXd pair_lever;    // (npairs, n): the same for the pair's relative motion
  double max_margin = 0.0;       // the largest pair margin (set_margins keeps it)
  int n = 0;

 private:
  void bound_levers();
};

// One thread's scratch space over a Scene.
class Work {
 public:
  explicit Work(const Scene& s);

  void place(const double* x);                 // kinematics; placements when asked for
  void ready(int g);                           // geometry g's placement and boxes
  void ready_body(int b);                      // body b's geometries and box
  bool pair_hits(int p, double margin);        // cull, then coal with `margin`
  int first_hit(const double* x, Mode mode);   // first colliding pair in order, or -1
  bool free(const double* x);                  // the planner's check (last hit first)
  bool motion_free(const double* a, const double* b, double step);
  double pair_distance(int p);                 // lower bound [m] at the current placement
  void body_box(int b);                        // the union of its geometries' world boxes

  const Scene& s;
  pin::Data data;
  std::vector<coal::Transform3s> tf;
  std::vector<Box> world, body_world;
  std::vector<Obb> world_obb;
  std::vector<coal::ComputeCollision> collide;
  std::vector<std::unique_ptr<coal::ComputeCollision>> hull_collide;  // null: no hull
  std::vector<std::unique_ptr<coal::ComputeDistance>> hull_distance;
  std::vector<coal::ComputeDistance> distance;
  std::vector<coal::CollisionRequest> request;
  Vec q, x_tmp;
  std::vector<std::vector<int>> orders;  // bisection_order(n), kept by n
  std::vector<unsigned> stamp, body_stamp;  // the `version` each placement was computed at
  unsigned version = 1;
  int last_hit = -1;
  long states = 0;  // state checks done (statistics)
  long queries = 0;  // coal queries made (statistics)
};

// Order of the interior and end points of a segment cut into n steps: the end first, then
// the midpoints of ever smaller intervals (as OMPL's discrete motion validator checks).
std::vector<int> bisection_order(int n);

// -- the planner (rrt.cpp) -------------------------------------------------------------------

struct PlanOptions {
  double range = 1.0;       // [rad] longest tree extension (Euclidean in x)
  double goal_bias = 0.05;  // probability of growing toward the other tree's root
  double step = 0.02;       // [rad or m] collision-check step along an edge (max norm)
  double timeout = 1.0;     // [s] wall clock for the whole search
  uint64_t seed = 0;
  int threads = 1;          // searches run at once (attempts are still taken in order)
  long attempt_nodes = 20000;  // nodes per attempt before the next seed takes over
  double bridge = 0.0;      // probability of a bridge-test target (narrow passages)
  double bridge_sigma = 0.3;  // [rad] spread of a bridge's second end
  double lazy_step = 0.0;   // [rad] > step: edges grown at this step, the path's at `step`
};

struct PlanStats {
  int attempt = -1;  // which attempt's path was taken (-1: none)
  long states = 0;   // state checks over every attempt
  long nodes = 0;
  bool timed_out = false;
};

// A collision-free polyline (rows: waypoints) or an empty matrix.
RMat rrt_connect(const Scene& s, const Vec& start, const Vec& goal,
                            const PlanOptions& o, PlanStats& stats);

// A shorter path with the same ends: greedy pass, then seeded random shortcuts, then greedy.
RMat shortcut(Work& w, const RMat& path, double step, uint64_t seed,
                         int tries, int patience);

// -- certification (certify.cpp) -------------------------------------------------------------

struct SweepResult {
  long sample = -1;  // first sample in collision, or -1
  int pair = -1;
  long queries = 0;  // coal queries made
  long bounds = 0;   // pair distance bounds taken (box gaps or coal distances)
};

// Every sample X.row(k) checked exactly (all pairs at the first, moving pairs after).
SweepResult sweep(Work& w, const double* X, long rows);

// Torques of the joints `iv` (v indices) at planned values x, velocities xd, accelerations
// xdd: RNEA, mimic followers moving with their leaders; q, v, a are scratch.
void inverse_dynamics(const Scene& s, pin::Data& data, const double* x, const double* xd,
                      const double* xdd, const std::vector<int>& iv, Vec& q, Vec& v, Vec& a,
                      double* tau);

}  // namespace armcli_plan
