// Grading tests for lesson 07, integrators and accuracy (exercises ex07.1 and ex07.2).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. Each case steps a system whose motion is known by
// hand (a spring a = -w^2 x, a drag a = -c v, free fall a = g) and checks one step against the
// worked numbers, the states at which the step asks for the acceleration, or an invariant: the
// factor by which one step scales a spring's energy, and how fast the error falls with dt.
#include <cmath>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "clothlab/integrators/runge_kutta.hpp"
#include "grading.hpp"

using clothlab::AccelerationField;
using clothlab::Index;
using clothlab::Matrix3X;
using clothlab::RungeKuttaStages;
using clothlab::Vec3;

namespace {

// midpoint_step and rk4_step share this signature, so the helpers below work for both.
using Step = void (*)(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
                      RungeKuttaStages& stages);

// A 3 x n state, one column per particle, from its columns.
Matrix3X columns(std::initializer_list<Vec3> cols) {
  Matrix3X m(3, static_cast<Index>(cols.size()));
  Index k = 0;
  for (const Vec3& c : cols)
    m.col(k++) = c;
  return m;
}

// Stages sized for n particles, as the integrators hand them over, and filled with NaN: a step
// gets back whatever the previous step left there, so it must write a stage before it reads it.
RungeKuttaStages fresh_stages(Index n) {
  RungeKuttaStages stages;
  stages.resize(n);
  for (auto* stage : {&stages.x, &stages.v, &stages.a}) {
    for (Matrix3X& m : *stage)
      m.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  return stages;
}

// A spring to the origin for every particle: a = -w^2 x [m/s^2], with w^2 in [1/s^2].
AccelerationField spring(double w2) {
  return [w2](const Matrix3X& x, const Matrix3X&, Matrix3X& a) { a = -w2 * x; };
}

// A linear drag for every particle: a = -c v [m/s^2], with c in [1/s].
AccelerationField drag(double c) {
  return [c](const Matrix3X&, const Matrix3X& v, Matrix3X& a) { a = -c * v; };
}

// The same constant acceleration g [m/s^2] for every particle.
AccelerationField constant(const Vec3& g) {
  return [g](const Matrix3X& x, const Matrix3X&, Matrix3X& a) { a = g.replicate(1, x.cols()); };
}

// One call of accel during a step: the trial state it was given, the acceleration it returned,
// and whether the caller's x and v had already changed from the start of the step by then.
struct Call {
  Matrix3X x, v, a;
  bool x_changed, v_changed;
};

// Wraps field so that every call is recorded in calls. x and v are the matrices about to be
// stepped: their start values are kept, and they are watched while the step runs.
AccelerationField recording(const AccelerationField& field, const Matrix3X& x, const Matrix3X& v,
                            std::vector<Call>& calls) {
  return [field, &x, &v, x0 = Matrix3X(x), v0 = Matrix3X(v), &calls](
             const Matrix3X& xs, const Matrix3X& vs, Matrix3X& a) {
    field(xs, vs, a);
    calls.push_back({xs, vs, a, (x.array() != x0.array()).any(), (v.array() != v0.array()).any()});
  };
}

// True when two states agree within tol in every entry (and have the same size).
bool near(const Matrix3X& a, const Matrix3X& b, double tol) {
  return a.cols() == b.cols() && ((a - b).cwiseAbs().array() <= tol).all();
}

// "[(..), (..)]": the columns of a state, for a failed check.
std::string show(const Matrix3X& m) {
  std::ostringstream out;
  out << "[";
  for (Index k = 0; k < m.cols(); ++k)
    out << (k ? ", " : "") << grading::show(Vec3(m.col(k)));
  out << "]";
  return out.str();
}

// The positions x [m] and velocities v [m/s] of particles, one column per particle.
struct State {
  Matrix3X x, v;
};

// The state (x, v) after one step of dt [s] under accel, taken with fresh stages.
State after_one_step(Step step, Matrix3X x, Matrix3X v, double dt, const AccelerationField& accel) {
  RungeKuttaStages stages = fresh_stages(x.cols());
  step(x, v, dt, accel, stages);
  return {x, v};
}

// One step of dt [s] with every call of accel recorded, for the cases that check where a step
// asks for its accelerations. Two particles under a = -4 x - 0.5 v + (0, -9.8, 0): the
// acceleration depends on both x and v, so a trial state with the wrong position or the wrong
// velocity shows. Gives the start state (x0, v0), the state the step ended at (x, v) and the
// calls in order.
struct RecordedStep {
  Matrix3X x0, v0, x, v;
  std::vector<Call> calls;
};

RecordedStep record_one_step(Step step, double dt) {
  const Vec3 g(0.0, -9.8, 0.0);
  const AccelerationField field = [g](const Matrix3X& xs, const Matrix3X& vs, Matrix3X& a) {
    a = -4.0 * xs - 0.5 * vs;
    a.colwise() += g;
  };
  RecordedStep r;
  r.x0 = columns({Vec3(0.3, -1.2, 2.0), Vec3(-0.7, 0.4, 1.1)});
  r.v0 = columns({Vec3(1.5, -0.2, 0.9), Vec3(-0.4, 2.2, 0.1)});
  r.x = r.x0;
  r.v = r.v0;
  RungeKuttaStages stages = fresh_stages(2);
  step(r.x, r.v, dt, recording(field, r.x, r.v, r.calls), stages);
  return r;
}

// Three particles, each under its own acceleration: 0 on the spring a = -4 x, 1 pinned (inverse
// mass 0, so a = 0) and 2 under the drag a = -2 v.
AccelerationField spring_pinned_and_drag() {
  return [](const Matrix3X& xs, const Matrix3X& vs, Matrix3X& a) {
    a.resize(3, xs.cols());
    a.col(0) = -4.0 * xs.col(0);
    a.col(1).setZero();
    a.col(2) = -2.0 * vs.col(2);
  };
}

// The energy per unit mass of each particle on a spring to the origin,
// E_k = (|v_k|^2 + w_k^2 |x_k|^2) / 2 [J/kg].
std::vector<double> spring_energies(const Matrix3X& x, const Matrix3X& v,
                                    const std::vector<double>& w) {
  std::vector<double> e;
  for (Index k = 0; k < x.cols(); ++k) {
    const double wk = w[static_cast<size_t>(k)];
    e.push_back(0.5 * (v.col(k).squaredNorm() + wk * wk * x.col(k).squaredNorm()));
  }
  return e;
}

// The energies (spring_energies) of three particles before and after one step of dt [s], each
// on its own spring to the origin, a_k = -w_k^2 x_k, from a state with no zero component.
struct EnergyChange {
  std::vector<double> before, after;
};

EnergyChange spring_energies_over_one_step(Step step, const std::vector<double>& w, double dt) {
  const AccelerationField field = [&w](const Matrix3X& xs, const Matrix3X&, Matrix3X& a) {
    a.resize(3, xs.cols());
    for (Index k = 0; k < xs.cols(); ++k)
      a.col(k) = -w[static_cast<size_t>(k)] * w[static_cast<size_t>(k)] * xs.col(k);
  };
  const Matrix3X x = columns({Vec3(0.3, -1.2, 2.0), Vec3(-0.7, 0.4, 1.1), Vec3(1.0, 0.5, -0.25)});
  const Matrix3X v = columns({Vec3(1.5, -0.2, 0.9), Vec3(-0.4, 2.2, 0.1), Vec3(0.0, -3.0, 0.5)});
  const State end = after_one_step(step, x, v, dt, field);
  return {spring_energies(x, v, w), spring_energies(end.x, end.v, w)};
}

// The error after one period of a spring with w = 2 pi 1/s (period 1 s), started at x = 1 m at
// rest and stepped n times with dt = 1/n s. It should come back exactly to (x, v) = (1, 0); the
// error is the distance from there in the phase plane, sqrt(dx^2 + (dv / w)^2) [m].
double error_after_one_period(Step step, int n) {
  const double w = 2.0 * std::numbers::pi;
  Matrix3X x = columns({Vec3(1.0, 0.0, 0.0)});
  Matrix3X v = columns({Vec3::Zero()});
  RungeKuttaStages stages = fresh_stages(1);
  const AccelerationField accel = spring(w * w);
  for (int k = 0; k < n; ++k)
    step(x, v, 1.0 / n, accel, stages);
  const double dx = (x.col(0) - Vec3(1.0, 0.0, 0.0)).norm();
  const double dv = v.col(0).norm() / w;
  return std::sqrt(dx * dx + dv * dv);
}

// Checks a recorded trial state against the lesson's equations: `name` must be evaluated at
// x_expected, v_expected (the `equation`). On a failure it says what went wrong: x or v changed
// before the call, the start velocity v0 passed instead of a trial velocity, or the position
// x_slip that a common slip (slip_hint) would have passed.
void check_stage(const Call& call, const Matrix3X& x_expected, const Matrix3X& v_expected,
                 const Matrix3X& v0, const std::string& name, const std::string& equation,
                 const Matrix3X& x_slip, const std::string& slip_hint) {
  const bool x_right = near(call.x, x_expected, 1e-12);
  const bool v_right = near(call.v, v_expected, 1e-12);
  std::string hint = name + " must be evaluated at " + equation;
  if (call.x_changed || call.v_changed) {
    hint +=
        ". When accel was called here your x or v had already been changed: they must hold the "
        "start of the step until every stage is evaluated; build the trial states in stages.x "
        "and stages.v and update x and v only at the very end";
  } else if (!x_right && near(call.x, x_slip, 1e-12)) {
    hint += ". " + slip_hint;
  } else if (!v_right && near(call.v, v0, 1e-12)) {
    hint +=
        ". You passed the start velocity v: the acceleration may depend on the velocity (drag, "
        "dampers), so pass the trial velocity too";
  }
  INFO(hint, " (see lessons/07-integrators/README.md)");
  {
    INFO("accel got x = ", show(call.x), ", expected ", show(x_expected));
    CHECK(x_right);
  }
  {
    INFO("accel got v = ", show(call.v), ", expected ", show(v_expected));
    CHECK(v_right);
  }
}

}  // namespace

TEST_SUITE("ex07") {
  // --- Exercise ex07.1: the midpoint method ------------------------------------------------------

  TEST_CASE("ex07.1 one midpoint step of a spring worked by hand" * POINTS(2)) {
    // a = -w^2 x with w = 2 1/s, dt = 0.1 s, from x = 1 m, v = 0.5 m/s (along the x axis):
    //   a1 = -4 * 1 = -4
    //   x2 = x + dt/2 v = 1 + 0.05 * 0.5 = 1.025,   v2 = v + dt/2 a1 = 0.5 - 0.2 = 0.3
    //   a2 = -4 * 1.025 = -4.1
    //   x' = x + dt v2 = 1 + 0.03 = 1.03,          v' = v + dt a2 = 0.5 - 0.41 = 0.09
    // Symbolically, with y = w dt: x' = x (1 - y^2/2) + dt v, v' = v (1 - y^2/2) - w^2 dt x,
    // the exact solution's Taylor polynomial to second order.
    const auto [x, v] = after_one_step(clothlab::midpoint_step, columns({Vec3(1.0, 0.0, 0.0)}),
                                       columns({Vec3(0.5, 0.0, 0.0)}), 0.1, spring(4.0));
    // The usual slips, and the (x', v') each gives here, are worked out in slips.hpp
    // (kMidpointSpring): the report names the one an answer is, then the hint that holds
    // whatever the answer.
    INFO(grading::hint(Vec3(x(0, 0), v(0, 0), 0.0), grading::slips::kMidpointSpring, 1e-12,
                       "spring a = -4 x, dt = 0.1 s, from x = 1 m, v = 0.5 m/s: the midpoint "
                       "step gives x' = x + dt v2 = 1.03 m and v' = v + dt a2 = 0.09 m/s, with "
                       "v2 = 0.3 m/s and a2 = -4.1 m/s^2 taken at the half step (see "
                       "lessons/07-integrators/README.md)"));
    CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(1.03, 0.0, 0.0), 1e-12);
    CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(0.09, 0.0, 0.0), 1e-12);
  }

  TEST_CASE("ex07.1 accel is called at the start and at the half step" * POINTS(1)) {
    // Two particles under a = -4 x - 0.5 v + (0, -9.8, 0): the acceleration depends on both x
    // and v, so a trial state with the wrong position or the wrong velocity shows. dt = 0.05 s.
    // The lesson's midpoint step asks for exactly two accelerations:
    //   call 1 at (x, v), which returns a1,
    //   call 2 at (x + dt/2 v, v + dt/2 a1), which returns a2,
    // and then x' = x + dt v2, v' = v + dt a2 with v2 the velocity of call 2. Each is checked
    // against what the step itself passed and got back, so one wrong line fails one check.
    const double dt = 0.05;
    const auto [x0, v0, x, v, calls] = record_one_step(clothlab::midpoint_step, dt);
    {
      INFO(
          "midpoint_step must call accel exactly twice per step, once at the start and once at "
          "the half step; it was called ",
          calls.size(), " times (see lessons/07-integrators/README.md)");
      REQUIRE(calls.size() == 2);
    }
    const Call &c1 = calls[0], &c2 = calls[1];
    check_stage(c1, x0, v0, v0, "the first acceleration a1", "the start of the step, (x, v)", x0,
                "");
    check_stage(c2, x0 + 0.5 * dt * v0, v0 + 0.5 * dt * c1.a, v0, "the second acceleration a2",
                "the half step x2 = x + dt/2 v, v2 = v + dt/2 a1", x0 + dt * v0,
                "You passed the full Euler step x + dt v: the midpoint is half a step away");
    {
      const Matrix3X x_expected = x0 + dt * c2.v;
      const Matrix3X v_expected = v0 + dt * c2.a;
      std::string hint =
          "the step must end at x' = x + dt v2 and v' = v + dt a2, with v2 the trial velocity of "
          "the half step and a2 the acceleration found there (see "
          "lessons/07-integrators/README.md)";
      // x and v overwritten with the trial state end the step at x2 + dt v2.
      if (!near(x, x_expected, 1e-12) && near(x, c2.x + dt * c2.v, 1e-12)) {
        hint +=
            ". Your x' is a full step from the trial state x2, not from the start x: x was "
            "overwritten with the trial state. Keep x and v as the start of the step and build "
            "x2 and v2 in stages.x[1] and stages.v[1]";
      }
      INFO(hint);
      {
        INFO("got x' = ", show(x), ", expected ", show(x_expected));
        CHECK(near(x, x_expected, 1e-12));
      }
      {
        INFO("got v' = ", show(v), ", expected ", show(v_expected));
        CHECK(near(v, v_expected, 1e-12));
      }
    }
  }

  TEST_CASE("ex07.1 a drag a = -c v follows exp(-c dt) to second order" * POINTS(1)) {
    // a = -c v with c = 2 1/s, dt = 0.1 s, so z = c dt = 0.2. Exactly, v(t) = v e^(-c t).
    //   a1 = -c v,   v2 = v + dt/2 a1 = v (1 - z/2) = 0.9 v,   a2 = -c v2
    //   v' = v + dt a2 = v (1 - z + z^2/2) = v (1 - 0.2 + 0.02) = 0.82 v
    //        (e^(-z) = 1 - z + z^2/2 - ..., cut after z^2: second order)
    //   x' = x + dt v2 = x + 0.1 * 0.9 v = x + 0.09 v
    // From x = (1, 2, 3) m, v = (1, -2, 3) m/s: v' = (0.82, -1.64, 2.46), x' = (1.09, 1.82, 3.27).
    const auto [x, v] = after_one_step(clothlab::midpoint_step, columns({Vec3(1.0, 2.0, 3.0)}),
                                       columns({Vec3(1.0, -2.0, 3.0)}), 0.1, drag(2.0));
    INFO(
        "drag a = -2 v, dt = 0.1 s: the midpoint step scales v by 1 - z + z^2/2 = 0.82 (z = "
        "c dt = 0.2, the Taylor polynomial of e^(-z)) and moves x by dt v2 = 0.09 v. v' = 0.8 v "
        "means the second acceleration was taken with the start velocity v instead of the "
        "trial velocity v2 = v + dt/2 a1 (see lessons/07-integrators/README.md)");
    CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(0.82, -1.64, 2.46), 1e-12);
    CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(1.09, 1.82, 3.27), 1e-12);
  }

  TEST_CASE("ex07.1 free fall is exact in one step of any size" * POINTS(1)) {
    // a = g constant: a1 = a2 = g, v2 = v + dt/2 g,
    //   x' = x + dt v2 = x + v dt + g dt^2/2,   v' = v + g dt:
    // the exact parabola, whatever dt. g = (0, -9.8, 0), dt = 0.5 s, x = (0, 10, 0) m,
    // v = (2, 0, -1) m/s: x' = (1, 10 - 9.8 * 0.125, -0.5) = (1, 8.775, -0.5), v' = (2, -4.9, -1).
    const auto [x, v] =
        after_one_step(clothlab::midpoint_step, columns({Vec3(0.0, 10.0, 0.0)}),
                       columns({Vec3(2.0, 0.0, -1.0)}), 0.5, constant(Vec3(0.0, -9.8, 0.0)));
    INFO(
        "under constant gravity the midpoint method is exact: x' = x + v dt + g dt^2/2 = "
        "(1, 8.775, -0.5) m after 0.5 s. y = 10 m means x moved with the start velocity v "
        "(Euler), y = 7.55 m means with the end velocity v' (see "
        "lessons/07-integrators/README.md)");
    CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(1.0, 8.775, -0.5), 1e-12);
    CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(2.0, -4.9, -1.0), 1e-12);
  }

  TEST_CASE("ex07.1 one step multiplies a spring's energy by 1 + (w dt)^4 / 4" * POINTS(1)) {
    // a = -w^2 x; in the units p = x, q = v / w one midpoint step is, with y = w dt,
    //   p' = (1 - y^2/2) p + y q,   q' = -y p + (1 - y^2/2) q
    // (from the hand-worked case above). The matrix [[c, y], [-y, c]] with c = 1 - y^2/2 scales
    // every vector's length squared by c^2 + y^2 = 1 + y^4/4, so the energy
    // E = (v^2 + w^2 x^2)/2 = w^2 (p^2 + q^2)/2 grows by exactly 1 + y^4/4 each step, from any
    // state, in each component. dt = 0.5 s and three particles with w = 1, 2, 4 1/s:
    // y = 0.5, 1, 2 give 65/64, 5/4 and 5. (Euler would give 1 + y^2 = 1.25, 2, 5.)
    const std::vector<double> w = {1.0, 2.0, 4.0};
    const std::vector<double> factor = {65.0 / 64.0, 5.0 / 4.0, 5.0};
    const auto [e0, e1] = spring_energies_over_one_step(clothlab::midpoint_step, w, 0.5);
    for (size_t k = 0; k < w.size(); ++k) {
      const double y = w[k] * 0.5;
      CAPTURE(y);
      INFO("particle ", k, ": energy ", e0[k], " J/kg before the step, ", e1[k], " J/kg after");
      INFO(
          "one midpoint step of an undamped spring must multiply its energy by exactly "
          "1 + y^4/4 with y = w dt; a different factor means a coefficient of the step is off, "
          "even if the step looks right (see lessons/07-integrators/README.md)");
      CHECK(e1[k] / e0[k] == doctest::Approx(factor[k]).epsilon(1e-12));
    }
  }

  TEST_CASE("ex07.1 halving dt cuts the error four times" * POINTS(1)) {
    // The midpoint method is second order: one step errs by O(dt^3), the n = T/dt steps of a
    // fixed time T by O(dt^2). Over one period of a spring (w = 2 pi, T = 1 s), 25 steps
    // (dt = 0.04 s, y = w dt = 0.25) err by about T w y^2 / 6 = 0.065 m; 50 steps by a quarter
    // of that. The ratio tends to 4 as dt -> 0; at these steps it is within 1 % of 4. A first
    // order method gives about 2, a right-looking step with a wrong weight usually 2 or less.
    const double coarse = error_after_one_period(clothlab::midpoint_step, 25);
    const double fine = error_after_one_period(clothlab::midpoint_step, 50);
    const double ratio = coarse / fine;
    CAPTURE(coarse);
    CAPTURE(fine);
    CAPTURE(ratio);
    INFO(
        "over one period of a spring the error with dt = 0.04 s must be about 4 times the "
        "error with dt = 0.02 s: the midpoint method is second order (see "
        "lessons/07-integrators/README.md)");
    CHECK(ratio > 3.8);
    CHECK(ratio < 4.2);
  }

  TEST_CASE("ex07.1 particles move independently and a pinned one stays put" * POINTS(1)) {
    // Three particles, each under its own acceleration, stepped together with dt = 0.1 s:
    //   0: the spring a = -4 x from x = (1, 0, 0), v = (0.5, 0, 0): as worked by hand above,
    //      x' = (1.03, 0, 0), v' = (0.09, 0, 0);
    //   1: pinned (inverse mass 0, so a = 0) and at rest at (5, 5, 5): x' = x, v' = 0;
    //   2: the drag a = -2 v from x = (1, 2, 3), v = (1, -2, 3): as above, x' = x + 0.09 v =
    //      (1.09, 1.82, 3.27), v' = 0.82 v = (0.82, -1.64, 2.46).
    const auto [x, v] =
        after_one_step(clothlab::midpoint_step,
                       columns({Vec3(1.0, 0.0, 0.0), Vec3(5.0, 5.0, 5.0), Vec3(1.0, 2.0, 3.0)}),
                       columns({Vec3(0.5, 0.0, 0.0), Vec3::Zero(), Vec3(1.0, -2.0, 3.0)}), 0.1,
                       spring_pinned_and_drag());
    INFO(
        "every column of x and v is one particle and moves only by its own acceleration: step "
        "whole matrices (x + 0.5 * dt * v), not just the first column (see "
        "lessons/07-integrators/README.md)");
    {
      INFO("particle 0 on the spring a = -4 x, as in the hand-worked case");
      CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(1.03, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(0.09, 0.0, 0.0), 1e-12);
    }
    {
      INFO("particle 1 is pinned: its acceleration is 0 and it is at rest, so it must not move");
      CHECK_NEAR_VEC(Vec3(x.col(1)), Vec3(5.0, 5.0, 5.0), 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(1)), Vec3::Zero(), 1e-12);
    }
    {
      INFO("particle 2 under the drag a = -2 v, as in the drag case");
      CHECK_NEAR_VEC(Vec3(x.col(2)), Vec3(1.09, 1.82, 3.27), 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(2)), Vec3(0.82, -1.64, 2.46), 1e-12);
    }
  }

  // --- Exercise ex07.2: classical Runge-Kutta (RK4) ----------------------------------------------

  TEST_CASE("ex07.2 one RK4 step of a spring worked by hand" * POINTS(2)) {
    // a = -w^2 x with w = 2 1/s, dt = 0.1 s, from x = 1 m, v = 0.5 m/s (along the x axis):
    //   stage 1: x1 = 1,                      v1 = 0.5,                  a1 = -4
    //   stage 2: x2 = 1 + 0.05 * 0.5 = 1.025,   v2 = 0.5 - 0.05 * 4 = 0.3,     a2 = -4.1
    //   stage 3: x3 = 1 + 0.05 * 0.3 = 1.015,   v3 = 0.5 - 0.05 * 4.1 = 0.295, a3 = -4.06
    //   stage 4: x4 = 1 + 0.1 * 0.295 = 1.0295, v4 = 0.5 - 0.1 * 4.06 = 0.094, a4 = -4.118
    //   x' = 1 + 0.1/6 (0.5 + 0.6 + 0.59 + 0.094) = 1 + 0.1784/6 = 7723/7500 = 1.0297333...
    //   v' = 0.5 + 0.1/6 (-4 - 8.2 - 8.12 - 4.118) = 0.5 - 2.4438/6 = 0.0927
    // Symbolically, with y = w dt = 0.2: x' = x (1 - y^2/2 + y^4/24) + dt v (1 - y^2/6), the
    // Taylor polynomial of the exact x(t) = cos(2t) + 0.25 sin(2t) = 1.029734 to fourth order.
    const auto [x, v] = after_one_step(clothlab::rk4_step, columns({Vec3(1.0, 0.0, 0.0)}),
                                       columns({Vec3(0.5, 0.0, 0.0)}), 0.1, spring(4.0));
    // The usual slips, and the (x', v') each gives here, are worked out in slips.hpp
    // (kRk4Spring).
    INFO(grading::hint(Vec3(x(0, 0), v(0, 0), 0.0), grading::slips::kRk4Spring, 1e-12,
                       "spring a = -4 x, dt = 0.1 s, from x = 1 m, v = 0.5 m/s: the RK4 step "
                       "gives x' = 1.0297333 m and v' = 0.0927 m/s (stage velocities 0.5, 0.3, "
                       "0.295, 0.094 and accelerations -4, -4.1, -4.06, -4.118, averaged with "
                       "weights (1, 2, 2, 1)/6: see lessons/07-integrators/README.md)"));
    CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(7723.0 / 7500.0, 0.0, 0.0), 1e-12);
    CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(0.0927, 0.0, 0.0), 1e-12);
  }

  TEST_CASE("ex07.2 accel is called at the four stages of the lecture" * POINTS(1)) {
    // Two particles under a = -4 x - 0.5 v + (0, -9.8, 0), dt = 0.05 s, as in ex07.1. RK4 asks
    // for exactly four accelerations, each at a trial step from the START (x, v) of the step
    // using the rates of the stage before:
    //   call 1 at (x, v)                        -> a1
    //   call 2 at (x + dt/2 v1, v + dt/2 a1)    -> a2
    //   call 3 at (x + dt/2 v2, v + dt/2 a2)    -> a3
    //   call 4 at (x + dt v3,   v + dt a3)      -> a4
    // and then x' = x + dt/6 (v1 + 2 v2 + 2 v3 + v4), v' = v + dt/6 (a1 + 2 a2 + 2 a3 + a4),
    // with vk the velocity of call k. Each is checked against what the step itself passed and
    // got back, so one wrong line fails one check.
    const double dt = 0.05;
    const auto [x0, v0, x, v, calls] = record_one_step(clothlab::rk4_step, dt);
    {
      INFO("rk4_step must call accel exactly four times per step, once per stage; it was called ",
           calls.size(), " times (see lessons/07-integrators/README.md)");
      REQUIRE(calls.size() == 4);
    }
    check_stage(calls[0], x0, v0, v0, "stage 1", "the start of the step, (x, v)", x0, "");
    // Stage k + 1 (k = 1, 2, 3) steps dt/2, dt/2, dt from the start with the rates of stage k.
    // The usual slip takes the same step from stage k's position instead.
    const double fraction[] = {0.0, 0.5, 0.5, 1.0};
    const char* equation[] = {"", "x2 = x + dt/2 v1, v2 = v + dt/2 a1",
                              "x3 = x + dt/2 v2, v3 = v + dt/2 a2",
                              "x4 = x + dt v3, v4 = v + dt a3"};
    for (size_t k = 1; k < 4; ++k) {
      const Call& before = calls[k - 1];
      const double h = fraction[k] * dt;
      check_stage(calls[k], x0 + h * before.v, v0 + h * before.a, v0,
                  "stage " + std::to_string(k + 1), equation[k], before.x + h * before.v,
                  "You built it from the previous stage's position; every stage starts from x, "
                  "the start of the step, and only takes the previous stage's rates");
    }
    {
      const Matrix3X x_expected =
          x0 + (dt / 6.0) * (calls[0].v + 2.0 * calls[1].v + 2.0 * calls[2].v + calls[3].v);
      const Matrix3X v_expected =
          v0 + (dt / 6.0) * (calls[0].a + 2.0 * calls[1].a + 2.0 * calls[2].a + calls[3].a);
      std::string hint =
          "the step must end at x' = x + dt/6 (v1 + 2 v2 + 2 v3 + v4) and v' = v + dt/6 (a1 + 2 "
          "a2 + 2 a3 + a4), the stage velocities and accelerations weighted (1, 2, 2, 1)/6: x' "
          "averages the stage velocities exactly as v' averages the stage accelerations (see "
          "lessons/07-integrators/README.md)";
      // Equal weights 1/4 are the usual slip.
      const Matrix3X v_equal =
          v0 + (dt / 4.0) * (calls[0].a + calls[1].a + calls[2].a + calls[3].a);
      if (!near(v, v_expected, 1e-12) && near(v, v_equal, 1e-12)) {
        hint += ". Your step weights the four stages equally, 1/4 each: the middle two count twice";
      }
      INFO(hint);
      {
        INFO("got x' = ", show(x), ", expected ", show(x_expected));
        CHECK(near(x, x_expected, 1e-12));
      }
      {
        INFO("got v' = ", show(v), ", expected ", show(v_expected));
        CHECK(near(v, v_expected, 1e-12));
      }
    }
  }

  TEST_CASE("ex07.2 a drag a = -c v follows exp(-c dt) to fourth order" * POINTS(1)) {
    // a = -c v with c = 2 1/s, dt = 0.1 s, z = c dt = 0.2. Every stage velocity is v times a
    // polynomial in z:
    //   v1 = v,  v2 = v (1 - z/2),  v3 = v (1 - z/2 + z^2/4),  v4 = v (1 - z + z^2/2 - z^3/4)
    //   v' = v + dt/6 (a1 + 2 a2 + 2 a3 + a4) = v - z/6 (v1 + 2 v2 + 2 v3 + v4)
    //      = v - z/6 v (6 - 3 z + z^2 - z^3/4) = v (1 - z + z^2/2 - z^3/6 + z^4/24),
    //        e^(-z) cut after z^4: 1 - 1/5 + 1/50 - 1/750 + 1/15000 = 12281/15000 = 0.8187333
    //   x' = x + dt/6 (v1 + 2 v2 + 2 v3 + v4) = x + dt v (1 - z/2 + z^2/6 - z^3/24)
    //        = x + 0.1 v * 2719/3000 = x + (2719/30000) v
    // From x = (1, 2, 3) m and v = (1, -2, 3) m/s.
    const Vec3 x0(1.0, 2.0, 3.0), v0(1.0, -2.0, 3.0);
    const auto [x, v] =
        after_one_step(clothlab::rk4_step, columns({x0}), columns({v0}), 0.1, drag(2.0));
    INFO(
        "drag a = -2 v, dt = 0.1 s: the RK4 step scales v by 1 - z + z^2/2 - z^3/6 + z^4/24 = "
        "0.8187333 (z = c dt = 0.2, the Taylor polynomial of e^(-z)) and moves x by "
        "0.0906333 v. A different v' means a stage took the wrong trial velocity: each one is "
        "v + (dt/2 or dt) times the acceleration of the stage before (see "
        "lessons/07-integrators/README.md)");
    CHECK_NEAR_VEC(Vec3(v.col(0)), (12281.0 / 15000.0) * v0, 1e-12);
    CHECK_NEAR_VEC(Vec3(x.col(0)), x0 + (2719.0 / 30000.0) * v0, 1e-12);
  }

  TEST_CASE("ex07.2 free fall is exact in one step of any size" * POINTS(1)) {
    // a = g constant: a1 = a2 = a3 = a4 = g and v1 = v, v2 = v3 = v + dt/2 g, v4 = v + dt g:
    //   x' = x + dt/6 (6 v + 2 dt g + dt g) = x + v dt + g dt^2/2,   v' = v + g dt:
    // the exact parabola. Same numbers as ex07.1: g = (0, -9.8, 0), dt = 0.5 s,
    // x = (0, 10, 0) m, v = (2, 0, -1) m/s give x' = (1, 8.775, -0.5), v' = (2, -4.9, -1).
    const auto [x, v] =
        after_one_step(clothlab::rk4_step, columns({Vec3(0.0, 10.0, 0.0)}),
                       columns({Vec3(2.0, 0.0, -1.0)}), 0.5, constant(Vec3(0.0, -9.8, 0.0)));
    INFO(
        "under constant gravity RK4 is exact: x' = x + v dt + g dt^2/2 = (1, 8.775, -0.5) m "
        "after 0.5 s; x' averages the stage velocities v1..v4 with weights (1, 2, 2, 1)/6 "
        "(see lessons/07-integrators/README.md)");
    CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(1.0, 8.775, -0.5), 1e-12);
    CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(2.0, -4.9, -1.0), 1e-12);
  }

  TEST_CASE("ex07.2 one step multiplies a spring's energy by 1 - y^6/72 + y^8/576" * POINTS(1)) {
    // a = -w^2 x, y = w dt. In the units p = x, q = v / w a step of RK4 multiplies p + i q by
    // the Taylor polynomial of e^(-i y) to fourth order, R = 1 - i y - y^2/2 + i y^3/6 + y^4/24,
    // so the energy w^2 (p^2 + q^2)/2 is multiplied by |R|^2 = (1 - y^2/2 + y^4/24)^2 +
    // (y - y^3/6)^2 = 1 - y^2 + y^4/3 - y^6/24 + y^8/576 + y^2 - y^4/3 + y^6/36
    //               = 1 - y^6/72 + y^8/576,
    // from any state. dt = 0.5 s and three particles with w = 1, 2, 4 1/s: y = 0.5, 1, 2 give
    // 147425/147456, 569/576 and 5/9: RK4 loses a little energy each step, the more the larger dt.
    const std::vector<double> w = {1.0, 2.0, 4.0};
    const std::vector<double> factor = {147425.0 / 147456.0, 569.0 / 576.0, 5.0 / 9.0};
    const auto [e0, e1] = spring_energies_over_one_step(clothlab::rk4_step, w, 0.5);
    for (size_t k = 0; k < w.size(); ++k) {
      const double y = w[k] * 0.5;
      CAPTURE(y);
      INFO("particle ", k, ": energy ", e0[k], " J/kg before the step, ", e1[k], " J/kg after");
      INFO(
          "one RK4 step of an undamped spring must multiply its energy by exactly "
          "1 - y^6/72 + y^8/576 with y = w dt; a different factor means a weight or a stage of "
          "the step is off, even if the step looks right (see lessons/07-integrators/README.md)");
      CHECK(e1[k] / e0[k] == doctest::Approx(factor[k]).epsilon(1e-12));
    }
  }

  TEST_CASE("ex07.2 halving dt cuts the error sixteen times" * POINTS(1)) {
    // RK4 is fourth order: one step errs by O(dt^5), the n = T/dt steps of a fixed time T by
    // O(dt^4). Over one period of a spring (w = 2 pi, T = 1 s), 25 steps (dt = 0.04 s,
    // y = w dt = 0.25) err by about T w y^4 / 120 = 2e-4 m; 50 steps by a sixteenth of that,
    // still far above rounding. The ratio tends to 16 as dt -> 0; at these steps it is within
    // 1 % of 16. Equal weights 1/4, or a stage taken from the wrong state, give about 4 or 2.
    const double coarse = error_after_one_period(clothlab::rk4_step, 25);
    const double fine = error_after_one_period(clothlab::rk4_step, 50);
    const double ratio = coarse / fine;
    CAPTURE(coarse);
    CAPTURE(fine);
    CAPTURE(ratio);
    INFO(
        "over one period of a spring the error with dt = 0.04 s must be about 16 times the "
        "error with dt = 0.02 s: RK4 is fourth order (see lessons/07-integrators/README.md)");
    CHECK(ratio > 15.0);
    CHECK(ratio < 17.0);
  }

  TEST_CASE("ex07.2 particles move independently and a pinned one stays put" * POINTS(1)) {
    // Three particles, each under its own acceleration, stepped together with dt = 0.1 s:
    //   0: the spring a = -4 x from x = (1, 0, 0), v = (0.5, 0, 0): as worked by hand above,
    //      x' = (7723/7500, 0, 0), v' = (0.0927, 0, 0);
    //   1: pinned (inverse mass 0, so a = 0) and at rest at (5, 5, 5): x' = x, v' = 0;
    //   2: the drag a = -2 v from x = (1, 2, 3), v = (1, -2, 3): as above,
    //      x' = x + (2719/30000) v, v' = (12281/15000) v.
    const Vec3 x2(1.0, 2.0, 3.0), v2(1.0, -2.0, 3.0);
    const auto [x, v] = after_one_step(
        clothlab::rk4_step, columns({Vec3(1.0, 0.0, 0.0), Vec3(5.0, 5.0, 5.0), x2}),
        columns({Vec3(0.5, 0.0, 0.0), Vec3::Zero(), v2}), 0.1, spring_pinned_and_drag());
    INFO(
        "every column of x and v is one particle and moves only by its own acceleration: step "
        "whole matrices, not just the first column (see lessons/07-integrators/README.md)");
    {
      INFO("particle 0 on the spring a = -4 x, as in the hand-worked case");
      CHECK_NEAR_VEC(Vec3(x.col(0)), Vec3(7723.0 / 7500.0, 0.0, 0.0), 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(0)), Vec3(0.0927, 0.0, 0.0), 1e-12);
    }
    {
      INFO("particle 1 is pinned: its acceleration is 0 and it is at rest, so it must not move");
      CHECK_NEAR_VEC(Vec3(x.col(1)), Vec3(5.0, 5.0, 5.0), 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(1)), Vec3::Zero(), 1e-12);
    }
    {
      INFO("particle 2 under the drag a = -2 v, as in the drag case");
      CHECK_NEAR_VEC(Vec3(x.col(2)), x2 + (2719.0 / 30000.0) * v2, 1e-12);
      CHECK_NEAR_VEC(Vec3(v.col(2)), (12281.0 / 15000.0) * v2, 1e-12);
    }
  }

}  // TEST_SUITE("ex07")
