// The part kit's types (parts/part.hpp) as the solver names them: the solver drives parts
// through this interface and owns none of it.
#pragma once

#include "parts/part.hpp"

namespace crater::solver {

using parts::ContactPoints;
using parts::ContactSurface;
using parts::Diagnostic;
using parts::Energies;
using parts::Fault;
using parts::Geometry;
using parts::Part;
using parts::StableStep;

}  // namespace crater::solver
