// Grading tests for lesson 02, spring-dampers (exercises ex02.1 and ex02.2).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. Each case calls its exercise's kernel and checks it
// against a hand-worked number, a limit case or an invariant (equal and opposite forces, force
// along the spring, a damper that only takes energy out, the force as the slope of the energy).
#include <array>
#include <cmath>
#include <sstream>
#include <string>

#include "clothlab/forces/spring_damper.hpp"
#include "grading.hpp"

using clothlab::Vec3;

namespace {

// One spring-damper with its state, for the cases that check an invariant on several inputs.
struct SpringCase {
  Vec3 r1, r2;  // positions [m]
  Vec3 v1, v2;  // velocities [m/s]
  double ks;    // spring constant [N/m]
  double kd;    // damping factor [N s/m]
  double l0;    // rest length [m]
};

// Fixed, "random-looking" inputs: no axis-aligned springs, velocities with components both along
// and across the spring, one spring stretched, one stiff and short, one compressed.
const std::array<SpringCase, 3> kSprings = {{
    {Vec3(0.3, -1.2, 2.0), Vec3(-0.7, 0.4, 1.1), Vec3(1.5, -0.2, 0.9), Vec3(-0.4, 2.2, 0.1), 120.0,
     1.5, 0.8},
    {Vec3(1.0, 1.0, 1.0), Vec3(1.05, 0.98, 1.2), Vec3(0.0, -3.0, 0.5), Vec3(0.7, 0.7, -0.2), 3000.0,
     4.0, 0.1},
    {Vec3(-2.0, 0.5, 0.25), Vec3(3.0, -1.0, 0.75), Vec3(10.0, 0.0, 0.0), Vec3(-10.0, 0.0, 0.0),
     10.0, 0.2, 6.0},
}};

// "r1 = (..), r2 = (..), v1 = (..), v2 = (..), ks = .., kd = .., l0 = ..": names the input of a
// failed check.
std::string describe(const SpringCase& s) {
  std::ostringstream out;
  out << "spring r1 = " << grading::show(s.r1) << ", r2 = " << grading::show(s.r2)
      << ", v1 = " << grading::show(s.v1) << ", v2 = " << grading::show(s.v2) << ", ks = " << s.ks
      << " N/m, kd = " << s.kd << " N s/m, l0 = " << s.l0 << " m";
  return out.str();
}

// Central finite-difference gradient of a scalar function of one point:
// dU/dx_k ~ (U(r + h u_k) - U(r - h u_k)) / (2 h), with an error of order h^2.
template <class Energy>
Vec3 central_gradient(const Energy& energy, const Vec3& r, double h) {
  Vec3 g;
  for (int k = 0; k < 3; ++k) {
    Vec3 plus = r, minus = r;
    plus[k] += h;
    minus[k] -= h;
    g[k] = (energy(plus) - energy(minus)) / (2.0 * h);
  }
  return g;
}

}  // namespace

