// vbd_vertex.hpp: one vertex's Newton step, the kernel of Vertex Block Descent (lesson 14,
// exercise ex14.1).
//
// Chen, Liu, Yang and Yuksel, "Vertex Block Descent", ACM Transactions on Graphics 43(4)
// (SIGGRAPH 2024).
//
// Implicit Euler's step is the minimiser of its incremental potential (lesson 13)
//
//   G(x) = 1/(2 h^2) (x - y)^T M (x - y) + E(x),     y = x_n + h v_n + h^2 M^-1 f_ext
//
// with E the springs' energy and y where inertia and the external forces alone would carry the
// particles. VBD lowers G one vertex at a time: vertex i moves while every other vertex is held
// where it is. As a function of x_i alone, G is (up to terms without x_i)
//
//   G_i(x_i) = m_i / (2 h^2) |x_i - y_i|^2 + sum over the springs at i of ks/2 (|x_i - x_j| - l0)^2
//
// and the vertex takes one Newton step on it: dx = H^-1 f, with f = -grad G_i the force on the
// vertex [N] and H = hess G_i its 3 x 3 block of G's Hessian [N/m]. Each term adds to both; with
// d = x_i - x_j, l = |d| and u = d / l the unit vector from the other end to the vertex:
//
//   inertia:  f += -m_i/h^2 (x_i - y_i)          H += m_i/h^2 I
//   spring:   f += -ks (l - l0) u                 H += ks (I - l0/l (I - u u^T))
//                                                    = ks (u u^T + (1 - l0/l) (I - u u^T))
//   damper:   f += -1/h D (dx_i - dx_j)           H += D / h
//             D = kd (u u^T + max(0, 1 - l0/l) (I - u u^T)),   dx_i = x_i - x_i,n (the step so far)
//
// The spring's Hessian, made definite. Along u its stiffness is ks. Across u it is ks (1 - l0/l):
// a stretched spring (l > l0) resists turning, but a compressed one (l < l0) is glad to buckle
// sideways, and its stiffness across is negative. Enough of that and H is indefinite, and a
// Newton step on an indefinite H may climb G instead of descending it. So the factor (1 - l0/l) is
// clamped at 0 for a compressed spring (the max above, as lesson 08's implicit Euler does): H is
// then the inertia's m_i/h^2 I plus positive semidefinite terms, positive definite. Only the
// step's length and direction change; f is G's exact force, so where the iterations settle, at
// f = 0, is still G's minimiser.
//
// The damper is Rayleigh damping on the spring's Hessian, as the paper damps: D is the clamped
// Hessian with kd [N s/m] in place of ks, and it acts on the velocity over the step,
// (x - x_n) / h. The paper applies it to the vertex's own displacement dx_i; this engine applies it
// to the displacement relative to the other end, dx_i - dx_j, as lecture 02's damper acts on
// relative velocity: a cloth that moves as one piece (falling, swinging) is not slowed by its own
// dampers. Along u it is then lecture 02's damper kd ((v_i - v_j) . u) u, taken at the step's end
// velocity; across u, a stretched spring also damps the pair's turning. With the clamp it only
// ever takes energy out. It is not the gradient of an energy: with kd > 0 the iterations settle
// where the forces balance (f = 0), implicit Euler's equations with this damper.
//
// The guard. H is singular only without inertia (a massless vertex) and with too few springs
// pulling across; then there is no Newton step, and the vertex is left where it is for this
// iteration. "Singular" is judged against H's own size: det(H) at most kSingularBlock times
// (trace(H) / 3)^3, the determinant of a matrix with H's mean eigenvalue on its diagonal, so that
// the test does not depend on units; below that ratio the determinant is rounding.
#pragma once

#include <span>

#include "clothlab/core/effect.hpp"
#include "clothlab/core/types.hpp"

namespace clothlab {

// One spring at the vertex, as the vertex's step sees it: the other end is held still.
struct VertexSpring {
  Vec3 x_j;        // the other end's position now [m]
  Vec3 x_j_start;  // the other end's position at the step's start, x_j,n [m] (for the damper)
  double ks;       // spring constant [N/m]
  double kd;       // damping factor [N s/m]
  double l0;       // rest length [m]
};

// The force on a vertex and its block of the Hessian (above).
struct VertexBlock {
  Vec3 f;  // -grad G_i [N]
  Mat3 H;  // hess G_i with each spring's (1 - l0/l) clamped at 0 [N/m]
};

// det(H) / (trace(H) / 3)^3 at or below which a block is singular (the guard above). Rounding
// leaves the determinant of a singular 3 x 3 block at a few 1e-16 of that scale; a block of a
// stiff rope (1 g vertices, ks = 1e6 N/m, h = 1/60 s) is at about 1e-10.
inline constexpr double kSingularBlock = 1e-13;

// Exercise ex14.1, part 1 (solutions/14_vbd.cpp; the student's is in exercises/14_vbd.cpp):
// G_i's force f [N] and Hessian H [N/m] at vertex i, which is at x_i [m] now and was at
// x_i_start [m] when the step began, with y_i [m] where inertia and the external forces carry it,
// inverse mass w_i > 0 [1/kg] (infinite for a massless vertex: no inertia term), the step
// h [s] and the springs at the vertex. A spring whose ends coincide (l = 0) has no direction and
// adds nothing.
VertexBlock vbd_vertex_block(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i,
                             double h, std::span<const VertexSpring> springs);

// Exercise ex14.1, part 2: the vertex's Newton step dx = H^-1 f [m] (the arguments as for
// vbd_vertex_block). A pinned vertex (w_i = 0) never moves: dx = 0. A singular block (the guard
// above) is skipped: dx = 0, never NaN.
Vec3 vbd_vertex_step(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i, double h,
                     std::span<const VertexSpring> springs);

}  // namespace clothlab
