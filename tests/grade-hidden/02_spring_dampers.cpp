// Hidden grading tests for exercise ex02.1, the spring-damper force.
//
// This folder is the instructor's: the student release leaves it out, and the build compiles it
// into the grading binaries only when it is there. Gradescope shows these cases once the due
// date has passed ("after_due_date"), or never (POINTS_VISIBILITY(n, hidden)). Like the visible
// tests, every expectation is derived beside its check and holds for any correct answer.
#include <array>
#include <cmath>

#include "clothlab/forces/spring_damper.hpp"
#include "grading.hpp"

using clothlab::Mat3;
using clothlab::Vec3;

TEST_SUITE("ex02") {
  TEST_CASE("ex02.1 hidden: moving and turning the whole spring turns its force with it" *
            POINTS(2)) {
    // The force depends only on r2 - r1 and v1, v2 through dot products with e, so a rigid
    // motion of the scene (translate positions by t, rotate everything by R) gives
    // f1(R r1 + t, R r2 + t, R v1, R v2) = R f1(r1, r2, v1, v2).
    // R: 30 degrees about the axis (1, 2, 2) / 3, from Rodrigues' formula.
    const double angle = M_PI / 6.0;
    const Vec3 axis = Vec3(1.0, 2.0, 2.0) / 3.0;
    Mat3 k;
    k << 0.0, -axis.z(), axis.y(), axis.z(), 0.0, -axis.x(), -axis.y(), axis.x(), 0.0;
    const Mat3 R = Mat3::Identity() + std::sin(angle) * k + (1.0 - std::cos(angle)) * k * k;
    const Vec3 t(5.0, -2.0, 0.5);

    const Vec3 r1(0.3, -1.2, 2.0), r2(-0.7, 0.4, 1.1), v1(1.5, -0.2, 0.9), v2(-0.4, 2.2, 0.1);
    const Vec3 f = clothlab::spring_damper_force(r1, r2, v1, v2, 120.0, 1.5, 0.8);
    const Vec3 moved =
        clothlab::spring_damper_force(R * r1 + t, R * r2 + t, R * v1, R * v2, 120.0, 1.5, 0.8);
    INFO(
        "the spring-damper force must not depend on where the spring is or which way it faces: "
        "use only r2 - r1 and the velocities projected on e");
    CHECK_NEAR_VEC(moved, Vec3(R * f), 1e-9);
  }

  TEST_CASE("ex02.1 hidden: the spring and the damper add" * POINTS_VISIBILITY(1, hidden)) {
    // f_sd = -ks (l0 - l) - kd (v1 - v2) is linear in (ks, kd): the force with both is the sum
    // of the force with the spring alone (kd = 0) and with the damper alone (ks = 0).
    const Vec3 r1(1.0, 1.0, 1.0), r2(1.05, 0.98, 1.2), v1(0.0, -3.0, 0.5), v2(0.7, 0.7, -0.2);
    const Vec3 both = clothlab::spring_damper_force(r1, r2, v1, v2, 3000.0, 4.0, 0.1);
    const Vec3 spring = clothlab::spring_damper_force(r1, r2, v1, v2, 3000.0, 0.0, 0.1);
    const Vec3 damper = clothlab::spring_damper_force(r1, r2, v1, v2, 0.0, 4.0, 0.1);
    INFO(
        "with ks = 0 only the damper acts and with kd = 0 only the spring: the two must add up "
        "to the force with both");
    CHECK_NEAR_VEC(both, Vec3(spring + damper), 1e-9);
  }
}
