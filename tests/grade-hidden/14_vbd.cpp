// Hidden grading tests for exercise ex14.1, one vertex's Newton step of Vertex Block Descent.
//
// This folder is the instructor's: the student release leaves it out, and the build compiles it
// into the grading binaries only when it is there. Like the visible tests, every expectation is
// derived beside its check and holds for any correct answer.
#include <cmath>
#include <vector>

#include "clothlab/integrators/vbd_vertex.hpp"
#include "grading.hpp"

using clothlab::Mat3;
using clothlab::Vec3;
using clothlab::VertexBlock;
using clothlab::VertexSpring;

namespace {

// A vertex of 0.25 kg (w = 4) at h = 0.05 s among three springs, each stretched (l > l0, so
// that no clamp is active and H is G_i's exact Hessian), without dampers.
const double w = 4.0, h = 0.05;
const Vec3 y(0.1, -0.2, 0.05);
const std::vector<VertexSpring> springs{
    {Vec3(1.2, 0.3, -0.4), Vec3(1.2, 0.3, -0.4), 80.0, 0.0, 0.9},
    {Vec3(-0.7, 0.9, 0.2), Vec3(-0.7, 0.9, 0.2), 150.0, 0.0, 0.6},
    {Vec3(0.2, -1.1, 0.8), Vec3(0.2, -1.1, 0.8), 40.0, 0.0, 1.0}};

// G_i, written from its definition: m/(2 h^2) |x - y|^2 + sum ks/2 (|x - x_j| - l0)^2.
double G(const Vec3& x) {
  double g = 0.5 / (w * h * h) * (x - y).squaredNorm();
  for (const VertexSpring& s : springs) {
    const double stretch = (x - s.x_j).norm() - s.l0;
    g += 0.5 * s.ks * stretch * stretch;
  }
  return g;
}

}  // namespace

TEST_SUITE("ex14") {
  TEST_CASE("ex14.1 hidden: f and H are the derivatives of G_i (finite differences)" * POINTS(1)) {
    // f = -grad G_i and H = -df/dx, each checked by central differences (step 1e-6 m: the
    // error is about 1e-12 of G's scale, far below the 1e-6 relative tolerance).
    const Vec3 x(0.05, 0.1, -0.1);
    const VertexBlock b = clothlab::vbd_vertex_block(x, x, y, w, h, springs);
    const double e = 1e-6;
    Vec3 grad;
    Mat3 jacobian;
    for (int a = 0; a < 3; ++a) {
      const Vec3 step = e * Vec3::Unit(a);
      grad(a) = (G(x + step) - G(x - step)) / (2.0 * e);
      jacobian.col(a) = -(clothlab::vbd_vertex_block(x + step, x + step, y, w, h, springs).f -
                          clothlab::vbd_vertex_block(x - step, x - step, y, w, h, springs).f) /
                        (2.0 * e);
    }
    INFO("three stretched springs and inertia: f must be -grad G_i = "
         << grading::show(-grad) << ", got " << grading::show(b.f)
         << "; H must be the derivative of -f, whose first column is "
         << grading::show(Vec3(jacobian.col(0))) << ", got " << grading::show(Vec3(b.H.col(0))));
    CHECK((b.f + grad).norm() <= 1e-6 * grad.norm());
    CHECK((b.H - jacobian).norm() <= 1e-6 * b.H.norm());
    CHECK((b.H - b.H.transpose()).norm() <= 1e-12 * b.H.norm());
  }

  TEST_CASE("ex14.1 hidden: the step depends on where the vertex is relative to the others" *
            POINTS(1)) {
    // Moving x_i, x_i,start, y_i and every x_j, x_j,start by the same (3, -5, 7) changes no
    // difference in G_i: the step is the same. (With dampers: the pair's motion is the same.)
    const Vec3 shift(3.0, -5.0, 7.0), x(0.05, 0.1, -0.1), start(0.0, 0.12, -0.08);
    std::vector<VertexSpring> damped = springs, moved;
    for (VertexSpring& s : damped)
      s.kd = 0.5;
    for (VertexSpring s : damped) {
      s.x_j += shift;
      s.x_j_start += shift;
      moved.push_back(s);
    }
    const Vec3 dx = clothlab::vbd_vertex_step(x, start, y, w, h, damped);
    const Vec3 dx_moved =
        clothlab::vbd_vertex_step(x + shift, start + shift, y + shift, w, h, moved);
    INFO("the same vertex and springs moved by (3, -5, 7) must take the same step: "
         << grading::show(dx) << " and " << grading::show(dx_moved));
    CHECK(dx.norm() > 0.0);
    CHECK_NEAR_VEC(dx_moved, dx, 1e-9 * dx.norm());
  }

  TEST_CASE("ex14.1 hidden: a stiff block is definite and takes its step" * POINTS(1)) {
    // A 1 g vertex (w = 1000) of a stiff rope, h = 1/60 s: m/h^2 = 3.6 N/m, against two springs
    // of ks = 1e6 N/m stretched 1 mm along x from both sides of x_i = 0 (ends at -1.001 and
    // +1.001, l0 = 1): their forces cancel, and y_i = (0, -1e-3, 0) pulls the vertex down,
    // f = -m/h^2 (x_i - y_i) = (0, -3.6e-3, 0). Across, each spring gives 1e6 (1 - 1/1.001) = 999
    // N/m, so H = diag(3.6 + 2e6, 3.6 + 1998, 3.6 + 1998): det / (trace/3)^3 is about 1e-6, far
    // above the guard's 1e-13. dx = (0, -3.6e-3 / 2001.6, 0) = (0, -1.7986e-6, 0).
    const double mh2 = 1.0 / (1000.0 * (1.0 / 60.0) * (1.0 / 60.0));
    const std::vector<VertexSpring> rope{
        {Vec3(-1.001, 0.0, 0.0), Vec3(-1.001, 0.0, 0.0), 1e6, 0.0, 1.0},
        {Vec3(1.001, 0.0, 0.0), Vec3(1.001, 0.0, 0.0), 1e6, 0.0, 1.0}};
    const Vec3 x = Vec3::Zero(), y_rope(0.0, -1e-3, 0.0);
    const Vec3 dx = clothlab::vbd_vertex_step(x, x, y_rope, 1000.0, 1.0 / 60.0, rope);
    const double across = mh2 + 2e6 * (1.0 - 1.0 / 1.001);
    const Vec3 expected(0.0, -mh2 * 1e-3 / across, 0.0);
    INFO(
        "a 1 g vertex between two springs of 1e6 N/m stretched 1 mm, pulled down by inertia: "
        "dx must be "
        << grading::show(expected) << ", got " << grading::show(dx)
        << " (a guard that judges det(H) without H's own scale skips this block)");
    CHECK_NEAR_VEC(dx, expected, 1e-6 * std::abs(expected.y()));
  }
}