TEST_SUITE("ex02") {
  // --- Exercise ex02.1: the spring-damper force --------------------------------------------------

  TEST_CASE("ex02.1 a stretched spring pulls and a compressed one pushes" * POINTS(1)) {
    // r1 = (1, 2, 3), r2 = r1 + (2, -3, 6): e* = (2, -3, 6), l = sqrt(4 + 9 + 36) = 7,
    // e = (2, -3, 6) / 7. Both particles at rest, so the damper adds nothing.
    const Vec3 r1(1.0, 2.0, 3.0), r2(3.0, -1.0, 9.0);
    {
      // Stretched, l0 = 5: f_sd = -ks (l0 - l) = -14 (5 - 7) = 28 N,
      // f1 = 28 e = 4 (2, -3, 6) = (8, -12, 24) N: along +e, toward particle 2.
      const Vec3 f1 =
          clothlab::spring_damper_force(r1, r2, Vec3::Zero(), Vec3::Zero(), 14.0, 0.3, 5.0);
      // The usual slips, and what each gives here, are worked out in slips.hpp
      // (kStretchedSpring): the report names the one an answer is, then the hint that holds
      // whatever the answer.
      INFO(grading::hint(f1, grading::slips::kStretchedSpring, 1e-9, grading::slips::kStretched));
      CHECK_NEAR_VEC(f1, Vec3(8.0, -12.0, 24.0), 1e-9);
    }
    {
      // Compressed, l0 = 9: f_sd = -14 (9 - 7) = -28 N, f1 = -28 e = (-8, 12, -24) N: away
      // from particle 2.
      const Vec3 f1 =
          clothlab::spring_damper_force(r1, r2, Vec3::Zero(), Vec3::Zero(), 14.0, 0.3, 9.0);
      INFO(
          "a spring compressed 2 m below its rest length pushes particle 1 away from particle 2 "
          "with 28 N: use the signed stretch l - l0, not its absolute value");
      CHECK_NEAR_VEC(f1, Vec3(-8.0, 12.0, -24.0), 1e-9);
    }
  }

  TEST_CASE("ex02.1 the damper resists only the motion along the spring" * POINTS(1)) {
    // r1 = 0, r2 = (2, 0, 0): l = 2 = l0, so the spring is silent and only the damper acts;
    // e = (1, 0, 0).
    const Vec3 r1 = Vec3::Zero(), r2(2.0, 0.0, 0.0);
    {
      // Closing in: v1 = (3, 5, 0), v2 = (-1, 0, 7). Along e: v1 = 3, v2 = -1 m/s (the y and z
      // components are across the spring and do not count).
      // f_sd = -kd (v1 - v2) = -0.5 (3 - (-1)) = -2 N, f1 = (-2, 0, 0): particle 1 is pushed
      // back, away from particle 2, against the closing motion.
      const Vec3 f1 = clothlab::spring_damper_force(r1, r2, Vec3(3.0, 5.0, 0.0),
                                                    Vec3(-1.0, 0.0, 7.0), 50.0, 0.5, 2.0);
      INFO(
          "the damper sees only the velocities along e (v1 = e . v1, v2 = e . v2): its force is "
          "-kd (v1 - v2) e. A force with y or z components means the whole velocity vectors were "
          "used instead of their projections; a force toward particle 2 means the damper's sign "
          "is flipped");
      CHECK_NEAR_VEC(f1, Vec3(-2.0, 0.0, 0.0), 1e-12);
    }
    {
      // Both ends moving with the same velocity (a rigid motion): v1 - v2 = 0, no damping.
      const Vec3 w(0.4, -3.0, 1.7);
      const Vec3 f1 = clothlab::spring_damper_force(r1, r2, w, w, 50.0, 0.5, 2.0);
      INFO("a spring at rest length moving as a whole (v1 == v2) feels no force at all");
      CHECK_NEAR_VEC(f1, Vec3::Zero(), 1e-12);
    }
    {
      // Spring and damper add. Back to the 3D spring of the first case: r2 - r1 = (2, -3, 6),
      // l = 7, ks = 14, l0 = 5 gives a spring force of +28 N along e. Particle 1 moves toward
      // particle 2 at v1 = (2, -3, 6) = 7 e m/s, particle 2 is still: v1 - v2 = 7 along e,
      // damper -kd 7 = -0.5 * 7 = -3.5 N. f_sd = 28 - 3.5 = 24.5 N,
      // f1 = 24.5 e = 3.5 (2, -3, 6) = (7, -10.5, 21) N.
      const Vec3 f1 =
          clothlab::spring_damper_force(Vec3(1.0, 2.0, 3.0), Vec3(3.0, -1.0, 9.0),
                                        Vec3(2.0, -3.0, 6.0), Vec3::Zero(), 14.0, 0.5, 5.0);
      INFO(
          "f_sd = -ks (l0 - l) - kd (v1 - v2): the spring's 28 N and the damper's -3.5 N add to "
          "24.5 N along e");
      CHECK_NEAR_VEC(f1, Vec3(7.0, -10.5, 21.0), 1e-9);
    }
  }

  TEST_CASE("ex02.1 the forces on the two ends are equal and opposite and along the spring" *
            POINTS(1)) {
    // Swapping the two particles flips e (e' = -e) and swaps the projected velocities, which
    // leaves f_sd unchanged, so the force on particle 2, f2 = f_sd (-e), is minus f1: Newton's
    // third law, and the spring's internal forces sum to zero. f1 = f_sd e is parallel to e, so
    // f1 x e = 0 (no torque on the pair: angular momentum is kept too).
    for (const SpringCase& s : kSprings) {
      INFO(describe(s));
      const Vec3 f1 = clothlab::spring_damper_force(s.r1, s.r2, s.v1, s.v2, s.ks, s.kd, s.l0);
      const Vec3 f2 = clothlab::spring_damper_force(s.r2, s.r1, s.v2, s.v1, s.ks, s.kd, s.l0);
      const Vec3 e = (s.r2 - s.r1).normalized();
      const double tol = 1e-9 * (1.0 + f1.norm());
      // And its size along e: f_sd = -ks (l0 - l) - kd e . (v1 - v2).
      const double f_sd = -s.ks * (s.l0 - (s.r2 - s.r1).norm()) - s.kd * e.dot(s.v1 - s.v2);
      {
        INFO(
            "calling spring_damper_force with the particles swapped must give minus the force: "
            "f2 = -f1, so the internal forces of a spring sum to zero");
        CHECK_NEAR_VEC(f1 + f2, Vec3::Zero(), tol);
      }
      {
        INFO(
            "the force must lie along the spring, f1 = f_sd e: components across e usually come "
            "from a damper that uses the whole velocities instead of e . v1 and e . v2");
        CHECK_NEAR_VEC(f1.cross(e), Vec3::Zero(), tol);
      }
      {
        INFO("along e the force must be f_sd = -ks (l0 - l) - kd (e . v1 - e . v2) = " << f_sd
                                                                                       << " N");
        CHECK(f1.dot(e) == doctest::Approx(f_sd).epsilon(1e-9));
      }
    }
  }

  TEST_CASE("ex02.1 a damper never adds energy" * POINTS(1)) {
    // With ks = 0 only the damper acts: f1 = -kd (e . (v1 - v2)) e and f2 = -f1. The power it
    // delivers to the pair is P = f1 . v1 + f2 . v2 = f1 . (v1 - v2) = -kd (e . (v1 - v2))^2,
    // never positive: a damper only turns motion into heat. The velocities across the spring do
    // not enter.
    for (const SpringCase& s : kSprings) {
      INFO(describe(s));
      const Vec3 f1 = clothlab::spring_damper_force(s.r1, s.r2, s.v1, s.v2, 0.0, s.kd, s.l0);
      const Vec3 dv = s.v1 - s.v2;
      const double power = f1.dot(dv);
      const double along = (s.r2 - s.r1).normalized().dot(dv);
      const double expected = -s.kd * along * along;
      const double tol = 1e-9 * (1.0 + std::abs(expected));
      CAPTURE(power);
      {
        INFO(
            "the damper's power on the pair, f1 . (v1 - v2), must never be positive: a positive "
            "power means the damper pushes along the relative motion (its sign is flipped)");
        CHECK(power <= tol);
      }
      {
        INFO(
            "the damper must take out exactly kd (e . (v1 - v2))^2 watts: project both "
            "velocities on e before taking their difference");
        CHECK(power == doctest::Approx(expected).epsilon(1e-9).scale(1.0));
      }
    }
  }

  TEST_CASE("ex02.1 the spring force is minus the slope of its energy" * POINTS(1)) {
    // The spring stores U(r1) = 1/2 ks (|r2 - r1| - l0)^2 (written out here, independently of
    // exercise 2.2). A conservative force is minus the gradient of its energy: f1 = -dU/dr1,
    // which central differences with h = 1e-6 m give to about 1e-8 relative. At rest (v = 0)
    // the damper adds nothing, whatever kd.
    for (const SpringCase& s : kSprings) {
      INFO(describe(s));
      const Vec3 f1 =
          clothlab::spring_damper_force(s.r1, s.r2, Vec3::Zero(), Vec3::Zero(), s.ks, s.kd, s.l0);
      const auto energy = [&](const Vec3& r1) {
        const double stretch = (s.r2 - r1).norm() - s.l0;
        return 0.5 * s.ks * stretch * stretch;
      };
      const Vec3 minus_gradient = -central_gradient(energy, s.r1, 1e-6);
      INFO(
          "the spring force on particle 1 must be minus the slope of 1/2 ks (l - l0)^2 with "
          "respect to r1: check the sign of the stretch and that e is normalised");
      CHECK_NEAR_VEC(f1, minus_gradient, 1e-5 * (1.0 + minus_gradient.norm()));
    }
  }

  TEST_CASE("ex02.1 coincident particles get a zero force and no NaN" * POINTS(1)) {
    // r1 == r2: l = 0 and e = e* / l = 0 / 0 is undefined. The lesson asks for a zero force
    // (a NaN would spread through the whole cloth in a few steps), even with a rest length
    // and moving particles.
    const Vec3 r(0.5, -0.25, 2.0);
    const Vec3 f1 = clothlab::spring_damper_force(r, r, Vec3(1.0, 2.0, 3.0), Vec3(-3.0, 0.0, 1.0),
                                                  100.0, 2.0, 0.1);
    INFO(
        "when r1 == r2 there is no direction to act along: return Vec3::Zero() before dividing "
        "by l = 0");
    CHECK(f1.allFinite());
    CHECK_NEAR_VEC(f1, Vec3::Zero(), 0.0);
    // Only l == 0 is special: 1 mm apart along z, e = (0, 0, 1), the spring is 0.099 m short,
    // f_sd = -100 (0.1 - 0.001) - 2 (3 - 1) = -9.9 - 4 = -13.9 N, f1 = (0, 0, -13.9) N.
    const Vec3 near = clothlab::spring_damper_force(
        r, r + Vec3(0.0, 0.0, 0.001), Vec3(1.0, 2.0, 3.0), Vec3(-3.0, 0.0, 1.0), 100.0, 2.0, 0.1);
    INFO(
        "particles 1 mm apart are not coincident: the squeezed spring and the damper push with "
        "f_sd = -9.9 - 4 = -13.9 N along e = (0, 0, 1)");
    CHECK_NEAR_VEC(near, Vec3(0.0, 0.0, -13.9), 1e-9);
  }

  // --- Exercise ex02.2: the energy of a spring ---------------------------------------------------

  TEST_CASE("ex02.2 the energy of a stretched spring worked by hand" * POINTS(1)) {
    // r2 - r1 = (2, -3, 6), l = 7. ks = 14 N/m, l0 = 5 m: U = 1/2 * 14 * (7 - 5)^2 = 28 J.
    // At its rest length (l0 = 7) the spring stores nothing.
    const Vec3 r1(1.0, 2.0, 3.0), r2(3.0, -1.0, 9.0);
    {
      const double u = clothlab::spring_energy(r1, r2, 14.0, 5.0);
      INFO(
          "U = 1/2 ks (l - l0)^2 with l = |r2 - r1| = 7 m: 28 J. 56 J means the 1/2 is missing; "
          "14 J means the stretch was not squared; a much larger value usually means l was taken "
          "as the squared length");
      CHECK(u == doctest::Approx(28.0).epsilon(1e-12));
    }
    {
      const double u = clothlab::spring_energy(r1, r2, 14.0, 7.0);
      INFO("a spring at its rest length stores no energy");
      CHECK(u == doctest::Approx(0.0).scale(1.0).epsilon(1e-12));
    }
  }

  TEST_CASE("ex02.2 a compressed spring stores energy too" * POINTS(1)) {
    // Same spring, l = 7, now with l0 = 9: it is 2 m too short. U = 1/2 * 14 * (7 - 9)^2 = 28 J,
    // as much as when stretched by 2 m: the energy depends on the square of the stretch, so it is
    // never negative. Swapping the ends changes nothing.
    const Vec3 r1(1.0, 2.0, 3.0), r2(3.0, -1.0, 9.0);
    const double u12 = clothlab::spring_energy(r1, r2, 14.0, 9.0);
    const double u21 = clothlab::spring_energy(r2, r1, 14.0, 9.0);
    INFO(
        "a spring compressed by 2 m stores 28 J, like one stretched by 2 m: square the stretch "
        "(l - l0), do not just multiply by it");
    CHECK(u12 == doctest::Approx(28.0).epsilon(1e-12));
    CHECK(u21 == doctest::Approx(28.0).epsilon(1e-12));
  }

  TEST_CASE("ex02.2 the slope of the energy is the spring force" * POINTS(2)) {
    // Differentiating U = 1/2 ks (l - l0)^2 with l = |r2 - r1|: dl/dr1 = -e and dl/dr2 = +e
    // (e = (r2 - r1) / l), so -dU/dr1 = ks (l - l0) e (a stretched spring pulls particle 1
    // toward 2) and -dU/dr2 = -ks (l - l0) e. Central differences of the student's energy, with
    // h = 1e-6 m, must give these forces to about 1e-8 relative.
    for (const SpringCase& s : kSprings) {
      INFO(describe(s));
      const double l = (s.r2 - s.r1).norm();
      const Vec3 e = (s.r2 - s.r1) / l;
      const Vec3 f1 = s.ks * (l - s.l0) * e;  // the hand-derived spring force on particle 1
      const auto energy_of_r1 = [&](const Vec3& r1) {
        return clothlab::spring_energy(r1, s.r2, s.ks, s.l0);
      };
      const auto energy_of_r2 = [&](const Vec3& r2) {
        return clothlab::spring_energy(s.r1, r2, s.ks, s.l0);
      };
      const Vec3 minus_grad_1 = -central_gradient(energy_of_r1, s.r1, 1e-6);
      const Vec3 minus_grad_2 = -central_gradient(energy_of_r2, s.r2, 1e-6);
      INFO(
          "minus the slope of the energy must be the spring force ks (l - l0) e on particle 1 "
          "and its opposite on particle 2: check U = 1/2 ks (l - l0)^2 with l the distance, "
          "not its square");
      CHECK_NEAR_VEC(minus_grad_1, f1, 1e-5 * (1.0 + f1.norm()));
      CHECK_NEAR_VEC(minus_grad_2, -f1, 1e-5 * (1.0 + f1.norm()));
    }
  }

}  // TEST_SUITE("ex02")
