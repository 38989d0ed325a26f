// Lesson 07, integrators and accuracy: the exercise kernels.
//
// exercises/ holds the stubs a student fills in; solutions/ holds the reference. The two files
// are the same except inside the regions between "BEGIN exNN.k" and "END exNN.k": write your
// answer there and leave the rest as it is. Grade your work with `./build/clothlab grade`, and
// watch a scene run on your code with
//   ./build/clothlab-student run lessons/07-integrators/pendulum-cloth.toml
// Every symbol is explained in lessons/07-integrators/README.md.
// Nothing needs rebuilding by hand: the grader, and each student program before it runs,
// compiles what you saved first.
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/integrators/runge_kutta.hpp"

namespace clothlab {

// Exercise ex07.1: the midpoint method (RK2). Take half a step with Euler, measure the
// acceleration there, and use that midpoint's rates for the whole step:
//   a1 = a(x, v)
//   x2 = x + dt/2 v,   v2 = v + dt/2 a1,   a2 = a(x2, v2)
//   x' = x + dt v2,    v' = v + dt a2
// Hints:
//   1. accel(x, v, a) writes the acceleration into a; give it stages.a[0], then stages.a[1].
//   2. Keep the trial state in stages.x[1] and stages.v[1]: x and v must stay the start of the
//      step until the very end.
//   3. Eigen adds and scales whole matrices: stages.x[1] = x + 0.5 * dt * v; is one line.
void midpoint_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
                   RungeKuttaStages& stages) {
  // BEGIN ex07.1: see lessons/07-integrators/README.md
  CLOTHLAB_TODO("ex07.1", "lessons/07-integrators/README.md");
  // END ex07.1
}

// Exercise ex07.2: classical Runge-Kutta (RK4). Four stages, each a trial step from the START of
// the step using the rates found by the stage before, then a weighted average (1, 2, 2, 1)/6:
//   stage 1: x1 = x,            v1 = v,            a1 = a(x1, v1)
//   stage 2: x2 = x + dt/2 v1,  v2 = v + dt/2 a1,  a2 = a(x2, v2)
//   stage 3: x3 = x + dt/2 v2,  v3 = v + dt/2 a2,  a3 = a(x3, v3)
//   stage 4: x4 = x + dt v3,    v4 = v + dt a3,    a4 = a(x4, v4)
//   x' = x + dt/6 (v1 + 2 v2 + 2 v3 + v4),   v' = v + dt/6 (a1 + 2 a2 + 2 a3 + a4)
// Hints:
//   1. Stage k (counting from 0) lives in stages.x[k], stages.v[k], stages.a[k].
//   2. The velocity of stage k is the rate of change of position of stage k: x' averages the
//      stage velocities exactly as v' averages the stage accelerations.
//   3. Every stage starts from x and v, not from the stage before it.
void rk4_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
              RungeKuttaStages& stages) {
  // BEGIN ex07.2: see lessons/07-integrators/README.md
  CLOTHLAB_TODO("ex07.2", "lessons/07-integrators/README.md");
  // END ex07.2
}

}  // namespace clothlab
