// An entity index as a container position: `v[at(i)]` for the std::vector of a field, where
// i is the signed Index that loops and lists use.
#pragma once

#include <cstddef>

#include "core/types.hpp"

namespace crater {

/// i as a std::size_t position (i >= 0).
inline std::size_t at(Index i) {
  return static_cast<std::size_t>(i);
}

}  // namespace crater
