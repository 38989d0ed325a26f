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

    // The spring before the motion, worked by hand: r2 - r1 = (6, 2, -3), l = 7,
    // e = (6, 2, -3) / 7; ks = 30 N/m, l0 = 4.5 m: the spring gives -30 (4.5 - 7) = 75 N.
    // v1 - v2 = (3, 1, -1), e . (v1 - v2) = (18 + 2 + 3) / 7 = 23 / 7 m/s; kd = 0.7 N s/m: the
    // damper gives -0.7 * 23 / 7 = -2.3 N. f_sd = 72.7 N, f1 = 72.7 e = (72.7 / 7) (6, 2, -3).
    const Vec3 r1(0.5, 1.0, -1.0), r2(6.5, 3.0, -4.0), v1(2.0, 1.0, 0.0), v2(-1.0, 0.0, 1.0);
    const Vec3 f = clothlab::spring_damper_force(r1, r2, v1, v2, 30.0, 0.7, 4.5);
    const Vec3 moved =
        clothlab::spring_damper_force(R * r1 + t, R * r2 + t, R * v1, R * v2, 30.0, 0.7, 4.5);
    const Vec3 expected = (72.7 / 7.0) * Vec3(6.0, 2.0, -3.0);
    INFO(
        "the spring-damper force must not depend on where the spring is or which way it faces: "
        "use only r2 - r1 and the velocities projected on e; before the motion it is "
        "(72.7 / 7) (6, 2, -3) N, after it R times that");
    CHECK_NEAR_VEC(f, expected, 1e-9);
    CHECK_NEAR_VEC(moved, Vec3(R * expected), 1e-9);
  }

  TEST_CASE("ex02.1 hidden: the spring and the damper add" * POINTS_VISIBILITY(1, hidden)) {
    // f_sd = -ks (l0 - l) - kd (v1 - v2) is linear in (ks, kd): the force with both is the sum
    // of the force with the spring alone (kd = 0) and with the damper alone (ks = 0).
    // By hand: r2 - r1 = (0.2, -0.3, 0.6), l = 0.7, e = (2, -3, 6) / 7. The spring, ks = 3000
    // N/m, l0 = 0.5 m: -3000 (0.5 - 0.7) = 600 N, f = (600 / 7) (2, -3, 6). The damper,
    // kd = 4 N s/m: v1 - v2 = (-0.7, -3.7, 0.7), e . (v1 - v2) = (-1.4 + 11.1 + 4.2) / 7 =
    // 13.9 / 7 m/s, -4 * 13.9 / 7 = -55.6 / 7 N, f = -(55.6 / 49) (2, -3, 6).
    const Vec3 r1(1.0, 1.0, 1.0), r2(1.2, 0.7, 1.6), v1(0.0, -3.0, 0.5), v2(0.7, 0.7, -0.2);
    const Vec3 both = clothlab::spring_damper_force(r1, r2, v1, v2, 3000.0, 4.0, 0.5);
    const Vec3 spring = clothlab::spring_damper_force(r1, r2, v1, v2, 3000.0, 0.0, 0.5);
    const Vec3 damper = clothlab::spring_damper_force(r1, r2, v1, v2, 0.0, 4.0, 0.5);
    INFO(
        "with ks = 0 only the damper acts and with kd = 0 only the spring: the two must add up "
        "to the force with both, (600 / 7) (2, -3, 6) N and -(55.6 / 49) (2, -3, 6) N here");
    CHECK_NEAR_VEC(spring, Vec3((600.0 / 7.0) * Vec3(2.0, -3.0, 6.0)), 1e-9);
    CHECK_NEAR_VEC(damper, Vec3(-(55.6 / 49.0) * Vec3(2.0, -3.0, 6.0)), 1e-9);
    CHECK_NEAR_VEC(both, Vec3(spring + damper), 1e-9);
  }
}
