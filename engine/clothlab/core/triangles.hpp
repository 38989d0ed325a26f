// triangles.hpp: the surface of a cloth, as triangles over its particles.
#pragma once

#include <array>

#include "clothlab/core/types.hpp"

namespace clothlab {

// Three particle indices. The order (winding) fixes which way the normal points; no force in
// clothlab depends on it.
using Triangle = std::array<Index, 3>;

}  // namespace clothlab
