// Grading tests for lesson 14, Vertex Block Descent (exercise ex14.1, one vertex's Newton step).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. For vertex i at x_i (at x_i,start when the step
// began), with y_i where inertia carries it, m_i / h^2 = 1 / (w_i h^2), and for each spring
// d = x_i - x_j, l = |d|, u = d / l, S = u u^T + max(0, 1 - l0/l) (I - u u^T):
//   f = -m_i/h^2 (x_i - y_i) + sum [ -ks (l - l0) u - (kd/h) S (dx_i - dx_j) ]
//   H =  m_i/h^2 I           + sum [ ks S + (kd/h) S ]
//   dx = H^-1 f;   dx = 0 for a pinned vertex (w_i = 0) and for a singular H.
// The numbers are chosen so that every value is a short decimal: most cases take m_i = 1 kg
// (w_i = 1) and h = 0.1 s, so that m_i / h^2 = 100 N/m.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "clothlab/integrators/vbd_vertex.hpp"
#include "grading.hpp"

using clothlab::Mat3;
using clothlab::Vec3;
using clothlab::VertexBlock;
using clothlab::VertexSpring;

namespace {

// A spring to an other end that has not moved in this step.
VertexSpring spring_to(const Vec3& x_j, double ks, double l0, double kd = 0.0) {
  return {x_j, x_j, ks, kd, l0};
}

std::string show(const Mat3& a) {
  std::ostringstream out;
  out.precision(10);
  out << "[";
  for (int r = 0; r < 3; ++r)
    out << (r ? "; " : "") << a(r, 0) << ", " << a(r, 1) << ", " << a(r, 2);
  return out.str() + "]";
}

Mat3 diag(double a, double b, double c) {
  return Vec3(a, b, c).asDiagonal();
}

// One vertex as the kernel sees it: at x_i now, at x_i,start when the step began (x_i unless
// given), carried to y_i by inertia, with inverse mass w_i, the step h and its springs.
struct Vertex {
  Vec3 x_i, y_i;
  double w_i, h;
  std::vector<VertexSpring> springs;
  Vec3 x_i_start = x_i;
};

// Checks the kernel's f, H and dx for `v` against the values worked out by hand, and on failure
// says what the vertex was (`given`), what was expected, what came back, and `hint`, after the
// slip the step dx is, if it is one of `slips` (worked out in slips.hpp).
void check_vertex(const std::string& given, const Vertex& v, const Vec3& f, const Mat3& H,
                  const Vec3& dx, const std::string& hint = "",
                  std::initializer_list<grading::Slip> slips = {}) {
  const VertexBlock b =
      clothlab::vbd_vertex_block(v.x_i, v.x_i_start, v.y_i, v.w_i, v.h, v.springs);
  const Vec3 step = clothlab::vbd_vertex_step(v.x_i, v.x_i_start, v.y_i, v.w_i, v.h, v.springs);
  std::ostringstream said;
  said << given << ": f must be " << grading::show(f) << ", H = " << show(H)
       << ", dx = " << grading::show(dx) << "; got f = " << grading::show(b.f)
       << ", H = " << show(b.H) << ", dx = " << grading::show(step) << hint;
  INFO(grading::hint(step, slips, 1e-12 * std::max(1.0, dx.norm()), said.str()));
  const double scale = H.cwiseAbs().maxCoeff();
  CHECK_NEAR_VEC(b.f, f, 1e-10 * std::max(1.0, f.norm()));
  CHECK(((b.H - H).cwiseAbs().array() <= 1e-10 * scale).all());
  CHECK_NEAR_VEC(step, dx, 1e-12 * std::max(1.0, dx.norm()));
}

}  // namespace

