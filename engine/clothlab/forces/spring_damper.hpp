// spring_damper.hpp: spring-damper elements between pairs of particles.
//
// Lecture: a spring-damper joins particles 1 and 2 with a spring constant ks [N/m], a damping
// factor kd [N s/m] and a rest length l0 [m]. It works along the line between the particles:
//
//   e* = r2 - r1,   l = |e*|,   e = e* / l          (unit vector from 1 toward 2)
//   v1 = e . v1,    v2 = e . v2                     (velocities along that line)
//   f_sd = -ks (l0 - l) - kd (v1 - v2)              (1D force: spring + damper)
//   f1 = f_sd e,    f2 = -f1                        (back to 3D, equal and opposite)
//
// A stretched spring (l > l0) pulls 1 toward 2; particles closing in (v1 > v2) are pushed apart
// by the damper. Cloth is a grid of these: structural springs along rows and columns, shear
// springs along the diagonals of each cell, and (lesson 04) bending springs two apart.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/core/effect.hpp"

namespace clothlab {

class SpringDampers;

// How the spring-damper force on particle 1 changes as particle 2 moves (df1/dr2) and as its
// velocity changes (df1/dv2), for the implicit integrator:
//   df1/dr2 = ks [ e e^T + max(0, 1 - l0/l) (I - e e^T) ],   df1/dv2 = kd e e^T.
// Along the spring the stiffness is ks; across it, a stretched spring resists turning with
// ks (1 - l0/l). A compressed spring would give a negative stiffness across it, which makes
// the implicit system indefinite; like most cloth codes we drop that term (the max), so the
// system stays symmetric positive definite and conjugate gradients can solve it. The damping
// force's change with position is small and dropped as well (Baraff and Witkin do the same).
struct SpringJacobian {
  Mat3 dfdx;
  Mat3 dfdv;
};
SpringJacobian spring_damper_jacobian(const Vec3& r1, const Vec3& r2, double ks, double kd,
                                      double l0);

// Exercise ex02.1: the force [N] a spring-damper exerts on particle 1 (the force on particle 2 is
// its negative), for positions r1, r2 [m], velocities v1, v2 [m/s], spring constant ks [N/m],
// damping factor kd [N s/m] and rest length l0 [m]. Coincident particles (l = 0) have no
// direction to push along: the force is zero, never NaN.
Vec3 spring_damper_force(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2, double ks,
                         double kd, double l0);

// Exercise ex02.2: the energy [J] stored in the spring (not the damper), 1/2 ks (l - l0)^2.
double spring_energy(const Vec3& r1, const Vec3& r2, double ks, double l0);

// The same double, bit for bit: -0.0 and 0.0 differ here, which == would not see, and two NaNs
// with the same bits are the same. (memcpy rather than std::bit_cast, which the C++ library of
// the WebAssembly build lacks.)
inline bool same_bits(double a, double b) {
  std::uint64_t bits_a, bits_b;
  std::memcpy(&bits_a, &a, sizeof a);
  std::memcpy(&bits_b, &b, sizeof b);
  return bits_a == bits_b;
}

// A family of springs as parallel arrays: spring k joins particles i(k) and j(k), with spring
// constant ks(k) [N/m], damping factor kd(k) [N s/m], rest length l0(k) [m] and its rest length
// as built, l_built(k) [m] (plasticity, lesson 06, keeps l0 within limits of l_built).
//
// The arrays are read through i(), j(), ks(), ... and changed only through the methods below.
// The fast engine (engine/fast/) keeps a description of the ends and the constants, and every
// method that changes one of them moves version() to a number no other change, of any set, has
// had: the fast engine compares it before every use, in every build, so it never computes with a
// description of springs that are no longer there. The rest lengths are no part of version()
// (plasticity changes them every step, and what is built on the ends and constants, a solver's
// factor, need not be built again), but a rest length set to other bits moves rest_version(),
// the same way: the fast engine's grid stencils hold the rest lengths of springs at the length
// they were built with.
class SpringSet {
 public:
  size_t size() const { return i_.size(); }

