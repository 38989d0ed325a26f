// keyframes.hpp: a vector given at a few times, linear in time between them (a moving pin's
// path, a gust of wind).
//
// Keyframes (t_k, y_k) with t_0 < t_1 < ...: for t_k <= t < t_{k+1},
//   y(t) = y_k + (t - t_k) / (t_{k+1} - t_k) (y_{k+1} - y_k),
//   dy/dt = (y_{k+1} - y_k) / (t_{k+1} - t_k).
// Before t_0 it holds y_0, from the last time on the last value; there dy/dt = 0.
#pragma once

#include <algorithm>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab {

struct Keyframes {
  std::vector<double> t;  // the times [s], increasing
  std::vector<Vec3> y;    // the value at each time

  bool empty() const { return t.empty(); }

  // The segment [t_k, t_{k+1}) holding `time`: k, or -1 before t_0, or the last k after it.
  long segment(double time) const {
    return static_cast<long>(std::upper_bound(t.begin(), t.end(), time) - t.begin()) - 1;
  }

  Vec3 at(double time) const {
    const long k = segment(time);
    if (k < 0) return y.front();
    if (k + 1 >= static_cast<long>(t.size())) return y.back();
    const double s = (time - t[k]) / (t[k + 1] - t[k]);  // 0 at t_k, 1 at t_{k+1}
    return y[k] + s * (y[k + 1] - y[k]);
  }

  Vec3 rate(double time) const {  // dy/dt [per s]
    const long k = segment(time);
    if (k < 0 || k + 1 >= static_cast<long>(t.size())) return Vec3::Zero();
    return (y[k + 1] - y[k]) / (t[k + 1] - t[k]);
  }
};

}  // namespace clothlab
