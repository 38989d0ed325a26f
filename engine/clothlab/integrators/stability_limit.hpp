// stability_limit.hpp: the largest stable time step of explicit Euler on a spring-damper
// (lesson 08).
//
// One particle of mass m on a spring ks = k with a damper kd = c, displaced along the spring:
//   m x'' = -k x - c x',   or   x'' = -w^2 x - beta x',   w^2 = k / m,   beta = c / m.
// Its solutions are x = e^(lambda t) with lambda^2 + beta lambda + w^2 = 0, and one step of
// explicit Euler multiplies each of them by its amplification factor R = 1 + dt lambda. The step
// is stable while |R| <= 1 for both roots lambda:
//   underdamped (c^2 < 4 k m): lambda = -beta/2 +- i sqrt(w^2 - beta^2/4), and
//     |R|^2 = 1 - dt beta + dt^2 w^2 <= 1   <=>   dt <= beta / w^2 = c / k;
//   overdamped (c^2 >= 4 k m): two real roots; the faster, -(beta/2 + sqrt(beta^2/4 - w^2)),
//     must keep R >= -1, which gives dt <= 4 m / (c + sqrt(c^2 - 4 k m)).
// The two agree at critical damping, dt = 2 / w. The time-step advisor (analysis/stability.hpp)
// asks this kernel for explicit Euler's limit.
#pragma once

namespace clothlab {

// Exercise ex08.1: the largest dt [s] at which explicit Euler is stable on the spring-damper
// m x'' = -k x - c x', for k >= 0 [N/m], m > 0 [kg] and c >= 0 [N s/m]. 0 when it is unstable
// at every dt (a spring without a damper: explicit Euler adds energy at every step), infinity
// when it is stable at every dt (no spring and no damper: nothing to oscillate or decay).
double largest_stable_dt_explicit_euler(double k, double m, double c);

}  // namespace clothlab
