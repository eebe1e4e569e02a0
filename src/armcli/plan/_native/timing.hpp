// Time parameterisation of a polyline (timing.cpp).

#pragma once

#include <vector>

#include "core.hpp"

namespace armcli_plan {

struct TimingLimits {
  Vec velocity, acceleration;  // (n,) [rad/s, rad/s²], already scaled by the margin
  Vec effort;                  // (n,) [N·m or N] or empty: no torque constraint
  std::vector<int> iv;         // v index of each planned joint (its torque)
};

struct Timed {
  Vec times;  // (P,) [s]
  RMat positions, velocities, accelerations;  // (P, n)
  int failed_segment = -1;  // TOPP-RA found no motion along this segment (else -1)
};

// Each segment of W (rows: waypoints) timed from rest to rest on a grid of `grid` intervals,
// the whole motion sampled at `rate` [Hz]. With `blend` > 0 and a Work `w`, each corner is
// first rounded (see timing.cpp) where the rounding is free by w's planner check at `step`,
// and the motion stops only at the corners that could not be rounded.
Timed time_polyline(const Scene& s, const RMat& W, const TimingLimits& lim, int grid,
                    double rate, Work* w = nullptr, double blend = 0.0, double step = 0.02);

// Velocities and accelerations at the knots of the clamped (zero end slopes) C² cubic spline.
void spline(const Vec& t, const RMat& y, RMat& v, RMat& a);

}  // namespace armcli_plan
