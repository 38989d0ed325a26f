// methods.hpp: the integration methods a scene can name, and the one that makes a method by name.
//
// The names are written once, in methods.cpp's table: the scene reader checks a scene's
// [integrator] method against it and lists it in its error, `clothlab --help` and the benches
// list it, and make_integrator builds from it. The interface every method implements is
// core/integrator.hpp; no method's header includes this file.
#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "clothlab/core/integrator.hpp"

namespace clothlab {

// The force-based integrators of lessons 01 to 08 (explicit and symplectic Euler, midpoint,
// RK4, the two Verlets, implicit Euler), in the order lesson 07 compares them.
std::span<const std::string_view> integrator_names();

// Every name a scene may give in [integrator] method = "...": integrator_names(), then lesson
// 12's "xpbd", which moves particles by constraints instead of by spring forces, and lesson 13's
// "local-global", which solves implicit Euler by local projections and a prefactored system, and
// lesson 14's "vbd", which solves it by Newton steps one vertex at a time.
std::span<const std::string_view> method_names();

// A new integrator of the method called `name`, or nullptr when no method has that name.
std::unique_ptr<Integrator> make_integrator(std::string_view name);

}  // namespace clothlab