  Index i(size_t k) const { return i_[k]; }
  Index j(size_t k) const { return j_[k]; }
  double ks(size_t k) const { return ks_[k]; }
  double kd(size_t k) const { return kd_[k]; }
  double l0(size_t k) const { return l0_[k]; }
  double l_built(size_t k) const { return l_built_[k]; }
  const std::vector<Index>& i() const { return i_; }
  const std::vector<Index>& j() const { return j_; }
  const std::vector<double>& ks() const { return ks_; }
  const std::vector<double>& kd() const { return kd_; }
  const std::vector<double>& l0() const { return l0_; }
  const std::vector<double>& l_built() const { return l_built_; }

  // Adds a spring from a to b with rest length l0_ab >= 0 [m] (a negative or NaN one throws
  // std::invalid_argument).
  void add(Index a, Index b, double ks_ab, double kd_ab, double l0_ab);
  // Adds a spring from a to b at rest as the particles stand: l0 = |x_b - x_a| [m].
  void add_at_rest(Index a, Index b, double ks_ab, double kd_ab, const Matrix3X& x);
  // Removes the springs at the given positions (ascending), keeping the others in order.
  void erase(const std::vector<size_t>& positions);
  // Spring k now joins a and b (its constants and lengths stay).
  void set_ends(size_t k, Index a, Index b);
  // The springs in the opposite order, each turned end for end: the same forces, summed in
  // another order.
  void reverse();
  void set_ks(size_t k, double value);
  void set_kd(size_t k, double value);
  void set_l0(size_t k, double value) {
    if (same_bits(l0_[k], value)) return;  // plasticity's elastic springs: no change
    l0_[k] = value;
    rest_changed();
  }

  // Which change of the ends or the constants this set is at (see above).
  unsigned long version() const { return version_; }
  // Which change of a rest length by set_l0 it is at (see above).
  unsigned long rest_version() const { return rest_version_; }

 private:
  void changed();
  void rest_changed();

  std::vector<Index> i_, j_;
  std::vector<double> ks_, kd_, l0_, l_built_;
  unsigned long version_ = 0;
  unsigned long rest_version_ = 0;
};

// The spring effect of `world` called `name` ("springs" or "bending"), or nullptr.
SpringDampers* find_spring_effect(World& world, std::string_view name);
const SpringDampers* find_spring_effect(const World& world, std::string_view name);

// Appends one spring per pair (a, b), joining particles first + a and first + b, with rest
// lengths measured in x (the distance at build time). The pairs are added sorted by (b - a, a),
// so that a grid's springs form long runs (engine/fast/springs.hpp): the row springs of a cloth,
// then its column springs, and so on, whatever order the builder listed them in.
void add_spring_family(SpringSet& springs, const std::vector<std::pair<Index, Index>>& pairs,
                       Index first, double ks, double kd, const Matrix3X& x);

// SpringDampers::potential_energy sums its springs' energies in blocks of this many, each block
// in order, then the blocks' sums in order: for a set of one block (up to 4096 springs) the same
// number as one sum in order, and for a larger one a sum the engine room can split between its
// threads, each summing whole blocks, to the same bits (engine/fast/springs.cpp).
inline constexpr size_t kEnergyBlock = 4096;

// The force effect of one or more spring families: "springs" (structural, shear and springs
// given one by one) or "bending".
class SpringDampers final : public ForceEffect {
 public:
  SpringDampers(std::string name, SpringSet springs)
      : name_(std::move(name)), springs_(std::move(springs)) {}
  std::string_view name() const override { return name_; }
  void add_forces(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                  Matrix3X& f) const override;
  double potential_energy(const Particles& p, const Matrix3X& x) const override;
  bool add_jacobians(const Particles& p, const Matrix3X& x, const Matrix3X& v,
                     ForceJacobians& jacobians) const override;
  const SpringSet& springs() const { return springs_; }
  SpringSet& springs() { return springs_; }

 private:
  std::string name_;
  SpringSet springs_;
};

}  // namespace clothlab