TEST_SUITE("ex14") {
  TEST_CASE("ex14.1 a vertex at rest where inertia carries it does not move" * POINTS(1)) {
    // m = 2 kg (w_i = 0.5), h = 0.1 s: m/h^2 = 200 N/m. x_i = y_i = (1, 0, 0) on one spring of
    // ks = 50 N/m at its rest length l0 = 1 from x_j = 0: u = (1, 0, 0), l - l0 = 0, so f = 0;
    // S = u u^T (1 - l0/l = 0), so H = 200 I + 50 diag(1, 0, 0) = diag(250, 200, 200); dx = 0.
    const Vec3 x(1.0, 0.0, 0.0);
    check_vertex(
        "m = 2 kg, h = 0.1 s, x_i = y_i = (1, 0, 0), one spring of ks = 50 N/m at its rest "
        "length from (0, 0, 0) (m/h^2 = 200 N/m on H's diagonal, ks along the spring)",
        {x, x, 0.5, 0.1, {spring_to(Vec3::Zero(), 50.0, 1.0)}}, Vec3::Zero(),
        diag(250.0, 200.0, 200.0), Vec3::Zero());
  }

  TEST_CASE("ex14.1 inertia alone: one Newton step lands on y" * POINTS(1)) {
    // No springs, m = 1 kg, h = 0.1 s: G_i = 100/2 |x_i - y_i|^2. x_i = 0, y_i = (0, -0.01, 0):
    // f = -100 (x_i - y_i) = (0, -1, 0) N, H = 100 I, dx = (0, -0.01, 0): exactly onto y_i.
    check_vertex(
        "m = 1 kg, h = 0.1 s, no springs, x_i = 0, y_i = (0, -0.01, 0): f = -m/h^2 (x_i - y_i), "
        "H = m/h^2 I, and the step lands on y_i",
        {Vec3::Zero(), Vec3(0.0, -0.01, 0.0), 1.0, 0.1, {}}, Vec3(0.0, -1.0, 0.0),
        100.0 * Mat3::Identity(), Vec3(0.0, -0.01, 0.0),
        ". An H of zero here means the inertia term is missing from H");
  }

  TEST_CASE("ex14.1 one stretched spring worked by hand" * POINTS(2)) {
    // x_i = (1.5, 0, 0) = y_i, x_j = 0, ks = 100 N/m, l0 = 1 m, m/h^2 = 100 N/m. l = 1.5,
    // u = (1, 0, 0): f = -100 (0.5) u = (-50, 0, 0) N. Across the spring 1 - l0/l = 1/3:
    // H = 100 I + 100 diag(1, 1/3, 1/3) = diag(200, 133.33, 133.33). dx = (-50/200, 0, 0)
    // = (-0.25, 0, 0): pulled back toward x_j, a quarter of the way, not all the way (inertia).
    const Vec3 x(1.5, 0.0, 0.0);
    check_vertex(
        "x_i = y_i = (1.5, 0, 0), x_j = 0, ks = 100 N/m, l0 = 1 m, m/h^2 = 100 N/m (ks along "
        "the spring, ks (1 - l0/l) across it, plus m/h^2)",
        {x, x, 1.0, 0.1, {spring_to(Vec3::Zero(), 100.0, 1.0)}}, Vec3(-50.0, 0.0, 0.0),
        diag(200.0, 100.0 + 100.0 / 3.0, 100.0 + 100.0 / 3.0), Vec3(-0.25, 0.0, 0.0),
        ". A dx of (+0.25, 0, 0) pushes the vertex away: check the signs of f and H",
        grading::slips::kVbdStretched);
  }

  TEST_CASE("ex14.1 two springs at a right angle add their forces and stiffnesses" * POINTS(2)) {
    // x_i = 0 = y_i, springs to (-2, 0, 0) and (0, -2, 0), each ks = 100 N/m, l0 = 1 m, so
    // l = 2 and 1 - l0/l = 0.5; u = (1, 0, 0) and (0, 1, 0). Forces (-100, 0, 0) and
    // (0, -100, 0); Hessians 100 diag(1, 0.5, 0.5) and 100 diag(0.5, 1, 0.5). With m/h^2 = 100:
    // f = (-100, -100, 0), H = diag(250, 250, 200), dx = (-0.4, -0.4, 0).
    check_vertex(
        "x_i = y_i = 0, springs of ks = 100 N/m, l0 = 1 m to (-2, 0, 0) and (0, -2, 0), "
        "m/h^2 = 100 N/m",
        {Vec3::Zero(),
         Vec3::Zero(),
         1.0,
         0.1,
         {spring_to(Vec3(-2.0, 0.0, 0.0), 100.0, 1.0),
          spring_to(Vec3(0.0, -2.0, 0.0), 100.0, 1.0)}},
        Vec3(-100.0, -100.0, 0.0), diag(250.0, 250.0, 200.0), Vec3(-0.4, -0.4, 0.0));
  }

  TEST_CASE("ex14.1 a compressed spring's Hessian is made definite" * POINTS(2)) {
    // m = 0.5 kg (w_i = 2), h = 0.1 s: m/h^2 = 50 N/m. x_i = (0.5, 0, 0), x_j = 0, ks = 100 N/m,
    // l0 = 1 m: l = 0.5, u = (1, 0, 0), f_spring = -100 (-0.5) u = (50, 0, 0), pushing apart.
    // Across: 1 - l0/l = -1, clamped to 0, so H = 50 I + 100 diag(1, 0, 0) = diag(150, 50, 50).
    // (Unclamped it would be diag(150, -50, -50): indefinite.) y_i = x_i + (0, 0.1, 0) adds
    // the inertia force -50 (x_i - y_i) = (0, 5, 0): f = (50, 5, 0), dx = (1/3, 0.1, 0), toward
    // y_i sideways. With the unclamped H the sideways step is 5 / -50 = -0.1, away from y_i.
    check_vertex(
        "x_i = (0.5, 0, 0), y_i = (0.5, 0.1, 0), x_j = 0, ks = 100 N/m, l0 = 1 m (squeezed to "
        "half), m/h^2 = 50 N/m: the factor 1 - l0/l = -1 across the spring is clamped at 0",
        {Vec3(0.5, 0.0, 0.0), Vec3(0.5, 0.1, 0.0), 2.0, 0.1, {spring_to(Vec3::Zero(), 100.0, 1.0)}},
        Vec3(50.0, 5.0, 0.0), diag(150.0, 50.0, 50.0), Vec3(1.0 / 3.0, 0.1, 0.0),
        ". An H of diag(150, -50, -50) and a dx with y = -0.1 (away from y_i) is the unclamped "
        "Hessian: a compressed spring must not make H indefinite",
        grading::slips::kVbdSqueezed);
  }

  TEST_CASE("ex14.1 the damper acts on the pair's motion over the step" * POINTS(2)) {
    // x_j = 0 (not moved), x_i = (1, 0, 0) = y_i, which was at (0.9, 0, 0) when the step began:
    // dx_i = (0.1, 0, 0). ks = 100 N/m at its rest length l0 = 1 (no spring force, S = u u^T =
    // diag(1, 0, 0)), kd = 2 N s/m, h = 0.1 s, m/h^2 = 100 N/m:
    //   f = -(kd/h) S dx_i = -20 (0.1, 0, 0) = (-2, 0, 0)
    //   H = 100 I + 100 S + 20 S = diag(220, 100, 100),   dx = (-2/220, 0, 0) = (-1/110, 0, 0).
    // Moved with the vertex (x_j,start = (-0.1, 0, 0)), the other end leaves no relative motion:
    // f = 0, the same H, dx = 0.
    const Vec3 x(1.0, 0.0, 0.0), start(0.9, 0.0, 0.0);
    check_vertex(
        "x_i = y_i = (1, 0, 0), moved from (0.9, 0, 0) this step, one spring at its rest length "
        "to x_j = 0 with ks = 100 N/m, kd = 2 N s/m, h = 0.1 s, m = 1 kg",
        {x, x, 1.0, 0.1, {{Vec3::Zero(), Vec3::Zero(), 100.0, 2.0, 1.0}}, start},
        Vec3(-2.0, 0.0, 0.0), diag(220.0, 100.0, 100.0), Vec3(-1.0 / 110.0, 0.0, 0.0), "",
        grading::slips::kVbdDamper);
    check_vertex(
        "the same, with x_j moved by the same (0.1, 0, 0) from (-0.1, 0, 0): no relative motion",
        {x, x, 1.0, 0.1, {{Vec3::Zero(), Vec3(-0.1, 0.0, 0.0), 100.0, 2.0, 1.0}}, start},
        Vec3::Zero(), diag(220.0, 100.0, 100.0), Vec3::Zero(),
        ". The damper acts on dx_i - dx_j, the pair's relative motion over the step");
  }

  TEST_CASE("ex14.1 a pinned vertex never moves" * POINTS(1)) {
    // w_i = 0: a pin, whatever pulls on it. x_i = 0 on a spring of ks = 1000 N/m, l0 = 1 m,
    // stretched to x_j = (2, 0, 0), with y_i = (0, -1, 0): the pinned vertex's step is exactly 0.
    // The same vertex free (w_i = 1, h = 0.1 s, m/h^2 = 100 N/m): u = (-1, 0, 0), so
    // f = -1000 (2 - 1) u + 100 (y_i - x_i) = (1000, -100, 0),
    // H = 100 I + 1000 diag(1, 0.5, 0.5) = diag(1100, 600, 600), dx = (10/11, -1/6, 0).
    const std::vector<VertexSpring> springs{spring_to(Vec3(2.0, 0.0, 0.0), 1000.0, 1.0)};
    const Vec3 y(0.0, -1.0, 0.0);
    const Vec3 pinned = clothlab::vbd_vertex_step(Vec3::Zero(), Vec3::Zero(), y, 0.0, 0.1, springs);
    INFO(
        "x_i = 0, a spring of ks = 1000 N/m, l0 = 1 m to (2, 0, 0), y_i = (0, -1, 0), pinned "
        "(w_i = 0): dx must be exactly 0, got "
        << grading::show(pinned));
    CHECK(pinned == Vec3::Zero());
    check_vertex("the same vertex free (w_i = 1, h = 0.1 s)", {Vec3::Zero(), y, 1.0, 0.1, springs},
                 Vec3(1000.0, -100.0, 0.0), diag(1100.0, 600.0, 600.0),
                 Vec3(10.0 / 11.0, -1.0 / 6.0, 0.0));
  }

  TEST_CASE("ex14.1 a block that would be singular is skipped and never gives NaN" * POINTS(1)) {
    // A massless vertex (w_i infinite, so m/h^2 = 0: no inertia term, and no NaN from it) at 0
    // with springs of ks = 100 N/m at their rest length 1 m to (-1, 0, 0) and (0, -1, 0):
    // f = 0 and H = 100 diag(1, 1, 0), singular (nothing resists z). The step is 0.
    // Stretched to 2 m instead, both springs stiffen across (1 - l0/l = 0.5): H = 100
    // diag(1.5, 1.5, 1), definite, f = (-100, -100, 0), and dx = (-2/3, -2/3, 0).
    const double massless = std::numeric_limits<double>::infinity();
    check_vertex(
        "a massless vertex (w_i = inf) at 0 with springs of ks = 100 N/m at their rest length "
        "1 m to (-1, 0, 0) and (0, -1, 0): H is singular and the guard skips the step",
        {Vec3::Zero(),
         Vec3::Zero(),
         massless,
         0.1,
         {spring_to(Vec3(-1.0, 0.0, 0.0), 100.0, 1.0),
          spring_to(Vec3(0.0, -1.0, 0.0), 100.0, 1.0)}},
        Vec3::Zero(), diag(100.0, 100.0, 0.0), Vec3::Zero(),
        ". A NaN step means the guard on a singular block is missing");
    check_vertex(
        "the same vertex with both springs stretched to 2 m: H is definite, the step is taken",
        {Vec3::Zero(),
         Vec3::Zero(),
         massless,
         0.1,
         {spring_to(Vec3(-2.0, 0.0, 0.0), 100.0, 1.0),
          spring_to(Vec3(0.0, -2.0, 0.0), 100.0, 1.0)}},
        Vec3(-100.0, -100.0, 0.0), diag(150.0, 150.0, 100.0), Vec3(-2.0 / 3.0, -2.0 / 3.0, 0.0));
  }
}
