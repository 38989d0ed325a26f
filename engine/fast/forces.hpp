// forces.hpp: the force effects the fast engine can sum on its copies (copies.hpp).
//
// The fast engine recognises an effect by its type and reads what it needs through the effect's
// public accessors: the effects themselves (engine/clothlab/) know nothing of it. For each one it
// keeps a FastForce, which adds the same forces as the effect's add_forces, on a range of
// particles, with the same floating-point operations on each particle in the same order, so
// that the two paths agree bit for bit. An effect it does not recognise (buoyancy, gravitation,
// one a student wrote) adds its forces with add_forces, in its turn (engine.cpp).
#pragma once

#include <memory>
#include <typeinfo>

#include "clothlab/core/effect.hpp"
#include "fast/copies.hpp"

namespace clothlab {
class SpringDampers;
class Aerodynamics;
}  // namespace clothlab

namespace clothlab::fast {

// On the copies in Scalar: double for the fast path, float for the float room (float_room.hpp).
template <class Scalar>
class FastForceOf {
 public:
  virtual ~FastForceOf() = default;

  // Whether it takes this evaluation; called once per evaluation, on one thread, so it may
  // rebuild what it keeps of its effect (a layout of springs or triangles) when that changed.
  virtual bool prepare(const Particles& p) = 0;

  // The effect's forces on particles [begin, end) only, added into those columns of f. It reads
  // x and v anywhere (a spring reaches out of the range) and writes f nowhere else: different
  // threads take different ranges at once.
  virtual void add(const Particles& p, const SoA3Of<Scalar>& x, const SoA3Of<Scalar>& v,
                   SoA3Of<Scalar>& f, Index begin, Index end) const = 0;

  // Springs it takes through grid stencils (springs.hpp), as prepared last: for tests and the
  // bench.
  virtual size_t stencil_springs() const { return 0; }

  // The effect's potential energy at x (the engine's layout), as its own potential_energy
  // computes it, bit for bit (Backend::potential_energy), on the world's threads where it can
  // split the work. False: declined.
  virtual bool potential_energy(const World& /*world*/, const Matrix3X& /*x*/, double& /*energy*/) {
    return false;
  }
};
using FastForce = FastForceOf<double>;

// A place in an engine's list of force effects and the fast form made for the effect seen there.
// An effect removed and another made at the same address is seen as new unless it is of the same
// type (and then the fast form reads the new one, and checks its version).
template <class Scalar>
struct FastForceSlot {
  const ForceEffect* effect = nullptr;
  const std::type_info* type = nullptr;
  std::unique_ptr<FastForceOf<Scalar>> fast;  // its fast form, or null

  // The slot for `e`: its fast form made by make(e), again only when `e` is new here.
  template <class Make>
  void match(const ForceEffect& e, Make make) {
    if (effect == &e && *type == typeid(e)) return;
    effect = &e;
    type = &typeid(e);
    fast = make(e);
  }
};

// The fast form of `effect`, reading it where it is (it must outlive the result), or null when
// there is none.
std::unique_ptr<FastForce> fast_force(const ForceEffect& effect);

// Its float form for the float room, or null when the float room does not cover it: gravity,
// damping, spring-dampers (springs, bending) and aerodynamics.
std::unique_ptr<FastForceOf<float>> fast_force_float(const ForceEffect& effect);

// The ones with files of their own (springs.cpp, aerodynamics.cpp).
template <class Scalar>
std::unique_ptr<FastForceOf<Scalar>> fast_springs(const SpringDampers& springs);
template <class Scalar>
std::unique_ptr<FastForceOf<Scalar>> fast_aerodynamics(const Aerodynamics& aerodynamics);

}  // namespace clothlab::fast
